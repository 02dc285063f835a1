"""AMBF's springs (Options.springs "ambf") evaluated whole in C, with their reads and pushes.

Under AMBF's springs the SpringSet reads its free bodies, evaluates every joint's spring, damper
and limits and pushes the bodies at each physics step. Its numpy costs per call, not per joint
(a few dozen calls of 1-3 µs on arrays of 47 rows at the corpus suturing set); state_calls.c's
adfkit_springs_apply makes the same evaluation (SpringSet.apply's formulas in the same order)
and hands the torques and forces to PyBullet in one call, after one call that reads the bodies.
The numbers are not numpy's to the bit: numpy's 3x3 products go through BLAS and its arctan2
and arcsin are its own (docs/speed.md has the parity figures). It plays a set of free bodies
(no multibody link) with no cone-twist limits and no body held alone on a static one; any other
set stays in numpy."""

from __future__ import annotations

import ctypes

import numpy as np

_P, _I = ctypes.c_void_p, ctypes.c_int


class _Springs(ctypes.Structure):
    _fields_ = [
        ("nb", _I),
        ("nj", _I),
        ("nf", _I),
        *((name, _P) for name in ("ip", "ic", "ra_in", "rb_in", "eq", "nk", "nc", "low", "high", "ieff", "fl")),
        *((name, _P) for name in ("pa_in", "pb_in", "feq", "fnk", "fnc", "flow", "fhigh", "fg", "inv_m", "inv_i")),
        ("nd", _I),
        ("np", _I),
        *((name, _P) for name in ("dyn", "duid", "dlink", "push", "puid", "plink", "work")),
    ]


def playable(springs) -> bool:
    """Whether SpringSet ``springs`` (its read plan made) can be evaluated in C (see the module)."""
    return (
        springs.form == "ambf"
        and springs.cones is None
        and springs.pivots is None
        and not springs._links
        and springs._in_order
        and len(springs.joints) > 0
    )


class CSprings:
    """SpringSet ``springs``' evaluation in C through ``lib`` (state_calls.c) and physics client
    ``client`` (state_calls.StateCalls.client)."""

    def __init__(self, lib, client, springs) -> None:
        s, c = springs, np.ascontiguousarray
        self.lib, self.client = lib, client
        fl = s.free_lin
        nb, nj, nf = len(s.bodies), len(s.joints), len(fl)
        self.springs = s
        self._keep = keep = {
            "ip": c(s.ip, dtype=np.intc),
            "ic": c(s.ic, dtype=np.intc),
            "ra_in": c(s.ra_in_p, dtype=float),
            "rb_in": c(s.rb_in_c, dtype=float),
            "eq": c(s.eq_ang, dtype=float),
            "low": c(s.ang_low, dtype=float),
            "high": c(s.ang_high, dtype=float),
            "ieff": c(s.i_eff, dtype=float),
            "fl": c(fl, dtype=np.intc),
            "pa_in": c(s.pa_in_p[fl], dtype=float),
            "pb_in": c(s.pb_in_c[fl], dtype=float),
            "feq": c(s.fl_eq, dtype=float),
            "flow": c(s.fl_low, dtype=float),
            "fhigh": c(s.fl_high, dtype=float),
            "fg": c(s.fl_g_rel, dtype=float),
            "inv_m": c(s.inv_m_shared, dtype=float),
            "inv_i": c(s.inv_i_shared, dtype=float),
            "dyn": c(s.dynamic, dtype=np.intc),
            "duid": c(s._twisted[0], dtype=np.intc),
            "dlink": c(s._twisted[1], dtype=np.intc),
            "push": c(s._pushed[0], dtype=np.intc),
            "puid": c(s._pushed[1], dtype=np.intc),
            "plink": c(s._pushed[2], dtype=np.intc),
            "work": np.zeros(9 * nb + 24 * nj + 18 * nf),
        }
        self.torque, self.force = np.zeros((nb, 3)), np.zeros((nb, 3))
        st = self.struct = _Springs(nb=nb, nj=nj, nf=nf, nd=len(keep["dyn"]), np=len(keep["push"]))
        for name, arr in keep.items():
            setattr(st, name, arr.ctypes.data)
        self._ref = ctypes.byref(st)
        self._out = (self.torque.ctypes.data, self.force.ctypes.data)
        self._dt = None

    def _gains(self, dt: float) -> None:
        """AMBF's capped gains, negated (SpringSet._gains), for this step."""
        s = self.springs
        s._gains(dt)
        nk, nc, _ = s._ang
        fnk, fnc, _ = s._fl
        g = self._gains_kept = [np.ascontiguousarray(a, dtype=float) for a in (nk, nc, fnk, fnc)]
        st = self.struct
        st.nk, st.nc, st.fnk, st.fnc = (a.ctypes.data for a in g)
        self._dt = dt

    def apply(self, states: np.ndarray, dt: float, erp: float) -> None:
        """Evaluate and push, the bodies' states ``states`` (bodies x 13, state_calls' read)."""
        if dt != self._dt:
            self._gains(dt)
        self.lib.adfkit_springs_apply(self.client, self._ref, states.ctypes.data, dt, erp, *self._out)
