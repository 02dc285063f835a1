"""Joint pivots and axes from a joint frame placed in the world (pure; adf-format.md §8.2).

The inverse of :func:`adfkit.model.semantics.joint_frames`: given the world poses of the
parent body, the child body and the joint frame (the constraint empty; its Z is the axis,
X for prismatic joints), return the ADF keys that make AMBF's frames A and B coincide
there at joint value zero.
"""

from __future__ import annotations

import math

from adfkit.model.pose import Pose, Quat, Vec3
from adfkit.model.semantics import JointKind, joint_kind, reference_axis, shortest_arc


def _angle_about(q: Quat, axis: Vec3) -> float:
    """Signed angle of a rotation about ``axis`` (its component about any other axis is ignored)."""
    s = q.x * axis[0] + q.y * axis[1] + q.z * axis[2]
    a = 2.0 * math.atan2(s, q.w)
    return (a + math.pi) % (2 * math.pi) - math.pi


def _clean(v: float) -> float:
    return round(v, 12) + 0.0


def _vec(v) -> Vec3:
    return Vec3(*(_clean(c) for c in v))


def derive(
    joint_type: str | None, parent: Pose, child: Pose, frame: Pose, parent_scale: float = 1.0, child_scale: float = 1.0
) -> dict:
    kind = joint_kind(joint_type) or JointKind.REVOLUTE
    d = reference_axis(kind)
    a_frame = parent.inverse() * frame
    b_frame = child.inverse() * frame
    a = a_frame.orientation.rotate(d).normalized()
    b = b_frame.orientation.rotate(d).normalized()
    joint_offset = _angle_about(a_frame.orientation * shortest_arc(d, a).inverse(), a)
    rot_off = a_frame.orientation * b_frame.orientation.inverse() * shortest_arc(b, a).inverse()
    offset = _angle_about(rot_off, a)
    return {
        "parent_pivot": _vec(a_frame.position.scaled(1.0 / parent_scale)),
        "child_pivot": _vec(b_frame.position.scaled(1.0 / child_scale)),
        "parent_axis": _vec(a),
        "child_axis": _vec(b),
        "offset": _clean(offset),
        "joint_offset": _clean(joint_offset),
    }
