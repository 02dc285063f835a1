"""AMBF's hinge limit row on the revolute joints of PyBullet's multibodies. PyBullet's multibody
limit (changeDynamics' jointLowerLimit/jointUpperLimit) stops a joint at a limit it reaches but
does not push back a joint that is already past it: a hinge that starts outside its limits stays
where it is. AMBF's hinge (btHingeConstraint with setLimit's defaults: bias 0.3, relaxation 1)
has a one-sided row past a limit that asks for the joint velocity 0.3·max(erp·error/dt, the speed
further out), inward (btHingeConstraint::getInfo2Internal), erp the joint's `joint erp` (0.1
unless the file says otherwise), dt the physics step: the joint is kicked back in and coasts.

Each control step, a revolute joint past its limits that nothing else drives (its articulation
free, no joint command on it) and moving inward slower than that row asks is driven at that
velocity by its motor (force up to joint_commands.LIMIT_FORCE); the motor is turned off again
once the joint is inside or leaves faster. While the joint is outside, PyBullet's own limit is
moved out to where the joint is (crossing back in from outside, that limit kicked a lone hinge
from the row's 3 rad/s to 7.4 rad/s) and put back once it is inside. Joint commands keep their
own hold (runner/joint_commands.py); an articulation whose position motors hold it is left alone."""

from __future__ import annotations

import pybullet as pb

from ...model.semantics import JointKind, joint_kind
from ..joint_commands import AMBF_JOINT_ERP, LIMIT_FORCE, limits_of

#: btHingeConstraint::setLimit's default bias factor, which AMBF's hinges keep
HINGE_LIMIT_BIAS = 0.3


def limit_row_velocity(q: float, v: float, limits: tuple[float, float], erp: float, dt: float) -> float:
    """The joint velocity AMBF's hinge limit row asks for at ``q`` (moving at ``v``), 0 within
    ``limits``: 0.3·max(erp·error/dt, the speed further out), toward the limits."""
    lo, hi = limits
    if q > hi:
        return -HINGE_LIMIT_BIAS * max(erp * (q - hi) / dt, v)
    if q < lo:
        return HINGE_LIMIT_BIAS * max(erp * (lo - q) / dt, -v)
    return 0.0


class LimitRows:
    def __init__(self, world) -> None:
        self.world = world
        self.dt = world.dt
        # per articulation: [(index, limits, erp)] of its limited revolute joints
        self.joints = []
        for art in world.articulations:
            rows = []
            for n, rec in enumerate(art.records):
                joint = rec[0]
                lim = limits_of(joint)
                if joint_kind(joint.type) is JointKind.REVOLUTE and lim is not None and lim[0] < lim[1]:
                    erp = joint.joint_erp if joint.joint_erp is not None else AMBF_JOINT_ERP
                    rows.append((n, lim, erp))
            if rows:
                self.joints.append((art, rows))
        self.commanded: set[tuple[int, int]] = set()  # (uid, index) under a joint command
        self.engaged: set[tuple[int, int]] = set()  # (uid, index) whose motor this row drives now
        self.widened: set[tuple[int, int]] = set()  # (uid, index) whose PyBullet limits reach past its own

    def leave(self, art, index: int) -> None:
        """Joint ``index`` of ``art`` is under a joint command from now on: not this row's."""
        self.commanded.add((art.uid, index))
        self._release(art, index)

    def _release(self, art, index: int) -> None:
        """The joint's own limits back in PyBullet; its motor no longer this row's."""
        key = (art.uid, index)
        self.engaged.discard(key)
        if key in self.widened:
            lo, hi = limits_of(art.records[index][0])
            pb.changeDynamics(art.uid, index, jointLowerLimit=lo, jointUpperLimit=hi, physicsClientId=self.world.cid)
            self.widened.discard(key)

    def apply(self) -> None:
        cid = self.world.cid
        for art, rows in self.joints:
            if art.held:  # its position motors drive every joint
                for n, _l, _e in rows:
                    self._release(art, n)
                continue
            states = pb.getJointStates(art.uid, [n for n, _l, _e in rows], physicsClientId=cid)
            for (n, lim, erp), s in zip(rows, states):
                key = (art.uid, n)
                if key in self.commanded:
                    continue
                q, v = s[0], s[1]
                outside = not lim[0] <= q <= lim[1]
                if outside or key in self.widened:  # PyBullet's limit up to where the joint is
                    lo, hi = (min(lim[0], q), max(lim[1], q)) if outside else lim
                    pb.changeDynamics(art.uid, n, jointLowerLimit=lo, jointUpperLimit=hi, physicsClientId=cid)
                    (self.widened.add if outside else self.widened.discard)(key)
                back = limit_row_velocity(q, v, lim, erp, self.dt)
                if back != 0.0 and (back - v) * back > 0.0:  # inward slower than the row asks
                    pb.setJointMotorControl2(
                        art.uid, n, pb.VELOCITY_CONTROL, targetVelocity=back, force=LIMIT_FORCE, physicsClientId=cid
                    )
                    self.engaged.add(key)
                elif key in self.engaged:
                    pb.setJointMotorControl2(art.uid, n, pb.VELOCITY_CONTROL, force=0.0, physicsClientId=cid)
                    self.engaged.discard(key)
