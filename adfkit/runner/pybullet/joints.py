"""Joints between bodies that PyBullet cannot make as Featherstone links, and the per-step
spring, damping and limit forces PyBullet's constraints lack (adf-format.md §8).

PyBullet's createConstraint joins maximal-coordinate bodies only with JOINT_FIXED,
JOINT_POINT2POINT and JOINT_GEAR. So:
- `fixed` → JOINT_FIXED; `p2p` → JOINT_POINT2POINT at the pivots;
- `six dof`/`six dof spring`/`cone twist`/springs whose linear range is locked → a
  JOINT_POINT2POINT at the pivot plus angular spring-damper and limit torques applied each
  control step (the 6-DOF spring approximation, see docs/runner.md);
- the same types with a free linear range → no constraint at all; linear and angular
  springs and limits are all applied as forces;
- a revolute joint that closes a loop → two JOINT_POINT2POINT constraints along the axis.
Springs and dampers are integrated implicitly over the control step (backward Euler on the two
bodies' relative motion, so stable at any gain, as Bullet's own 6-DOF spring rows are); limits
are velocity corrections with Baumgarte feedback on what the spring leaves. Neither can do more
than stop the joint's relative motion within the step.
"""

from __future__ import annotations

from itertools import chain

import numpy as np
import pybullet as pb

from ...model.semantics import JointKind
from ..rotations import euler_xyz, matrix_to_pq, pose_matrix, quat_to_matrix
from ..springs import SpringJoint, spring_joint  # noqa: F401 - built here for PyBullet

FIXED_SPAN = 0.005  # m: the pivots' span of a fixed joint whose origin is at the child's centre of mass
HINGE_HALF_SPAN = 0.01  # m: the two p2p constraints of a loop-closing hinge sit ±this along the axis


def _static_frame(cid: int, body):
    if body.link == -1:
        return pb.getBasePositionAndOrientation(body.uid, physicsClientId=cid)
    st = pb.getLinkState(body.uid, body.link, computeForwardKinematics=True, physicsClientId=cid)
    return st[0], st[1]  # constraint pivots are in the link's inertial frame


def _multibody(body) -> bool:
    return getattr(body, "articulation", None) is not None


def _static(body) -> bool:
    return bool(getattr(body, "static", False))


class ConstraintRefused(Exception):
    """PyBullet could not join the two bodies as asked (the world warns and skips the joint)."""


_JTYPE_NAMES = {
    pb.JOINT_FIXED: "fixed",
    pb.JOINT_POINT2POINT: "point-to-point",
    pb.JOINT_PRISMATIC: "prismatic",
    pb.JOINT_GEAR: "gear",
}


