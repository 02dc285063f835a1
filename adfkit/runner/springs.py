"""The six-dof family of joints (adf-format.md §8.1) resolved once for every engine: limits,
stiffness, damping and equilibrium per axis in the joint frame, with AMBF's defaults."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model.semantics import DEFAULT_SIX_DOF_LIMIT, DEFAULT_SIX_DOF_SPRING, JointKind
from .cone_twist import spans


@dataclass
class SpringJoint:
    name: str
    parent: object  # SimBody
    child: object
    frame_a: np.ndarray  # joint frame in the parent's PyBullet frame (4×4)
    frame_b: np.ndarray  # joint frame in the child's PyBullet frame
    lin_low: np.ndarray
    lin_high: np.ndarray
    ang_low: np.ndarray
    ang_high: np.ndarray
    k_lin: np.ndarray = field(default_factory=lambda: np.zeros(3))
    c_lin: np.ndarray = field(default_factory=lambda: np.zeros(3))
    eq_lin: np.ndarray = field(default_factory=lambda: np.zeros(3))
    k_ang: np.ndarray = field(default_factory=lambda: np.zeros(3))
    c_ang: np.ndarray = field(default_factory=lambda: np.zeros(3))
    eq_ang: np.ndarray = field(default_factory=lambda: np.zeros(3))
    linear_constrained: bool = True  # a p2p holds the pivots together
    in_multibody: bool = False  # a multibody's joint plays its limits and locked axes (spring_alone)
    cone: np.ndarray | None = None  # a cone twist's (swing span 1, swing span 2, twist span): cone_twist.spans
    free_pivot: bool = False  # no engine constraint: the springs play Bullet's pivot rows (pybullet/cone_limits.py)


def _vec(v, default: float) -> np.ndarray:
    if v is None:
        return np.full(3, float(default))
    return np.array([default if c is None else c for c in v], dtype=float)


def spring_joint(joint, kind: JointKind, parent, child, frame_a, frame_b) -> SpringJoint:
    """Limits and gains of a six-dof-family joint in the joint frame (§8.1)."""
    lim = joint.joint_limits
    zero = np.zeros(3)
    if kind in (JointKind.SIX_DOF, JointKind.SIX_DOF_SPRING):
        d = DEFAULT_SIX_DOF_LIMIT
        lin_low, lin_high = np.full(3, -d), np.full(3, d)
        ang_low, ang_high = np.full(3, -d), np.full(3, d)
        if lim is not None and lim.linear is not None:
            lin_low, lin_high = _vec(lim.linear.low, -d), _vec(lim.linear.high, d)
        if lim is not None and lim.angular is not None:
            ang_low, ang_high = _vec(lim.angular.low, -d), _vec(lim.angular.high, d)
    elif kind is JointKind.CONE_TWIST:
        lin_low = lin_high = zero
        sx = lim.x if lim is not None and lim.x is not None else 0.7
        sy = lim.y if lim is not None and lim.y is not None else 0.7
        sz = lim.z if lim is not None and lim.z is not None else 0.7
        ang_high = np.array([sx, sy, sz])
        ang_low = -ang_high
    else:  # linear or torsion spring: all locked but the spring axis (z) when limits exist
        lin_low = lin_high = zero.copy()
        ang_low, ang_high = zero.copy(), zero.copy()
        has = lim is not None and lim.low is not None and lim.high is not None
        if has:
            if kind is JointKind.LINEAR_SPRING:
                lin_low, lin_high = np.array([0, 0, lim.low]), np.array([0, 0, lim.high])
            else:
                ang_low, ang_high = np.array([0, 0, lim.low]), np.array([0, 0, lim.high])
    sj = SpringJoint(joint.identifier, parent, child, frame_a, frame_b, lin_low, lin_high, ang_low, ang_high)
    sj.linear_constrained = bool(np.all(lin_low == 0) and np.all(lin_high == 0))
    if kind is JointKind.CONE_TWIST:
        sj.cone = spans(lim)
    if kind is JointKind.SIX_DOF_SPRING:
        for attr, key in (
            ("stiffness", "stiffness"),
            ("damping", "damping"),
            ("equilibrium_point", "equilibrium point"),
        ):
            block = getattr(joint, attr)
            dflt = DEFAULT_SIX_DOF_SPRING[key]
            lin = _vec(getattr(block, "linear", None), dflt)
            ang = _vec(getattr(block, "angular", None), dflt)
            tag = {"stiffness": "k", "damping": "c", "equilibrium_point": "eq"}[attr]
            setattr(sj, f"{tag}_lin", lin)
            setattr(sj, f"{tag}_ang", ang)
    elif kind in (JointKind.LINEAR_SPRING, JointKind.TORSION_SPRING):
        k = joint.stiffness if isinstance(joint.stiffness, (int, float)) else 0.0
        c = joint.damping if isinstance(joint.damping, (int, float)) else 0.0
        lim_ok = lim is not None and lim.low is not None and lim.high is not None
        eq = (
            joint.equilibrium_point
            if isinstance(joint.equilibrium_point, (int, float))
            else ((lim.low + lim.high) / 2 if lim_ok else 0.0)
        )
        if lim_ok:
            if kind is JointKind.LINEAR_SPRING:
                sj.k_lin, sj.c_lin, sj.eq_lin = np.array([0, 0, k]), np.array([0, 0, c]), np.array([0, 0, eq])
            else:
                sj.k_ang, sj.c_ang, sj.eq_ang = np.array([0, 0, k]), np.array([0, 0, c]), np.array([0, 0, eq])
    return sj


def spring_alone(sj: SpringJoint) -> SpringJoint | None:
    """``sj`` with its spring and damper only, its limits and locked axes left to an exact joint
    that plays them (a limited torsion or linear spring in a multibody: a revolute or prismatic
    joint with its limits); None when it has neither stiffness nor damping (nothing is left)."""
    if not (np.any(sj.k_lin) or np.any(sj.c_lin) or np.any(sj.k_ang) or np.any(sj.c_ang)):
        return None
    free_low, free_high = np.ones(3), -np.ones(3)  # low > high: free (Bullet's convention)
    sj.lin_low, sj.lin_high, sj.ang_low, sj.ang_high = free_low, free_high, free_low.copy(), free_high.copy()
    sj.linear_constrained = not (np.any(sj.k_lin) or np.any(sj.c_lin))
    sj.in_multibody = True
    return sj
