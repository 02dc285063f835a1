"""AMBF's limit rows on the joints of PyBullet's multibodies. PyBullet's multibody limit
(changeDynamics' jointLowerLimit/jointUpperLimit) stops a joint at a limit it reaches but does not
push back a joint that is already past it, and does nothing before the joint gets there. AMBF's
joints are Bullet constraints whose limit rows ask, each physics step dt, for a joint velocity:
- a `revolute` joint (btHingeConstraint, setLimit's defaults: bias 0.3, relaxation 1), past a
  limit: 0.3·max(erp·error/dt, the speed further out), inward (btHingeConstraint::
  getInfo2Internal), erp the joint's `joint erp` (0.1 unless the file says otherwise): the joint
  is kicked back in and coasts;
- a `prismatic` joint (btSliderConstraint), past a limit: erp·depth/dt inward, erp the world's
  (0.2: AMBF's `joint erp` goes to a parameter the slider does not read), no bounce;
- a limited `torsion spring` or `linear spring` (btGeneric6DofSpring2Constraint, whose limit rows
  are there whenever low < high, not only past a limit): toward a limit at a gap g inside it, at
  most erp·g/dt, and not at all when the joint would cross it within the step; past it, erp·|g|/dt
  back in; erp the joint's (AMBF sets the axis's stop ERP). A joint falling onto its limit slows
  and stops short of it, where PyBullet's limit stopped it on it within a step.
  Only where AMBF's springs are asked for (Options.springs "ambf", adfkit run's and parity's).

Each control step (each physics step where the world steps them one by one), such a joint that
nothing else drives (its articulation free, no joint command on it) and that moves where its row
would not let it is driven at the row's velocity by its motor (force up to joint_commands.
LIMIT_FORCE); the motor is turned off again once the row lets the joint be. While the joint is
outside, PyBullet's own limit is moved out to where the joint is (crossing back in from outside,
that limit kicked a lone hinge from the row's 3 rad/s to 7.4 rad/s) and put back once it is inside.
Joint commands keep their own hold (runner/joint_commands.py); an articulation whose position
motors hold it is left alone."""

from __future__ import annotations

from functools import partial

import pybullet as pb

from ...model.semantics import HINGE_LIMIT_BIAS, ONE_AXIS_SPRINGS, SLIDER_LIMIT_ERP, JointKind, joint_kind
from ..joint_commands import AMBF_JOINT_ERP, LIMIT_FORCE, limits_of


def limit_row_velocity(q: float, v: float, limits: tuple[float, float], erp: float, dt: float) -> float:
    """The joint velocity AMBF's hinge limit row asks for at ``q`` (moving at ``v``), 0 within
    ``limits``: 0.3·max(erp·error/dt, the speed further out), toward the limits."""
    lo, hi = limits
    if q > hi:
        return -HINGE_LIMIT_BIAS * max(erp * (q - hi) / dt, v)
    if q < lo:
        return HINGE_LIMIT_BIAS * max(erp * (lo - q) / dt, -v)
    return 0.0


def _hinge_row(q: float, v: float, limits: tuple[float, float], erp: float, dt: float) -> float | None:
    back = limit_row_velocity(q, v, limits, erp, dt)
    return back if back != 0.0 and (back - v) * back > 0.0 else None  # inward slower than the row asks


def slider_row_velocity(q: float, v: float, limits: tuple[float, float], dt: float) -> float | None:
    """The velocity AMBF's slider limit row drives a prismatic joint at, past a limit and not moving
    back in at erp·depth/dt already; None where the row does not push."""
    lo, hi = limits
    if q < lo:
        back = SLIDER_LIMIT_ERP * (lo - q) / dt
        return back if v < back else None
    if q > hi:
        back = -SLIDER_LIMIT_ERP * (q - hi) / dt
        return back if v > back else None
    return None


def spring_row_velocity(q: float, v: float, limits: tuple[float, float], erp: float, dt: float) -> float | None:
    """The velocity AMBF's btGeneric6DofSpring2Constraint's limit rows hold a spring's axis to this
    physics step (get_limit_motor_info2, its limit rows always there where low < high, no bounce):
    toward a limit at a gap g inside it at most erp·g/dt, and not at all where the joint would
    cross it within the step (at more than g/dt); past it, erp·|g|/dt back in. None where the
    rows do not push."""
    lo, hi = limits
    gap = q - lo
    slowest = 0.0 if gap > 0.0 and -v * dt > gap else -erp * gap / dt
    if v < slowest:
        return slowest
    gap = hi - q
    fastest = 0.0 if gap > 0.0 and v * dt > gap else erp * gap / dt
    if v > fastest:
        return fastest
    return None