def make_constraint(
    cid: int, kind: JointKind, parent, child, frame_a: np.ndarray, frame_b: np.ndarray, max_force: float
) -> list[tuple[int, np.ndarray, np.ndarray, np.ndarray | None]]:
    """PyBullet constraints for a joint: [(constraint id, pivot in parent frame, pivot in child
    frame, slide axis in the parent frame or None)]."""
    out = []

    def create(a, b, jtype, axis, pa, pb_, oa, ob):
        return pb.createConstraint(
            a.uid,
            a.link,
            b.uid,
            b.link,
            jtype,
            list(map(float, axis)) if axis is not None else [0, 0, 0],
            list(map(float, pa)),
            list(map(float, pb_)),
            list(oa),
            list(ob),
            physicsClientId=cid,
        )

    def to_world(moving, mp, mo, static, sp, so, jtype):
        # the static end's pivot in the world frame; the constraint holds the moving end there
        pw, ow = matrix_to_pq(pose_matrix(*_static_frame(cid, static)) @ pose_matrix(sp, so))
        try:
            return pb.createConstraint(
                moving.uid,
                moving.link,
                -1,
                -1,
                jtype,
                [0, 0, 0],
                list(map(float, mp)),
                list(map(float, pw)),
                list(mo),
                list(ow),
                physicsClientId=cid,
            )
        except pb.error:
            return None

    def add(jtype, pa, pb_, oa=(0, 0, 0, 1), ob=(0, 0, 0, 1), axis=None):
        if axis is None and _static(parent) and _multibody(child):
            # A multibody held by a point constraint to a static (mass 0) rigid body: PyBullet
            # 3.2.7 builds its rows reading freed memory (btMultiBodyConstraint::
            # fillMultiBodyConstraint, valgrind), a segfault in the first step depending on the
            # heap (the corpus's parallel_structure.yaml whenever its output went to a pipe). The
            # static body never moves: the constraint holds the pivot in the world frame instead.
            c = to_world(child, pb_, ob, parent, pa, oa, jtype)
        elif axis is None and _static(child) and _multibody(parent):
            c = to_world(parent, pa, oa, child, pb_, ob, jtype)
        else:
            # PyBullet joins a multibody link to a free (maximal-coordinate) body only with the
            # link first (btMultiBodyPoint2Point/btMultiBodyFixedConstraint take the multibody as
            # body A): such a joint is made with its ends swapped, which is the same joint
            swap = axis is None and not _multibody(parent) and _multibody(child)
            try:
                c = (
                    create(child, parent, jtype, None, pb_, pa, ob, oa)
                    if swap
                    else create(parent, child, jtype, axis, pa, pb_, oa, ob)
                )
            except pb.error:
                c = None
            if c is None and _static(parent):
                # PyBullet refuses e.g. a fixed constraint from a static (mass 0) body to a
                # multibody base; a static parent never moves: from the child to the world frame
                c = to_world(child, pb_, ob, parent, pa, oa, jtype)
        if c is None:
            raise ConstraintRefused(
                f"PyBullet refused a {_JTYPE_NAMES.get(jtype, jtype)} constraint between "
                f"{getattr(parent, 'key', 'the parent')} and {getattr(child, 'key', 'the child')}"
            )
        pb.changeConstraint(c, maxForce=max_force, physicsClientId=cid)
        out.append(
            (c, np.asarray(pa, float), np.asarray(pb_, float), None if axis is None else np.asarray(axis, float))
        )

    if kind is JointKind.FIXED:
        # Three point pivots at non-collinear points of the joint frame, not JOINT_FIXED:
        # PyBullet's fixed constraint ignores both frame orientations and holds the two
        # inertial frames parallel (measured: the corpus needle's thread turns 90 degrees off
        # the needle in 0.1 s); point pivots keep the file's relative pose exactly.
        for e in fixed_pivots(frame_b):
            add(pb.JOINT_POINT2POINT, frame_a[:3, :3] @ e + frame_a[:3, 3], frame_b[:3, :3] @ e + frame_b[:3, 3])
    elif kind is JointKind.PRISMATIC:
        # between multibody links only (the caller checks): btMultiBodySliderConstraint, its
        # axis given in the parent's link (COM) frame, along the joint's x axis as the
        # multibody's own prismatic joints are (articulation.py); orientation held as it is
        pa, oa = matrix_to_pq(frame_a)
        pbp, ob = matrix_to_pq(frame_b)
        add(pb.JOINT_PRISMATIC, pa, pbp, oa, ob, axis=frame_a[:3, 0])
    elif kind is JointKind.REVOLUTE:
        for s in (-HINGE_HALF_SPAN, HINGE_HALF_SPAN):
            add(pb.JOINT_POINT2POINT, frame_a[:3, 3] + s * frame_a[:3, 2], frame_b[:3, 3] + s * frame_b[:3, 2])
    else:
        add(pb.JOINT_POINT2POINT, frame_a[:3, 3], frame_b[:3, 3])
    return out


