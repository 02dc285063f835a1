"""A `resistance` sensor's forces as AMBF 2.0 plays them (afResistanceSensor::update,
afFramework.cpp), engine-agnostic: each control step, after the physics steps, every ray that hits
a rigid body gives a force Fw = F_normal + F_static + F_dynamic, applied at the hit point, -Fw on
the sensor's parent and +Fw on the body hit (a static body takes none); the engines hold it over the
next control step, as Bullet keeps a force applied after stepSimulation until the next one ends.

- F_normal = stiffness·d·R_a·N_a: d the ray's depth fraction (1 - hit fraction), N_a the ray's
  direction as the file writes it (an `array`'s not normalised) taken in the parent's COM frame R_a.
  AMBF adds `contact damping`·(d - d_last), but reads d_last after its ray tracer has overwritten it
  with d: the term is always 0 (measured: a tip with contact damping 20 flies as with 0.1 in AMBF).
- F_static: at a ray's first hit the hit point is stored in both bodies' COM frames; on later hits
  the error e between them, minus its part along R_a·N_a, gives
  friction.static·s·e + friction.damping·(e - e_two_steps_ago) (AMBF's buffer shifts before it is
  read) while 0 < |e| <= `contact area`, else the points are dropped (stored again next hit).
- F_dynamic = friction.dynamic·s·dv: dv the hit point's velocity on the parent minus on the body
  hit, its part along the hit normal removed.
- s = |F_normal| with friction.variable, else 1. AMBF's defaults: static 0, damping 0.1, dynamic 0,
  contact area 0.1, stiffness 0.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class ResistanceParams:
    static: float = 0.0
    damping: float = 0.1
    dynamic: float = 0.0
    variable: bool = False
    area: float = 0.1
    stiffness: float = 0.0

    @classmethod
    def of(cls, s) -> ResistanceParams:
        f = s.friction
        d = cls()

        def pick(v, default):
            return default if v is None else v

        return cls(
            static=float(pick(f and f.static, d.static)),
            damping=float(pick(f and f.damping, d.damping)),
            dynamic=float(pick(f and f.dynamic, d.dynamic)),
            variable=bool(pick(f and f.variable, d.variable)),
            area=float(pick(s.contact_area, d.area)),
            stiffness=float(pick(s.contact_stiffness, d.stiffness)),
        )


@dataclass
class Body:
    """A body's COM frame and velocities, world frame."""

    com: np.ndarray
    rot: np.ndarray
    v: np.ndarray
    w: np.ndarray


@dataclass
class RayState:
    valid: bool = False
    pa: np.ndarray = field(default_factory=lambda: np.zeros(3))  # the stored point, parent's COM frame
    pb: np.ndarray = field(default_factory=lambda: np.zeros(3))  # and the sensed body's
    err: np.ndarray = field(default_factory=lambda: np.zeros(3))
    err_last: np.ndarray = field(default_factory=lambda: np.zeros(3))


def _plane_dir(n: np.ndarray, x: np.ndarray) -> np.ndarray:
    """(n × x) × n, normalised where longer than 1e-4 (AMBF's test), as AMBF makes it."""
    d = np.cross(np.cross(n, x), n)
    ln = float(np.linalg.norm(d))
    return d / ln if ln > 0.0001 else d


def ray_force(
    p: ResistanceParams,
    st: RayState,
    n_a: np.ndarray,
    a: Body,
    b: Body,
    point: np.ndarray,
    normal: np.ndarray,
    depth: float,
) -> np.ndarray:
    """Fw (world) for one ray that hit a rigid body ``b`` at ``point`` (normal ``normal``,
    depth fraction ``depth``); updates the ray's state."""
    n_aw = a.rot @ n_a
    f_n = p.stiffness * depth * n_aw
    scale = float(np.linalg.norm(f_n)) if p.variable else 1.0
    f_s = np.zeros(3)
    if st.valid:
        e = (a.rot @ st.pa + a.com) - (b.rot @ st.pb + b.com)
        ed = _plane_dir(n_aw, e)
        te = float(ed @ e) * ed
        te_last = st.err_last
        st.err_last = st.err
        st.err = te
        ln = float(np.linalg.norm(te))
        if 0.0 < ln <= p.area:
            f_s = p.static * scale * te + p.damping * (te - te_last)
        else:
            st.valid = False
    else:
        st.pa = a.rot.T @ (point - a.com)
        st.pb = b.rot.T @ (point - b.com)
        st.valid = True
    dv = (a.v + np.cross(a.w, point - a.com)) - (b.v + np.cross(b.w, point - b.com))
    vd = _plane_dir(normal, dv)
    f_d = p.dynamic * scale * float(vd @ dv) * vd
    return f_s + f_d + f_n


def missed(st: RayState) -> None:
    st.valid = False