def _pulled(q: float, limits: tuple[float, float], force: float) -> bool:
    """Whether a row's motor, last step, pulled its joint toward the nearer limit (``force``, the
    motor's applied joint force or torque) where AMBF's limit row, whose impulse is clamped to push
    the joint away from its limit, would have let it go: PyBullet's velocity motor holds both ways."""
    lo, hi = limits
    inward = 1.0 if q - lo < hi - q else -1.0
    return force * inward < 0.0


class LimitRows:
    def __init__(self, world) -> None:
        self.world = world
        self.dt = world.dt
        springs = world.opt.springs == "ambf"
        # per articulation: [(index, limits, the row's velocity (q, v, limits, dt) or None)] of its
        # limited revolute and prismatic joints, and its limited springs under AMBF's springs
        self.joints = []
        for art in world.articulations:
            rows = []
            for n, rec in enumerate(art.records):
                joint = rec[0]
                lim = limits_of(joint)
                kind = joint_kind(joint.type)
                if lim is None or not lim[0] < lim[1]:
                    continue
                erp = joint.joint_erp if joint.joint_erp is not None else AMBF_JOINT_ERP
                if kind is JointKind.REVOLUTE:
                    rows.append((n, lim, partial(_hinge_row, erp=erp)))
                elif kind is JointKind.PRISMATIC:
                    rows.append((n, lim, slider_row_velocity))
                elif kind in ONE_AXIS_SPRINGS and springs:
                    rows.append((n, lim, partial(spring_row_velocity, erp=erp)))
            if rows:
                self.joints.append((art, rows))
        self.commanded: set[tuple[int, int]] = set()  # (uid, index) under a joint command
        self.engaged: set[tuple[int, int]] = set()  # (uid, index) whose motor this row drives now
        self.widened: set[tuple[int, int]] = set()  # (uid, index) whose PyBullet limits reach past its own

    def leave(self, art, index: int) -> None:
        """Joint ``index`` of ``art`` is under a joint command from now on: not this row's."""
        self.commanded.add((art.uid, index))
        self.release(art, index)

    def release(self, art, index: int) -> None:
        """The joint's own limits back in PyBullet; its motor no longer this row's."""
        key = (art.uid, index)
        self.engaged.discard(key)
        if key in self.widened:
            lo, hi = limits_of(art.records[index][0])
            pb.changeDynamics(art.uid, index, jointLowerLimit=lo, jointUpperLimit=hi, physicsClientId=self.world.cid)
            self.widened.discard(key)

    def apply(self) -> None:
        cid = self.world.cid
        chains = getattr(self.world, "limit_chains", None)
        for art, rows in self.joints:
            if chains is not None and chains.playing(art):  # AMBF's solver step plays its stops (limit_chains.py)
                continue
            if art.held:  # its position motors drive every joint
                for n, _l, _r in rows:
                    self.release(art, n)
                continue
            states = pb.getJointStates(art.uid, [n for n, _l, _r in rows], physicsClientId=cid)
            for (n, lim, row), s in zip(rows, states):
                key = (art.uid, n)
                if key in self.commanded:
                    continue
                q, v = s[0], s[1]
                outside = not lim[0] <= q <= lim[1]
                if outside or key in self.widened:  # PyBullet's limit up to where the joint is
                    lo, hi = (min(lim[0], q), max(lim[1], q)) if outside else lim
                    pb.changeDynamics(art.uid, n, jointLowerLimit=lo, jointUpperLimit=hi, physicsClientId=cid)
                    (self.widened.add if outside else self.widened.discard)(key)
                back = row(q, v, lim, dt=self.dt)
                if back is not None and key in self.engaged and _pulled(q, lim, s[3]):
                    back = None  # AMBF's row only pushes: let go of a joint its motor held back
                if back is not None:
                    pb.setJointMotorControl2(
                        art.uid, n, pb.VELOCITY_CONTROL, targetVelocity=back, force=LIMIT_FORCE, physicsClientId=cid
                    )
                    self.engaged.add(key)
                elif key in self.engaged:
                    pb.setJointMotorControl2(art.uid, n, pb.VELOCITY_CONTROL, force=0.0, physicsClientId=cid)
                    self.engaged.discard(key)
