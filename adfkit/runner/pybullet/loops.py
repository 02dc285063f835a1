"""Loops inside one multibody (a parallelogram, a four-bar, a gripper's jaws joined by a slider):
the joint that closes one is a constraint between two of the multibody's links (joints.py), and
the multibody starts with it closed.

AMBF places every body where the file places it and its joints' constraints meet there, up to
the file's rounding. A multibody's links can only be where its joint values put them: at the
values that best reproduce the files' `location`s, a loop's pivots start a fraction of a
millimetre apart (the corpus ECM's pitch parallelogram 0.1 mm, the parallel structure 0.5 mm),
and left free, the constraint pushing that gap apart drove the whole mechanism (the weightless
ECM 121 mm in 1 s). So the joint values are moved, as little as they can be, until every such
constraint's pivots meet; then the joints are left free, as AMBF's are."""

from __future__ import annotations

import numpy as np
import pybullet as pb

from .articulation import TREE_KINDS

#: a loop counts as closed when its pivots are this close (m)
CLOSED_M = 1e-8
_STEP = 1e-7  # the joint values' step for the numerical Jacobian (rad or m)
_REACH = 1e-2  # directions the joints move the pivots in less than this, relative to the most, are left


def close_loops(world) -> dict[int, float]:
    """Close every loop of each multibody of ``world``; returns, by multibody uid, the largest
    pivot gap (m) before it was closed."""
    before = {}
    for art in world.articulations:
        mine = [i for i, r in enumerate(world.constraints) if r[2].articulation is art and r[3].articulation is art]
        if mine:
            rows = [world.constraints[i] for i in mine]
            before[art.uid] = _close(art, rows)
            for i, row in zip(mine, rows, strict=True):  # their child pivots, anchored
                world.constraints[i] = row
    return before


def pivot_gaps(rows) -> np.ndarray:
    """Each row's pivot gap (parent's pivot less child's, world frame; a slider's along its axis
    left out), stacked: (3·len(rows),)."""
    out = []
    for _name, _c, parent, child, pa, pbv, axis in rows:
        a, b = _frame(parent), _frame(child)
        gap = a[:3, :3] @ pa + a[:3, 3] - (b[:3, :3] @ pbv + b[:3, 3])
        if axis is not None:
            u = a[:3, :3] @ axis
            gap = gap - (gap @ u) * u
        out.append(gap)
    return np.concatenate(out)


def _frame(sb) -> np.ndarray:
    return _body_frame(sb.uid, sb.link, sb.cid)


def _close(art, rows, iterations: int = 30) -> float:
    dofs = [n for n, k in enumerate(art.kinds) if k in TREE_KINDS]
    q = np.array(art.joint_values(), float)

    def put(values) -> None:
        for n in dofs:
            pb.resetJointState(art.uid, n, float(values[n]), physicsClientId=art.cid)

    e = pivot_gaps(rows)
    first = float(np.abs(e).max())
    for _ in range(iterations):
        if np.abs(e).max() < CLOSED_M:
            break
        jac = np.zeros((e.size, len(dofs)))
        for i, n in enumerate(dofs):
            qs = q.copy()
            qs[n] += _STEP
            put(qs)
            jac[:, i] = (pivot_gaps(rows) - e) / _STEP
        # the smallest move of the joint values that closes the gaps (least squares, least
        # norm), along the directions the joints can move the pivots in: a planar mechanism
        # cannot close a gap across its plane, and chasing one threw gripper3's jaws 0.76 rad
        dq = np.linalg.lstsq(jac, -e, rcond=_REACH)[0]
        q[dofs] += dq
        put(q)
        e = pivot_gaps(rows)
    put(q)
    for n in dofs:
        art.targets[n] = float(q[n])
    _anchor(rows, art.cid)
    return first


def _anchor(rows, cid: int) -> None:
    """What the joints cannot close (the file's rounding across a planar loop, 0.37 mm on
    gripper3's slider) is closed by putting each constraint's child pivot where its parent's is:
    AMBF's solver pulls the bodies together by as much in its first steps. (PyBullet's ends
    are not always the joint's: one end static, the constraint holds the other in the world.)"""
    for i, (name, c, parent, child, pa, _pbv, axis) in enumerate(rows):
        a, b = _frame(parent), _frame(child)
        pbv = np.linalg.solve(b, np.append(a[:3, :3] @ pa + a[:3, 3], 1.0))[:3]
        rows[i] = (name, c, parent, child, pa, pbv, axis)
        info = pb.getConstraintInfo(c, physicsClientId=cid)
        at = _body_frame(info[0], info[1], cid) @ np.append(info[6], 1.0)  # its parent end's pivot
        child_end = _body_frame(info[2], info[3], cid)
        there = np.linalg.solve(child_end, at)[:3]
        pb.changeConstraint(c, jointChildPivot=there.tolist(), physicsClientId=cid)
        if info[4] == pb.JOINT_PRISMATIC:  # a slider holds the ends' orientation too: as they start
            turn = _body_frame(info[0], info[1], cid)[:3, :3] @ _matrix(info[8])
            orn = _quaternion(child_end[:3, :3].T @ turn)
            pb.changeConstraint(c, jointChildFrameOrientation=orn, physicsClientId=cid)


def _matrix(q) -> np.ndarray:
    return np.array(pb.getMatrixFromQuaternion(q)).reshape(3, 3)


def _quaternion(m: np.ndarray) -> list[float]:
    from ..rotations import matrix_to_pq

    full = np.eye(4)
    full[:3, :3] = m
    return list(matrix_to_pq(full)[1])


def _body_frame(uid: int, link: int, cid: int) -> np.ndarray:
    """The frame a constraint's pivot is given in: a link's or base's COM frame, the world's for -1."""
    m = np.eye(4)
    if uid < 0:
        return m
    if link < 0:
        p, q = pb.getBasePositionAndOrientation(uid, physicsClientId=cid)
    else:
        p, q = pb.getLinkState(uid, link, computeForwardKinematics=True, physicsClientId=cid)[:2]
    m[:3, :3] = _matrix(q)
    m[:3, 3] = p
    return m
