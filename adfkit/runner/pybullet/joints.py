"""Joints between bodies that PyBullet cannot make as Featherstone links (adf-format.md §8).

PyBullet's createConstraint joins maximal-coordinate bodies only with JOINT_FIXED,
JOINT_POINT2POINT and JOINT_GEAR. So:
- `fixed` → JOINT_FIXED; `p2p` → JOINT_POINT2POINT at the pivots;
- `six dof`/`six dof spring`/`cone twist`/springs whose linear range is locked → a
  JOINT_POINT2POINT at the pivot plus angular spring-damper and limit torques applied each
  control step (the 6-DOF spring approximation, see docs/runner.md);
- the same types with a free linear range → no constraint at all; linear and angular
  springs and limits are all applied as forces;
- a revolute joint that closes a loop → two JOINT_POINT2POINT constraints along the axis.
The spring, damping and limit forces are spring_forces.py's.
"""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ...model.semantics import JointKind, body_joint_frames
from ..rotations import invert, matrix_to_pq, pose_matrix, pose_to_matrix
from ..springs import spring_joint  # noqa: F401 - built here for PyBullet

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


def com_frames(joint, parent, child) -> tuple[np.ndarray, np.ndarray]:
    """The joint's frames (4x4) in its parent's and its child's centre-of-mass frames."""
    a, b = body_joint_frames(joint, parent.body, child.body)
    return invert(parent.com_in_body) @ pose_to_matrix(a), invert(child.com_in_body) @ pose_to_matrix(b)


def make_constraint(
    cid: int,
    kind: JointKind,
    parent,
    child,
    frame_a: np.ndarray,
    frame_b: np.ndarray,
    max_force: float,
    gyration_span: bool = False,
) -> list[tuple[int, np.ndarray, np.ndarray, np.ndarray | None]]:
    """PyBullet constraints for a joint: [(constraint id, pivot in parent frame, pivot in child
    frame, slide axis in the parent frame or None)]. ``gyration_span``: a fixed joint's pivots
    span at least the child's radius of gyration (fixed_pivots; AMBF's bodies asked for)."""
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
        least = gyration_radius(child) if gyration_span else 0.0
        for e in fixed_pivots(frame_b, least):
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


def gyration_radius(body) -> float:
    """m, sqrt(largest principal inertia / mass) of a moving body (0 for a static one)."""
    mass, inertia = float(getattr(body, "mass", 0.0) or 0.0), getattr(body, "inertia", None)
    if mass <= 0.0 or not inertia:
        return 0.0
    return float(np.sqrt(max(inertia) / mass))


def fixed_pivots(frame_b: np.ndarray, least: float = 0.0) -> list[np.ndarray]:
    """The three pivots of a fixed joint, in the joint frame: its origin, the point as far beyond
    the child's centre of mass (the child's far end: where a chain hung from it pulls) and that
    point moved as far again across. Pivots spanning the child hold it where its load comes in:
    pivots 5 mm to the side of the joint origin, off a 2.4 mm thread element, let Bullet's
    solver leave the element 27° off the needle as the thread hung from it (its 50 iterations
    do not converge a 40-element chain, whose joint impulses start from zero every step), and
    the joint 2.3 mm open at those pivots; spanning the element: under 3°.

    ``least``: the span the pivots reach at least, along the same directions. An impulse at a
    pivot r from the centre of mass turns the child by r·P/I and moves it by P/m: pivots much
    nearer than its radius of gyration (sqrt(I/m)) barely turn it, and Bullet's solver leaves its
    orientation off where AMBF's fixed constraint (btFixedConstraint: three angular rows besides
    the three linear) holds it. The corpus suturing set's thread (elements 2.4 mm long, 0.03 kg,
    5e-5 kg·m²: 4.1 cm) at rest on the phantom: its first element 0.77° off the needle with
    pivots spanning the element, 0.01° with them spanning 2.4 cm, AMBF's 0.001°."""
    com = -frame_b[:3, :3].T @ frame_b[:3, 3]  # the child's centre of mass in the joint frame
    dist = float(np.linalg.norm(com))
    if dist < 5e-5:  # the joint at the child's centre of mass: any span will do
        span = max(FIXED_SPAN, least)
        return [np.zeros(3), np.array([span, 0.0, 0.0]), np.array([0.0, span, 0.0])]
    reach = max(2.0 * dist, least)
    far = reach * com / dist
    across = np.cross(far, np.eye(3)[int(np.argmin(np.abs(far)))])
    return [np.zeros(3), far, far + reach * across / np.linalg.norm(across)]
