"""One physics step of AMBF's constraint solver over a chain of hinges and sliders, as Bullet
(AMBF's external/bullet, 2.8x) builds and solves it, in maximal coordinates: each body a
btRigidBody, each joint a btHingeConstraint (getInfo2InternalUsingFrameOffset: three linear and
two angular locking rows, then one row along the axis for its motor and limit) or a
btSliderConstraint (two angular and two linear locking rows, one row along the axis for its
motor and limit, one angular row about it), solved by btSequentialImpulseConstraintSolver's
projected Gauss-Seidel: the joints' rows start from no impulse each step (joint rows are not
warm-started), AMBF's ten iterations, each row in turn

    Δλ = rhs − cfm·λ − J·Δv / (J·M⁻¹·Jᵀ),   rhs = (c − J·v₀) / (J·M⁻¹·Jᵀ),

λ clamped to the row's bounds, v₀ the bodies' velocities after their damping and the step's
external forces (gravity). Ten iterations do not settle a chain's coupled rows: what the step
leaves is what AMBF's PSM and KUKA move with under joint commands.

The chain's state comes from the engine, with what its bodies carry apart from the joints'
motion (``Joint.pivot_a``, ``axis_b``, ``twist``: the locking rows' position errors, closed at
erp a step); ``joint_velocities`` reads the joints' velocities out of the bodies' velocities
the step leaves. Engine-neutral: numpy only."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from itertools import chain

import numpy as np

from ..model.semantics import HINGE_LIMIT_BIAS
from ..model.semantics import SLIDER_LIMIT_ERP as GLOBAL_ERP  # a slider's limit row: the world's erp

#: btContactSolverInfo's m_numIterations, which AMBF keeps
AMBF_ITERATIONS = 10
_EPS = 1.1920929e-07  # SIMD_EPSILON (float)


@dataclass
class Body:
    """A btRigidBody of the chain at the step's start: centre of mass, world inverse inertia,
    velocities (after damping and the step's external impulses), inverse mass (0: static)."""

    com: np.ndarray
    inv_mass: float
    inv_inertia: np.ndarray  # 3x3, world frame
    v: np.ndarray
    w: np.ndarray
    inertia: np.ndarray | None = None  # 3x3, world frame (its inverse where not given)


@dataclass
class Joint:
    """A hinge ("revolute"), slider ("prismatic") or point joint ("p2p") from body ``parent`` (Bullet's A) to
    ``child`` (B). ``pivot``: the child's joint frame origin in the world; ``axis``: the hinge
    axis or the slide direction; ``y``: the parent's joint frame y axis (a hinge's fallback
    direction). ``position``/``velocity``: the joint's; ``limits`` when enabled; ``motor``:
    (target velocity, slowed near a limit as Bullet's getMotorFactor slows it; cfm; max
    impulse) when its motor is on."""

    kind: str
    parent: int
    child: int
    pivot: np.ndarray
    axis: np.ndarray
    y: np.ndarray
    position: float
    velocity: float
    erp: float
    limits: tuple[float, float] | None = None
    motor: tuple[float, float, float] | None = None
    # where the bodies have come apart at the joint: the parent's pivot, the child's axis, the
    # child's turn about the axis (a slider's), when they are not the child's pivot, the axis, 0
    pivot_a: np.ndarray | None = None
    axis_b: np.ndarray | None = None
    twist: float = 0.0
    cfm: float = 0.0  # a point joint's rows' (AMBF sets the joint's cfm on a btPoint2PointConstraint)

    def errors(self) -> tuple[np.ndarray, np.ndarray]:
        """The pivots' gap (child's less parent's) and the axes' cross product (parent's ×
        child's): what the locking rows close at erp a step."""
        ofs = self.pivot - self.pivot_a if self.pivot_a is not None else _Z
        u = cross3(self.axis, self.axis_b) if self.axis_b is not None else _Z
        return ofs, u


_Z = np.zeros(3)


@dataclass
class Rows:
    a: list[int] = field(default_factory=list)
    b: list[int] = field(default_factory=list)
    j: list[tuple] = field(default_factory=list)  # J1 linear, J1 angular, J2 linear, J2 angular (3 each)
    c: list[float] = field(default_factory=list)
    cfm: list[float] = field(default_factory=list)
    lo: list[float] = field(default_factory=list)
    hi: list[float] = field(default_factory=list)

    def add(self, a, b, j1l, j1a, j2l, j2a, c=0.0, cfm=0.0, lo=-math.inf, hi=math.inf):
        self.a.append(a)
        self.b.append(b)
        self.j.append((j1l, j1a, j2l, j2a))
        self.c.append(c)
        self.cfm.append(cfm)
        self.lo.append(lo)
        self.hi.append(hi)


def cross3(a, b) -> np.ndarray:
    """a × b of two 3-vectors (numpy's cross costs ten times as much on one pair), on Python
    floats (the same products and differences as numpy's scalars, at a third of their cost)."""
    a0, a1, a2 = a.tolist() if isinstance(a, np.ndarray) else a
    b0, b1, b2 = b.tolist() if isinstance(b, np.ndarray) else b
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def plane_space(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """btPlaneSpace1: two unit vectors across ``n``, as Bullet picks them."""
    if abs(n[2]) > math.sqrt(0.5):
        a = n[1] ** 2 + n[2] ** 2
        k = 1.0 / math.sqrt(a)
        p = np.array([0.0, -n[2] * k, n[1] * k])
        return p, np.array([a * k, -n[0] * p[2], n[0] * p[1]])
    a = n[0] ** 2 + n[1] ** 2
    k = 1.0 / math.sqrt(a)
    p = np.array([-n[1] * k, n[0] * k, 0.0])
    return p, np.array([-n[2] * p[1], n[2] * p[0], a * k])


def _offset_frame(bodies, jt: Joint, origin_a: np.ndarray, slide: float):
    """The frame-offset construction both constraints share: the rows' lever arms relA, relB
    and the directions p, q across the axis, weighted by the bodies' inverse masses."""
    A, B = bodies[jt.parent], bodies[jt.child]
    mi = A.inv_mass + B.inv_mass
    fa = B.inv_mass / mi if mi > 0.0 else 0.5
    fb = 1.0 - fa
    ax = jt.axis
    rel_b = jt.pivot - B.com
    proj_b = ax * (rel_b @ ax)
    ortho_b = rel_b - proj_b
    rel_a = origin_a - A.com
    proj_a = ax * (rel_a @ ax)
    ortho_a = rel_a - proj_a
    total = proj_a + ax * slide - proj_b
    rel_a = ortho_a + total * fa
    rel_b = ortho_b - total * fb
    p = ortho_b * fa + ortho_a * fb
    n2 = p @ p
    p = p / math.sqrt(n2) if n2 > _EPS else jt.y
    return fa, fb, rel_a, rel_b, p, cross3(ax, p)


def hinge_rows(rows: Rows, bodies, jt: Joint, dt: float) -> None:
    """btHingeConstraint::getInfo2InternalUsingFrameOffset, AMBF's hinge (reference frame A:
    its angle is the joint's): locking rows with no position error, then the axis row."""
    A, B = bodies[jt.parent], bodies[jt.child]
    a, b, ax = jt.parent, jt.child, jt.axis
    fa, fb, rel_a, rel_b, p, q = _offset_frame(bodies, jt, jt.pivot if jt.pivot_a is None else jt.pivot_a, 0.0)
    static = A.inv_mass < _EPS or B.inv_mass < _EPS
    lim = jt.limits if jt.limits is not None and jt.limits[0] <= jt.limits[1] else None
    limit = lim is not None and not lim[0] <= jt.position <= lim[1]
    k = jt.erp / dt
    ofs, u = jt.errors()
    rows.add(a, b, p, cross3(rel_a, p), -p, -cross3(rel_b, p), k * (p @ ofs))
    ta, tb = cross3(rel_a, q), cross3(rel_b, q)
    if static and limit:  # Bullet's "more rigid" weighting against a static body
        ta, tb = ta * fa, tb * fb
    rows.add(a, b, q, ta, -q, -tb, k * (q @ ofs))
    ta, tb = cross3(rel_a, ax), cross3(rel_b, ax)
    if static:
        ta, tb = ta * fa, tb * fb
    rows.add(a, b, ax, ta, -ax, -tb, k * (ax @ ofs))
    rows.add(a, b, _Z, p, _Z, -p, k * (u @ p))
    rows.add(a, b, _Z, q, _Z, -q, k * (u @ q))
    if not (limit or jt.motor is not None):
        return
    # the row's velocity is −(joint velocity): the hinge is built with reference frame A
    c, cfm, lo, hi = 0.0, 0.0, -math.inf, math.inf
    powered = jt.motor is not None and not (limit and lim[0] == lim[1])
    if powered:
        target, cfm, imp = jt.motor
        c = -target
        lo, hi = -imp, imp
    if limit:
        q_ = jt.position
        err = q_ - lim[1] if q_ > lim[1] else q_ - lim[0]  # Bullet's limit error, in the row's sense
        c += jt.erp / dt * err
        if lim[0] == lim[1]:
            lo, hi = -math.inf, math.inf
        elif err > 0.0:  # past the upper limit: the row may only push the joint down
            lo, hi = 0.0, math.inf
            if jt.velocity > 0.0:
                c = max(c, jt.velocity)  # relaxation 1: the speed further out, turned back
        else:
            lo, hi = -math.inf, 0.0
            if jt.velocity < 0.0:
                c = min(c, jt.velocity)
        c *= HINGE_LIMIT_BIAS
    rows.add(a, b, _Z, ax, _Z, -ax, c, cfm, lo, hi)


def slider_rows(rows: Rows, bodies, jt: Joint, dt: float) -> None:
    """btSliderConstraint::getInfo2NonVirtual with the frame offset, AMBF's slider (linear
    reference frame A): two angular and two linear locking rows with no position error, the
    axis row (motor, limit at the world's erp 0.2, no bounce), the angular row about the axis
    (its angular limits are 0 and 0)."""
    A, B = bodies[jt.parent], bodies[jt.child]
    a, b, ax = jt.parent, jt.child, jt.axis
    static = A.inv_mass < _EPS or B.inv_mass < _EPS
    ap, aq = plane_space(ax)
    k = GLOBAL_ERP / dt  # the slider's softness 1 times the world's erp
    ofs, u = jt.errors()
    rows.add(a, b, _Z, ap, _Z, -ap, k * (u @ ap))
    rows.add(a, b, _Z, aq, _Z, -aq, k * (u @ aq))
    lim = jt.limits if jt.limits is not None and jt.limits[0] <= jt.limits[1] else None
    depth = 0.0
    if lim is not None and not lim[0] <= jt.position <= lim[1]:
        depth = jt.position - (lim[1] if jt.position > lim[1] else lim[0])
    origin_a = (jt.pivot if jt.pivot_a is None else jt.pivot_a) - ax * jt.position
    _fa, _fb, rel_a, rel_b, p, q = _offset_frame(bodies, jt, origin_a, jt.position - depth)
    ofs = ofs - ax * (ofs @ ax)  # the gap across the axis (along it is the slide)
    rows.add(a, b, p, cross3(rel_a, p), -p, -cross3(rel_b, p), k * (p @ ofs))
    ta, tb = cross3(rel_a, q), cross3(rel_b, q)
    if static:  # its angular limit is always solved (0 and 0)
        ta, tb = ta * _fa, tb * _fb
    rows.add(a, b, q, ta, -q, -tb, k * (q @ ofs))
    if depth != 0.0 or jt.motor is not None:
        c, cfm, lo, hi = 0.0, 0.0, -math.inf, math.inf
        powered = jt.motor is not None and not (depth != 0.0 and lim[0] == lim[1])
        if powered:
            target, cfm, imp = jt.motor
            c = -target
            lo, hi = -imp, imp
        if depth != 0.0:
            c += GLOBAL_ERP / dt * depth
            if lim[0] == lim[1]:
                lo, hi = -math.inf, math.inf
            elif depth > 0.0:
                lo, hi = 0.0, math.inf
            else:
                lo, hi = -math.inf, 0.0
        ja, jb = (_Z, _Z) if static else (cross3(rel_a, ax), -cross3(rel_b, ax))
        rows.add(a, b, ax, ja, -ax, jb, c, cfm, lo, hi)
    rows.add(a, b, _Z, ax, _Z, -ax, k * jt.twist)


def point_rows(rows: Rows, bodies, jt: Joint, dt: float) -> None:
    """btPoint2PointConstraint::getInfo2NonVirtual, AMBF's p2p joint: three rows holding the
    child's pivot on the parent's, at the joint's erp and cfm."""
    A, B = bodies[jt.parent], bodies[jt.child]
    pivot_a = jt.pivot if jt.pivot_a is None else jt.pivot_a
    rel_a, rel_b = pivot_a - A.com, jt.pivot - B.com
    ofs = jt.pivot - pivot_a
    k = jt.erp / dt
    for e in np.eye(3):
        rows.add(jt.parent, jt.child, e, cross3(rel_a, e), -e, -cross3(rel_b, e), k * float(e @ ofs), jt.cfm)


_ROWS = {"revolute": hinge_rows, "prismatic": slider_rows, "p2p": point_rows}


def island_order(n: int) -> list[int]:
    """The order Bullet's solver takes ``n`` constraints of one island in: the world's list
    sorted by island (btAlignedObjectArray::quickSort, not stable: equal keys are swapped), the
    chain's own constraints alone (the world's others would shuffle it otherwise)."""
    order = list(range(n))

    def sort(lo: int, hi: int) -> None:
        i, j = lo, hi
        while i <= j:  # every key equal: nothing is less than the pivot
            order[i], order[j] = order[j], order[i]
            i += 1
            j -= 1
        if lo < j:
            sort(lo, j)
        if i < hi:
            sort(i, hi)

    if n > 1:
        sort(0, n - 1)
    return order


def solve(
    bodies: list[Body],
    joints: list[Joint],
    dt: float,
    added: list[int] | None = None,
    iterations: int = AMBF_ITERATIONS,
) -> np.ndarray:
    """The bodies' velocities (n, 6: linear, angular) after the step's joint rows, ``iterations``
    sweeps; ``added``: the joints in the order AMBF adds their constraints to the world (its
    file's order), which Bullet's island sort then shuffles."""
    added = list(range(len(joints))) if added is None else added
    rows = Rows()
    for k in island_order(len(joints)):
        jt = joints[added[k]]
        _ROWS[jt.kind](rows, bodies, jt, dt)
    n, m = len(bodies), len(rows.c)
    J = np.zeros((m, 6 * n))
    r = np.arange(m)[:, None]
    six = np.arange(6)
    j12 = np.concatenate(list(chain.from_iterable(rows.j))).reshape(m, 12)  # (np.array's nesting costs 2x)
    J[r, 6 * np.array(rows.a)[:, None] + six] = j12[:, :6]  # a row's two bodies differ
    J[r, 6 * np.array(rows.b)[:, None] + six] = j12[:, 6:]
    minv = np.zeros((6 * n, 6 * n))
    v0 = np.zeros(6 * n)
    for k, bd in enumerate(bodies):
        minv[6 * k : 6 * k + 3, 6 * k : 6 * k + 3] = np.eye(3) * bd.inv_mass
        minv[6 * k + 3 : 6 * k + 6, 6 * k + 3 : 6 * k + 6] = bd.inv_inertia
        v0[6 * k : 6 * k + 3], v0[6 * k + 3 : 6 * k + 6] = bd.v, bd.w
    B = minv @ J.T
    A = J @ B
    diag = np.diag(A).copy()
    jinv = np.where(np.abs(diag) > _EPS, 1.0 / np.where(diag == 0.0, 1.0, diag), 0.0)
    rhs = ((np.asarray(rows.c) - J @ v0) * jinv).tolist()
    cfm, lo, hi, jin = rows.cfm, rows.lo, rows.hi, jinv.tolist()
    lam = np.zeros(m)
    now = [0.0] * m  # lam's values as Python floats: the sweep's scalar arithmetic without numpy's
    rows_a = [a.dot for a in A]
    for _ in range(iterations):
        for i in range(m):
            li = now[i]
            s = li + rhs[i] - li * cfm[i] - jin[i] * float(rows_a[i](lam))
            s = lo[i] if s < lo[i] else s
            lam[i] = now[i] = hi[i] if s > hi[i] else s
    return (v0 + B @ lam).reshape(n, 6)


def joint_velocities(bodies: list[Body], joints: list[Joint], v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The joints' velocities that carry the bodies' momentum ``v`` (n, 6) best: the projection
    of the bodies' velocities onto the chain's joints weighted by the bodies' masses, qd =
    (Jᵀ·M·J)⁻¹·Jᵀ·M·v with J the bodies' velocities per unit of joint velocity. Where the rows
    left the chain together this is each joint's own velocity; where ten iterations left it
    apart (a body turned about its own centre, its pivot opening) it is what the chain's
    locking rows make of that once they settle (a moving base: its six velocities come first,
    not returned), and the bodies' velocities (n, 6) those joint velocities give."""
    n = len(bodies)
    children: dict[int, list[int]] = {}
    for k, jt in enumerate(joints):
        children.setdefault(jt.parent, []).append(k)
    moving_base = bodies[0].inv_mass > 0.0
    base = 6 if moving_base else 0
    J = np.zeros((6 * n, base + len(joints)))
    if moving_base:
        for b in range(n):
            J[6 * b : 6 * b + 3, 0:3] = np.eye(3)
            r = bodies[b].com - bodies[0].com
            J[6 * b : 6 * b + 3, 3:6] = -np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
            J[6 * b + 3 : 6 * b + 6, 3:6] = np.eye(3)
    for k, jt in enumerate(joints):
        stack = [jt.child]
        while stack:  # the joint moves its child and everything beyond it
            b = stack.pop()
            col = base + k
            if jt.kind == "revolute":
                J[6 * b : 6 * b + 3, col] = cross3(jt.axis, bodies[b].com - jt.pivot)
                J[6 * b + 3 : 6 * b + 6, col] = jt.axis
            else:
                J[6 * b : 6 * b + 3, col] = jt.axis
            stack.extend(joints[c].child for c in children.get(b, []))
    M = np.zeros((6 * n, 6 * n))
    for b, bd in enumerate(bodies):
        if bd.inv_mass > 0.0:
            M[6 * b : 6 * b + 3, 6 * b : 6 * b + 3] = np.eye(3) / bd.inv_mass
            M[6 * b + 3 : 6 * b + 6, 6 * b + 3 : 6 * b + 6] = (
                bd.inertia if bd.inertia is not None else np.linalg.pinv(bd.inv_inertia)
            )
    JtM = J.T @ M
    qd = np.linalg.lstsq(JtM @ J, JtM @ v.reshape(-1), rcond=None)[0]
    return qd[base:], (J @ qd).reshape(n, 6)
