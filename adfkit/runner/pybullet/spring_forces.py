"""The spring, damping and limit forces of the joints PyBullet's constraints cannot make (joints.py):
six-dof springs and the like, evaluated together with numpy (adf-format.md §8).

Springs and dampers are played one of two ways (Options.springs): "implicit", integrated over the
control step by backward Euler on the two bodies' relative motion (stable at any gain); or "ambf",
as Bullet's btGeneric6DofSpring2Constraint in AMBF: the explicit k·x + c·v at every physics step,
k capped at m/(16·dt²) and c at m/dt, m the joint's inertia about the axis (each body's about the
axis plus its mass times the squared distance from its centre of mass to the joint frame) or its
mass, both bodies' in series. Limits are velocity corrections with Baumgarte feedback on what the
spring leaves; they can do no more than stop the joint's relative motion within the step.
"""

from __future__ import annotations

import numpy as np

from ..rotations import cross_rows as _cross
from ..rotations import euler_xyz
from ..springs import SpringJoint
from .cone_limits import ConeLimits
from .joint_inertia import PivotInertia, bullet_spring_masses
from .spring_reads import SpringReads


class SpringSet(SpringReads):
    """All force-driven joints, evaluated together with numpy each control step.

    The per-step cost is mostly PyBullet's: one getBasePositionAndOrientation and one
    getBaseVelocity per free body (PyBullet has no batched call for them) and one
    applyExternalTorque per dynamic body. Everything that does not change between steps (the
    joints' index subsets, gains, limits and incidence blocks) is sliced once here, and the
    calls pass their arguments by position (keyword parsing is a tenth of a call's cost)."""

    def __init__(self, joints: list[SpringJoint], cid: int, gravity=(0.0, 0.0, 0.0), form: str = "implicit") -> None:
        """``gravity``: the world's; a body's own (``SimBody.gravity``) replaces it. ``form``: "implicit"
        or "ambf" (Options.springs; the world applies "ambf" springs at every physics step)."""
        self.joints = joints
        self.form = form
        self.cid = cid
        self.world_gravity = np.asarray(gravity, dtype=float)
        self._poses: list = []  # each free body's (position, quaternion) as last read, in _base_keys' order
        self._vels: list = []  # and its (linear, angular) velocity
        self._read_c = None  # the free bodies' states read in one C call (state_calls.py), else None
        self._bases_read = None  # the (n, 13) rows it read last
        self._base_index: dict[tuple[int, int], int] = {}  # (uid, -1) -> its place in those
        self._order = None
        n = len(joints)
        if not n:
            return
        st = np.stack
        fa, fb = st([j.frame_a for j in joints]), st([j.frame_b for j in joints])
        self.ra_in_p, self.pa_in_p = fa[:, :3, :3], fa[:, :3, 3]
        self.rb_in_c, self.pb_in_c = fb[:, :3, :3], fb[:, :3, 3]
        self.r_in_ends = np.concatenate((self.ra_in_p, self.rb_in_c))  # frames A then B, in their bodies
        for name in (
            "lin_low",
            "lin_high",
            "ang_low",
            "ang_high",
            "k_lin",
            "c_lin",
            "eq_lin",
            "k_ang",
            "c_ang",
            "eq_ang",
        ):
            setattr(self, name, st([getattr(j, name) for j in joints]))
        self.free_lin = np.flatnonzero([not j.linear_constrained for j in joints])
        bodies = []
        for j in joints:
            for b in (j.parent, j.child):
                if b not in bodies:
                    bodies.append(b)
        self.bodies = bodies
        idx = {id(b): i for i, b in enumerate(bodies)}
        self.ip = np.array([idx[id(j.parent)] for j in joints])
        self.ic = np.array([idx[id(j.child)] for j in joints])
        self.ends = np.concatenate((self.ip, self.ic))  # each joint's parent, then each joint's child
        # incidence: a joint's torque acts + on its child and - on its parent; summing per body
        # is one matrix product (np.add.at is ten times slower at this size)
        self.to_child = np.zeros((n, len(bodies)))
        self.to_child[np.arange(n), self.ic] = 1.0
        self.to_parent = np.zeros((n, len(bodies)))
        self.to_parent[np.arange(n), self.ip] = 1.0
        self.net = (self.to_child - self.to_parent).T
        self.dynamic = np.flatnonzero([not b.static for b in bodies])
        # bodies that get a net force (joint ends of a spring with free linear axes), the rest a torque only
        pushed = np.zeros(len(bodies), dtype=bool)
        pushed[self.ip[self.free_lin]] = True
        pushed[self.ic[self.free_lin]] = True
        self.pushed = pushed
        # each joint's effective inertia (mass) as if each body's were shared among the spring
        # joints on it: the joints act together (a Jacobi step), and a body between two joints
        # that each stopped their relative motion alone would be turned twice as far back
        deg = np.bincount(np.concatenate([self.ip, self.ic]), minlength=len(bodies)).astype(float)
        inv_m = np.array([0.0 if b.static else 1.0 / b.mass for b in bodies]) * deg
        inv_i = np.array([0.0 if b.static else 1.0 / max(min(b.inertia), 1e-12) for b in bodies]) * deg
        self.m_eff = 1.0 / np.maximum(inv_m[self.ip] + inv_m[self.ic], 1e-12)
        self.i_eff = 1.0 / np.maximum(inv_i[self.ip] + inv_i[self.ic], 1e-12)
        cones = ConeLimits.among(joints) if form == "ambf" else np.zeros(0, int)
        self.ang_low[cones], self.ang_high[cones] = 1.0, -1.0  # Bullet's cone and twist instead (cone_limits.py)
        active = self.ang_low <= self.ang_high
        self.ang_active = True if active.all() else active  # True: _limit skips its &s
        self.ang_ranged = self.ang_low < self.ang_high if form == "ambf" else None  # AMBF's rows inside (_limit)
        fl = self.free_lin
        # the free-linear joints' constant blocks, sliced once (the same values every step)
        self.fl_ip, self.fl_ic = self.ip[fl], self.ic[fl]
        # the pivots in their bodies (A in the parent's, then B in the child's), and the bodies the
        # force at pivot B turns (the child's, then the parent's): each block one product
        self.fl_ends = np.concatenate((self.fl_ip, self.fl_ic))
        self.fl_p_ends = np.concatenate((self.pa_in_p[fl], self.pb_in_c[fl]))[:, :, None]
        self.fl_arms = np.concatenate((self.fl_ic, self.fl_ip))
        self.fl_eq, self.fl_low, self.fl_high = self.eq_lin[fl], self.lin_low[fl], self.lin_high[fl]
        self.fl_active = True if (self.fl_low <= self.fl_high).all() else self.fl_low <= self.fl_high
        self.fl_ranged = self.fl_low < self.fl_high if form == "ambf" else None
        self.fl_m = self.m_eff[fl][:, None]
        # each body's 1/m and principal 1/I, shared as m_eff's are, for the pivots' mass (_pivot_mass)
        self.inv_m_shared = inv_m
        self.inv_i_shared = (
            np.array(
                [np.zeros(3) if b.static else 1.0 / np.maximum(np.asarray(b.inertia, float), 1e-12) for b in bodies]
            )
            * deg[:, None]
        )
        self.fl_net = self.net[:, fl]
        self.fl_child_t, self.fl_parent_t = self.to_child[fl].T, self.to_parent[fl].T
        # the child's acceleration under gravity relative to the parent's, in the world: the
        # limits of a free linear axis predict the velocity at the end of the control step with
        # it, as a constraint row solved with the forces would (below)
        acc = np.array(
            [np.zeros(3) if b.static else (b.gravity if b.gravity is not None else self.world_gravity) for b in bodies]
        )
        self.fl_g_rel = (acc[self.ic] - acc[self.ip])[fl] if n else np.zeros((0, 3))
        self.i_eff_col = self.i_eff[:, None]
        held = np.flatnonzero(PivotInertia.held(bodies, self.ip, self.ic, deg, fl))  # alone on a static body
        self.pivots = None
        if form == "ambf" and held.size:
            self.pivots = (PivotInertia(bodies, self.ip[held], self.ic[held], deg, self.pb_in_c[held]), held)
        # Bullet's m, but never past the joint's share of its bodies' inertia (and mass) that the
        # implicit form uses: Bullet's counts mass·r² even about an axis through both centres of
        # mass, and the forces here act all at once (a Jacobi step), where Bullet solves rows one
        # after another. With Bullet's m alone the corpus thread (capsules: 5e-10 kg m² about
        # their axis, 90x less than its m) flew apart within the first second. A spring of a
        # multibody's joint (SpringJoint.in_multibody) turns its child about its joint alone, the
        # joint holding the rest: its m is Bullet's (a rod's mass·r² about its pivot, not its own
        # inertia about its centre of mass, 1000x less for the test's pendulum, which its spring
        # then could not hold up)
        m_ang, m_lin = bullet_spring_masses(bodies, self.ip, self.ic, fa, fb)
        exact = np.array([j.in_multibody for j in joints])[:, None]
        self.m_ang = np.where(exact, m_ang, np.minimum(m_ang, self.i_eff[:, None]))
        self.m_lin = np.where(exact, m_lin, np.minimum(m_lin, self.m_eff[:, None]))
        self.i_implicit = np.where(exact, m_ang, self.i_eff[:, None])  # what the implicit form integrates
        self.m_implicit = np.where(exact, m_lin, self.m_eff[:, None])
        self._gains_dt = None
        self.cones = ConeLimits(self, cones, held, acc) if len(cones) else None
        self._c_springs = None  # the whole evaluation in C, where it can be (spring_c.py; _read_plan)

    def _gains(self, dt: float) -> None:
        """Per-joint constants of the spring-damper -(K·x + C·v) / D at this step (_spring).
        Implicit (backward Euler): K = k, C = c + k·dt, D = 1 + (c·dt + k·dt²)/I (I the joint's
        effective inertia or mass): the force that leaves the pair moving at the velocity the
        spring and damper give it at the end of the step, for small gains the explicit -k·x - c·v,
        for large ones at most what stops the motion. AMBF's (btGeneric6DofSpring2Constraint::
        get_limit_motor_info2): K = min(k, m/(16·dt²)), C = min(c, m/dt), D = 1 (None: not divided by)."""
        if self._gains_dt == dt:
            return
        if self.form == "ambf":  # (_spring takes -K and -C: negated once here, not at every step)
            self._ang = (
                -np.minimum(self.k_ang, self.m_ang / (16 * dt * dt)),
                -np.minimum(self.c_ang, self.m_ang / dt),
                None,
            )
            self._lin = (
                -np.minimum(self.k_lin, self.m_lin / (16 * dt * dt)),
                -np.minimum(self.c_lin, self.m_lin / dt),
                None,
            )
        else:
            den_ang = 1.0 + (self.c_ang * dt + self.k_ang * dt**2) / self.i_implicit
            den_lin = 1.0 + (self.c_lin * dt + self.k_lin * dt**2) / self.m_implicit
            self._ang = (-self.k_ang, -(self.c_ang + self.k_ang * dt), den_ang)
            self._lin = (-self.k_lin, -(self.c_lin + self.k_lin * dt), den_lin)
        k, c, den = self._lin
        fl = self.free_lin
        self._fl = (k[fl], c[fl], den if den is None else den[fl])
        self._gains_dt = dt

    @staticmethod
    def _spring(gains, x, v):
        """The spring-damper's force or torque -(K·x + C·v) / D, ``gains`` (-K, -C, D) (_gains: the
        same products as (-K)·x and (-C)·v, the negations made once).
        D None is AMBF's row (get_limit_motor_info2): its impulse is bounded by the spring-damper's
        and the damper's alone and driven to the bound on the side of their sum, so where the damper
        opposes the spring and outweighs it the damper acts alone (a spring released toward its
        equilibrium is braked by the whole of -C·v, not by what the spring leaves of it)."""
        neg_k, neg_c, den = gains
        spring, damper = neg_k * x, neg_c * v
        out = spring + damper
        if den is None:
            return np.where((spring * damper < 0.0) & (np.abs(damper) > np.abs(spring)), damper, out)
        return out / den

    def apply(self, dt: float, erp: float = 0.2) -> None:
        if not self.joints:
            return
        if self._order is None:
            self._read_plan()
        if self._c_springs is not None:  # read, evaluated and pushed in C (spring_c.py)
            self._c_springs.apply(self._c_read(), dt, erp)
            return
        self._gains(dt)
        pos, rot, lv, av = self.states()
        ip, ic, n = self.ip, self.ic, len(self.joints)
        frames = rot[self.ends] @ self.r_in_ends  # joint frames A, then B, in the world
        ra = frames[:n]
        rat = ra.transpose(0, 2, 1)
        rel = rat @ frames[n:]  # frame B in frame A
        ang = euler_xyz(rel)
        w_rel = (rat @ (av[ic] - av[ip])[:, :, None])[..., 0]
        # angular springs and limits, in joint frame A, turned into the world
        i_eff = self.i_eff_col
        if self.pivots is not None:
            held = self.pivots[1]
            i_eff = np.repeat(i_eff, 3, axis=1)
            i_eff[held] = self.pivots[0].about_pivots(pos, rot, ra[held])
        tau = self._spring(self._ang, ang - self.eq_ang, w_rel)
        tau += self._limit(
            ang,
            lambda: w_rel + tau * dt / i_eff,
            self.ang_low,
            self.ang_high,
            i_eff,
            dt,
            erp,
            self.ang_active,
            (self.ang_ranged, w_rel),
        )
        if self.cones is not None:  # Bullet's swing and twist rows (cone_limits.py)
            tau[self.cones.index] += self.cones.in_frame_a(pos, rot, lv, av, ra, frames[n:], dt)
        torque = self.net @ (ra @ tau[:, :, None])[..., 0]
        force = None
        fl = self.free_lin
        if fl.size:
            # free linear axes: spring, damper and limits on the pivot offset in frame A; a
            # force at the pivot = the same force at the COM plus its moment about the COM
            fp, fc, k = self.fl_ip, self.fl_ic, fl.size
            ends = self.fl_ends
            pivots = pos[ends] + (rot[ends] @ self.fl_p_ends)[..., 0]
            pa, pbw = pivots[:k], pivots[k:]
            raft = rat[fl]
            d = (raft @ (pbw - pa)[:, :, None])[..., 0]
            if self.form == "ambf":  # Bullet's: the pivots' own velocities, each body's turning too
                arms = pivots - pos[ends]
                vp = lv[ends] + _cross(av[ends], arms)
                v_rel = (raft @ (vp[k:] - vp[:k])[:, :, None])[..., 0]
            else:
                v_rel = (raft @ (lv[fc] - lv[fp])[:, :, None])[..., 0]
            m_eff = self._pivot_mass(pos, rot, pbw, ra[fl]) if self.form == "ambf" else self.fl_m
            f = self._spring(self._fl, d - self.fl_eq, v_rel)
            # the limits see the velocity gravity adds over the step too: held for the whole step,
            # a correction blind to it leaves a limit g·dt²/erp short under gravity (0.78 mm at
            # 4 ms: the corpus phantom's hole bodies, whose axes are locked or at a limit, sagged
            # that far below AMBF's, which solves them as constraint rows)
            g_rel = (raft @ self.fl_g_rel[:, :, None])[..., 0]
            f += self._limit(
                d,
                v_rel + (f / m_eff + g_rel) * dt,
                self.fl_low,
                self.fl_high,
                m_eff,
                dt,
                erp,
                self.fl_active,
                (self.fl_ranged, v_rel),
            )
            f_w = (ra[fl] @ f[:, :, None])[..., 0]
            force = self.fl_net @ f_w
            # the force's moments about the child's, then the parent's, centre of mass
            moments = _cross(np.concatenate((pbw, pbw)) - pos[self.fl_arms], np.concatenate((f_w, f_w)))
            torque += self.fl_child_t @ moments[:k] - self.fl_parent_t @ moments[k:]
        self._push(torque, force, pos)

    def _pivot_mass(self, pos, rot, pivot, axes) -> np.ndarray:
        """(k, 3): the mass each free-linear joint's pivot B has along each axis of its frame A
        (``axes``: columns, in the world), its two bodies pushed there (as a constraint row's:
        1 / Σ (1/m + (r×a)·I⁻¹·(r×a)), r from a body's centre of mass to the pivot). The body's
        mass alone, where the pivot is off its centre of mass, overshot: a pendulum bob pushed
        sideways at its pivot 0.1 m above its centre turned 20x as far as the push meant, and a
        bob resting on the floor so flew apart."""
        k = len(pivot)
        ends, inv_m, inv_i = self._pivot_ends()
        cols = axes.transpose(0, 2, 1).reshape(-1, 3)  # the three axes of each joint, one per row
        # both ends at once (the parents', then the children's rows): each row's products as they were
        r = np.repeat(np.concatenate((pivot, pivot)) - pos[ends], 3, axis=0)  # (6k, 3): each arm once per axis
        rxa = _cross(r, np.concatenate((cols, cols))).reshape(2 * k, 3, 3) @ rot[ends]  # r×a, principal frame
        terms = inv_m + (rxa * rxa * inv_i).sum(2)
        total = terms[:k] + terms[k:]  # the parent's, then the child's (0 + the parent's is the parent's)
        return 1.0 / np.maximum(total, 1e-12)

    def _pivot_ends(self):
        """_pivot_mass's constants: the free-linear joints' parents then children, their shared 1/m
        (a column) and principal 1/I (one row per end), sliced once."""
        c = getattr(self, "_pivot_consts", None)
        if c is None:
            ends = np.concatenate((self.fl_ip, self.fl_ic))
            c = self._pivot_consts = (ends, self.inv_m_shared[ends][:, None], self.inv_i_shared[ends][:, None, :])
        return c

    @staticmethod
    def _limit(x, v, low, high, inertia, dt, erp, active=None, ranged=None):
        """Velocity-correcting force that keeps x within [low, high] (low > high: free, Bullet): it
        drives a violation back at -erp·err/dt and only ever pushes. ``v`` (the velocity at the end
        of the step, the step's forces in) may be a callable giving it. ``ranged``: (the axes whose
        range is open, the velocity before the step) or None: AMBF's limit rows there (there while
        low < high: limit_rows.spring_row_velocity): a joint moves toward a limit at a gap g at most
        erp·g/dt, and not at all where it came in fast enough to cross it within the step."""
        active = low <= high if active is None else active
        if active is True:  # every axis limited: the same masks without the &
            over, under, rows = x > high, x < low, None
        else:
            over, under, rows = active & (x > high), active & (x < low), None
        if ranged is not None and ranged[0] is not None:  # rows act where x + v·dt/erp leaves the range
            rows, v0 = ranged
            v = v() if callable(v) else v
            ahead = x + v * (dt / erp)
            rows = rows if np.count_nonzero(rows & ((ahead < low) | (ahead > high))) else None
        if not (np.count_nonzero(over) or np.count_nonzero(under)) and rows is None:  # a third of .any()'s
            return 0.0
        if callable(v):
            v = v()
        gap_lo = x - low
        err = np.where(over, x - high, np.where(under, gap_lo, 0.0))
        f = inertia * (-erp * err / dt - v) / dt
        out = np.where(over, np.minimum(f, 0.0), np.where(under, np.maximum(f, 0.0), 0.0))
        if rows is None:
            return out
        gap_hi = high - x  # Bullet tests the crossing with the velocity before the step
        v0_dt = v0 * dt  # (-v0·dt is -(v0·dt) to the bit: rounding is symmetric)
        slowest = np.where((gap_lo > 0.0) & (-v0_dt > gap_lo), 0.0, -erp * gap_lo / dt)
        fastest = np.where((gap_hi > 0.0) & (v0_dt > gap_hi), 0.0, erp * gap_hi / dt)
        pushes = np.maximum(inertia * (slowest - v) / dt, 0.0) + np.minimum(inertia * (fastest - v) / dt, 0.0)
        return np.where(rows if active is True else rows & active, pushes, out)
