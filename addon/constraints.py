"""Blender's rigid body constraint kept in step with the ADF joint panel: limits typed in
the panel are mirrored onto the constraint (hinge Z, slider X, generic six-dof axes)."""

from __future__ import annotations

from adfkit.model.semantics import JointKind, joint_kind


def _set(rbc, attr: str, on: bool, lo: float = 0.0, hi: float = 0.0) -> None:
    if not hasattr(rbc, "use_limit_" + attr):
        return
    setattr(rbc, "use_limit_" + attr, on)
    if on:
        setattr(rbc, f"limit_{attr}_lower", lo)
        setattr(rbc, f"limit_{attr}_upper", hi)


def mirror_limits(obj) -> None:
    """Copy the joint panel's limits of ``obj`` onto its rigid body constraint."""
    rbc = getattr(obj, "rigid_body_constraint", None)
    if rbc is None or obj.adf.kind != "JOINT":
        return
    p = obj.adf.joint
    kind = joint_kind(p.type) if p.use_type else None
    one = p.use_limit_low and p.use_limit_high
    if kind in (JointKind.REVOLUTE, JointKind.TORSION_SPRING):
        _set(rbc, "ang_z", one, p.limit_low, p.limit_high)
    elif kind == JointKind.PRISMATIC:
        _set(rbc, "lin_x", one, p.limit_low, p.limit_high)
    elif kind == JointKind.LINEAR_SPRING:
        _set(rbc, "lin_z", one, p.limit_low, p.limit_high)
    elif kind == JointKind.CONE_TWIST:
        for i, a in enumerate("xyz"):
            _set(rbc, "ang_" + a, p.use_cone_limits, -p.cone_limits[i], p.cone_limits[i])
    elif kind in (JointKind.SIX_DOF, JointKind.SIX_DOF_SPRING):
        for i, a in enumerate("xyz"):
            _set(rbc, "lin_" + a, p.use_linear_low and p.use_linear_high, p.linear_low[i], p.linear_high[i])
            _set(rbc, "ang_" + a, p.use_angular_low and p.use_angular_high, p.angular_low[i], p.angular_high[i])