def fixed_pivots(frame_b: np.ndarray) -> list[np.ndarray]:
    """The three pivots of a fixed joint, in the joint frame: its origin, the point as far beyond
    the child's centre of mass (the child's far end: where a chain hung from it pulls) and that
    point moved as far again across. Pivots spanning the child hold it where its load comes in:
    pivots 5 mm to the side of the joint origin, off a 2.4 mm thread element, let Bullet's
    solver leave the element 27° off the needle as the thread hung from it (its 50 iterations
    do not converge a 40-element chain, whose joint impulses start from zero every step), and
    the joint 2.3 mm open at those pivots; spanning the element: under 3°."""
    com = -frame_b[:3, :3].T @ frame_b[:3, 3]  # the child's centre of mass in the joint frame
    reach = 2.0 * float(np.linalg.norm(com))
    if reach < 1e-4:  # the joint at the child's centre of mass: any span will do
        return [np.zeros(3), np.array([FIXED_SPAN, 0.0, 0.0]), np.array([0.0, FIXED_SPAN, 0.0])]
    far = 2.0 * com
    across = np.cross(far, np.eye(3)[int(np.argmin(np.abs(far)))])
    return [np.zeros(3), far, far + reach * across / np.linalg.norm(across)]


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (n, 3) arrays: np.cross's products in np.cross's order,
    without its axis bookkeeping (a third of the cost at this size)."""
    out = np.empty_like(a)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


class SpringSet:
    """All force-driven joints, evaluated together with numpy each control step.

    The per-step cost is mostly PyBullet's: one getBasePositionAndOrientation and one
    getBaseVelocity per free body (PyBullet has no batched call for them) and one
    applyExternalTorque per dynamic body. Everything that does not change between steps (the
    joints' index subsets, gains, limits and incidence blocks) is sliced once here, and the
    calls pass their arguments by position (keyword parsing is a tenth of a call's cost)."""

    def __init__(self, joints: list[SpringJoint], cid: int, gravity=(0.0, 0.0, 0.0)) -> None:
        """``gravity``: the world's; a body's own (``SimBody.gravity``) replaces it."""
        self.joints = joints
        self.cid = cid
        self.world_gravity = np.asarray(gravity, dtype=float)
        self.pq: dict[tuple, tuple] = {}  # (uid, -1) -> (position, quaternion) of each free body, as last read
        self._order = None
        n = len(joints)
        if not n:
            return
        st = np.stack
        fa, fb = st([j.frame_a for j in joints]), st([j.frame_b for j in joints])
        self.ra_in_p, self.pa_in_p = fa[:, :3, :3], fa[:, :3, 3]
        self.rb_in_c, self.pb_in_c = fb[:, :3, :3], fb[:, :3, 3]
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
        self.ang_active = self.ang_low <= self.ang_high
        fl = self.free_lin
        # the free-linear joints' constant blocks, sliced once (the same values every step)
        self.fl_ip, self.fl_ic = self.ip[fl], self.ic[fl]
        self.fl_pa = self.pa_in_p[fl][:, :, None]
        self.fl_pb = self.pb_in_c[fl][:, :, None]
        self.fl_eq, self.fl_low, self.fl_high = self.eq_lin[fl], self.lin_low[fl], self.lin_high[fl]
        self.fl_k, self.fl_c = self.k_lin[fl], self.c_lin[fl]
        self.fl_active = self.fl_low <= self.fl_high
        self.fl_m = self.m_eff[fl][:, None]
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
        self._gains_dt = None

    def _gains(self, dt: float):
        """Per-joint constants of the implicit spring-damper at this step: the denominators
        1 + (c·dt + k·dt²)/I (I the joint's effective inertia or mass)."""
        if self._gains_dt != dt:
            i_eff, m_eff = self.i_eff[:, None], self.m_eff[:, None]
            self._den_ang = 1.0 + (self.c_ang * dt + self.k_ang * dt**2) / i_eff
            self._den_lin = 1.0 + (self.c_lin * dt + self.k_lin * dt**2) / m_eff
            self._fl_den = self._den_lin[self.free_lin]
            self._gains_dt = dt
        return self._den_ang, self._den_lin

    @staticmethod
    def _spring(k, c, x, v, den, dt):
        """Backward-Euler spring-damper: the force that leaves the pair moving at the velocity
        the spring and damper give it at the end of the step, -(k·x + (c + k·dt)·v) / den: for
        small gains the explicit -k·x - c·v, for large ones at most what stops the motion."""
        return -(k * x + (c + k * dt) * v) / den

    def _read_plan(self):
        """How to read every body's COM state with the fewest PyBullet calls: free bodies and
        multibody bases one by one (PyBullet has no batch call for them), the links of each
        multibody with one getLinkStates. Built on first use (bodies have their uids then)."""
        bases, links = [], {}
        for i, b in enumerate(self.bodies):
            if b.link < 0:
                bases.append((i, b.uid))
            else:
                links.setdefault(b.uid, []).append((i, b.link))
        order = [i for i, _ in bases] + [i for group in links.values() for i, _ in group]
        self._bases = [uid for _, uid in bases]
        self._base_keys = [(uid, -1) for uid in self._bases]
        self._links = [(uid, [k for _, k in group]) for uid, group in links.items()]
        self._order = np.argsort(np.array(order, dtype=int))  # read order -> body order
        self._in_order = bool(np.array_equal(self._order, np.arange(len(order))))
        self._apply_ids = [(i, self.bodies[i].uid, self.bodies[i].link, bool(self.pushed[i])) for i in self.dynamic]

    def states(self):
        """(positions, rotation matrices, linear and angular velocities) of every body's COM;
        the free bodies' (position, quaternion) stay in ``pq`` by (uid, -1) until the next read."""
        if self._order is None:
            self._read_plan()
        cid = self.cid
        bases = self._bases
        get_pose, get_vel, get_links = pb.getBasePositionAndOrientation, pb.getBaseVelocity, pb.getLinkStates
        poses = [get_pose(uid, cid) for uid in bases]
        rows = [p + q + v + w for (p, q), (v, w) in zip(poses, [get_vel(uid, cid) for uid in bases])]
        self.pq = dict(zip(self._base_keys, poses))
        for uid, ks in self._links:  # computeLinkVelocity, computeForwardKinematics
            rows += [s[0] + s[1] + s[6] + s[7] for s in get_links(uid, ks, 1, 1, cid)]
        a = np.fromiter(chain.from_iterable(rows), float, 13 * len(rows)).reshape(-1, 13)
        if not self._in_order:
            a = a[self._order]
        return (a[:, 0:3], quat_to_matrix(a[:, 3:7]), a[:, 7:10], a[:, 10:13])

    def apply(self, dt: float, erp: float = 0.2) -> None:
        if not self.joints:
            return
        den_ang, den_lin = self._gains(dt)
        pos, rot, lv, av = self.states()
        ip, ic = self.ip, self.ic
        ra = rot[ip] @ self.ra_in_p  # joint frame A in the world
        rat = ra.transpose(0, 2, 1)
        rel = rat @ (rot[ic] @ self.rb_in_c)  # frame B in frame A
        ang = euler_xyz(rel)
        w_rel = (rat @ (av[ic] - av[ip])[:, :, None])[..., 0]
        # angular springs and limits, in joint frame A, turned into the world
        i_eff = self.i_eff_col
        tau = self._spring(self.k_ang, self.c_ang, ang - self.eq_ang, w_rel, den_ang, dt)
        tau += self._limit(ang, w_rel + tau * dt / i_eff, self.ang_low, self.ang_high, i_eff, dt, erp, self.ang_active)
        torque = self.net @ (ra @ tau[:, :, None])[..., 0]
        force = None
        fl = self.free_lin
        if fl.size:
            # free linear axes: spring, damper and limits on the pivot offset in frame A; a
            # force at the pivot = the same force at the COM plus its moment about the COM
            fp, fc = self.fl_ip, self.fl_ic
            pa = pos[fp] + (rot[fp] @ self.fl_pa)[..., 0]
            pbw = pos[fc] + (rot[fc] @ self.fl_pb)[..., 0]
            raft = rat[fl]
            d = (raft @ (pbw - pa)[:, :, None])[..., 0]
            v_rel = (raft @ (lv[fc] - lv[fp])[:, :, None])[..., 0]
            m_eff = self.fl_m
            f = self._spring(self.fl_k, self.fl_c, d - self.fl_eq, v_rel, self._fl_den, dt)
            # the limits see the velocity gravity adds over the step too: held for the whole step,
            # a correction blind to it leaves a limit g·dt²/erp short under gravity (0.78 mm at
            # 4 ms: the corpus phantom's hole bodies, whose axes are locked or at a limit, sagged
            # that far below AMBF's, which solves them as constraint rows)
            g_rel = (raft @ self.fl_g_rel[:, :, None])[..., 0]
            f += self._limit(
                d, v_rel + (f / m_eff + g_rel) * dt, self.fl_low, self.fl_high, m_eff, dt, erp, self.fl_active
            )
            f_w = (ra[fl] @ f[:, :, None])[..., 0]
            force = self.fl_net @ f_w
            torque += self.fl_child_t @ _cross(pbw - pos[fc], f_w) - self.fl_parent_t @ _cross(pbw - pos[fp], f_w)
        torque = torque.tolist()
        if force is not None:
            force, pos = force.tolist(), pos.tolist()
        cid, frame = self.cid, pb.WORLD_FRAME
        apply_torque, apply_force = pb.applyExternalTorque, pb.applyExternalForce
        for i, uid, link, pushed in self._apply_ids:
            apply_torque(uid, link, torque[i], frame, cid)
            if pushed:
                apply_force(uid, link, force[i], pos[i], frame, cid)

    @staticmethod
    def _limit(x, v, low, high, inertia, dt, erp, active=None):
        """Velocity-correcting force that keeps x within [low, high] (low > high: free, Bullet):
        it drives a violation back at -erp·err/dt and only ever pushes, never pulls."""
        if active is None:
            active = low <= high
        over = active & (x > high)
        under = active & (x < low)
        if not (over.any() or under.any()):
            return 0.0
        err = np.where(over, x - high, np.where(under, x - low, 0.0))
        f = inertia * (-erp * err / dt - v) / dt
        return np.where(over, np.minimum(f, 0.0), np.where(under, np.maximum(f, 0.0), 0.0))
