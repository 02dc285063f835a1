"""Joint limits in the MuJoCo world as AMBF's Bullet constraints hold them, where AMBF's bodies
are asked for (``Options.bodies`` "ambf": ``adfkit run``, ``adfkit parity``).

Past a limit, Bullet's limit row asks for an inward joint velocity c·error in one physics step
and only pushes: a joint started outside is kicked in and coasts on; a joint resting on a limit
is held there. c is 0.3·erp/dt for a revolute joint (btHingeConstraint: setLimit's bias factor
0.3 times the joint's `joint erp`, 0.1 unless the file says otherwise) and erp/dt for the axes of
a `torsion spring` or `linear spring` (btGeneric6DofSpring2Constraint's stop ERP), 0.2/dt for a
prismatic joint (btSliderConstraint's rows at the world's ERP, not the joint's), 0.2/dt for the
angular axes of a `six dof` joint (btGeneric6DofConstraint's stop ERP) and 0.3/dt for a `cone
twist` (btConeTwistConstraint's bias factor): with MuJoCo's default a rod hinged at its end by
either, released level into its stop, sank 11-35 mm past where AMBF's stops (0.02-3.2 mm now).
Measured in
AMBF: a 0.5 kg arm on a hinge about z started 0.2 rad past its lower limit turns in at 6.0 rad/s
(0.3·0.1·0.2/1 ms) from the first step; on a torsion spring at 17.6 rad/s over the first 4 ms
(20 by the formula). MuJoCo's default (a 20 ms time constant, damping ratio 1) eased the hinge
in, 3.7 rad/s after 50 ms. A MuJoCo limit given the stiffness and damping c/dt and 1/dt
(solref's negative form) asks for the same velocity in one step: the hinge turns in at 6.0 rad/s.
A prismatic joint started 0.05 m past its limit is driven back at 10 m/s in AMBF (measured with
the PyBullet runner's slider rows, runner/pybullet/limit_rows.py).
"""

from __future__ import annotations

import mujoco

from ...model.semantics import DEFAULT_JOINT_ERP, HINGE_LIMIT_BIAS, ONE_AXIS_SPRINGS, SLIDER_LIMIT_ERP, JointKind

#: btGeneric6DofSpring2Constraint's stop ERP, which AMBF leaves at Bullet's default on a six dof spring;
#: btGeneric6DofConstraint's rotational limits (btRotationalLimitMotor::m_stopERP) have the same
SIX_DOF_SPRING_STOP_ERP = 0.2
#: btConeTwistConstraint's bias factor, which AMBF's setLimit leaves at Bullet's default
CONE_TWIST_BIAS = 0.3


def limit_rate(joint, kind) -> float | None:
    """c·dt of Bullet's limit row on ``joint``, None where MuJoCo's default is kept."""
    erp = joint.joint_erp if joint.joint_erp is not None else DEFAULT_JOINT_ERP
    if kind is JointKind.REVOLUTE:
        return HINGE_LIMIT_BIAS * erp
    if kind in ONE_AXIS_SPRINGS:
        return erp
    if kind in (JointKind.SIX_DOF_SPRING, JointKind.SIX_DOF):
        return SIX_DOF_SPRING_STOP_ERP
    if kind is JointKind.CONE_TWIST:
        return CONE_TWIST_BIAS
    if kind is JointKind.PRISMATIC:
        return SLIDER_LIMIT_ERP
    return None


def ambf_limits(model, joints, dt: float, skip=frozenset()) -> None:
    """The limited MuJoCo joints of ``joints`` (build.Plan.joints) given Bullet's limit rows, but
    those named in ``skip`` (spring_rows.capped_joints: springs Bullet caps keep MuJoCo's own)."""
    for j, kind, _parent, _child, names in joints:
        rate = limit_rate(j, kind)
        if rate is None:
            continue
        for name in names:
            if name in skip:
                continue
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
            if jid >= 0 and model.jnt_limited[jid]:
                model.jnt_solref[jid] = [-rate / dt**2, -1.0 / dt]
