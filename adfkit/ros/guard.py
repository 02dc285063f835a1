"""What a ROS client may send that must never reach the physics: a command holding a value that
is not a finite number (NaN, ±inf). One NaN in a joint command, a pose or a wrench turns the
engine's whole multibody or body into NaN for good (measured: ``set_joint_pos(0, nan)`` on psm1
made all eight of its joints NaN, and the next step stopped `adfkit ros` with numpy's "SVD did not
converge"; a NaN ``servo_jp`` stopped it at once). AMBF passes such a value to Bullet unchecked;
adfkit ignores the message, says so once, and keeps the last good command (the watchdog then
resets it as AMBF would when nothing good follows).

Each check returns the reason a message is refused, or None; no ROS needed here: they read the
fields of any object shaped like the message."""

from __future__ import annotations

import math

TYPE_FORCE, TYPE_POSITION, TYPE_VELOCITY = 0, 1, 2  # RigidBodyCmd's cartesian / joint types


def _bad(values, what: str) -> str | None:
    for k, v in enumerate(values):
        try:
            ok = math.isfinite(float(v))
        except (TypeError, ValueError):
            ok = False
        if not ok:
            return f"{what}[{k}] is {v!r}" if len(values) > 1 else f"{what} is {v!r}"
    return None


def pose_fault(pose, what: str = "pose") -> str | None:
    p, o = pose.position, pose.orientation
    return _bad([p.x, p.y, p.z], what + ".position") or _bad([o.x, o.y, o.z, o.w], what + ".orientation")


def vector_fault(v, what: str) -> str | None:
    return _bad([v.x, v.y, v.z], what)


def body_cmd_fault(cmd, n_joints: int) -> str | None:
    """A RigidBodyCmd: the Cartesian part its type uses and every joint command that reaches a
    joint (the first ``n_joints``, those of a known type)."""
    cart = cmd.cartesian_cmd_type
    why = None
    if cart == TYPE_FORCE:
        why = vector_fault(cmd.wrench.force, "wrench.force") or vector_fault(cmd.wrench.torque, "wrench.torque")
    elif cart == TYPE_POSITION:
        why = pose_fault(cmd.pose)
    elif cart == TYPE_VELOCITY:
        why = vector_fault(cmd.twist.linear, "twist.linear") or vector_fault(cmd.twist.angular, "twist.angular")
    if why:
        return why
    types = list(cmd.joint_cmds_types)
    for k, value in enumerate(list(cmd.joint_cmds)[:n_joints]):
        kind = types[k] if k < len(types) else TYPE_FORCE
        if kind in (TYPE_FORCE, TYPE_POSITION, TYPE_VELOCITY) and _bad([value], f"joint_cmds[{k}]"):
            return f"joint_cmds[{k}] is {value!r}"
    return None


def values_fault(values, what: str, need: int) -> str | None:
    """A JointState's ``position`` or ``velocity`` that a command reads ``need`` values of."""
    if len(values) < need:
        return f"{what} has {len(values)} value{'s' if len(values) != 1 else ''}, {need} needed"
    return _bad(list(values)[:need], what)
