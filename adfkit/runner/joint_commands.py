"""Joint commands as AMBF plays them (its afJoint and afJointController): a position command
goes through the joint's controller every time it is given (the file's `controller` P, I, D, or
AMBF's P 10, D 1 without one) and the controller's output drives the joint's velocity motor
(`max motor impulse`) or, for `controller output type: FORCE` (the default with a `controller`),
is an effort; a velocity command sets the motor's target velocity; an effort turns the motor off
and pushes the joint for the next step. AMBF applies the last command a joint was given at every
physics step (its ROS plugin does); ``JointCommands.apply`` does that once per control step.
The engine supplies ``joint_motor(art, index, velocity, max_force)`` and ``joint_effort(art,
index, effort)`` for a revolute or prismatic joint of one of its articulations.

AMBF's motor is a row of Bullet's constraint solver between the joint's two btRigidBodies, with
the joint's `joint cfm` (0.1 unless the file says otherwise). The solver leaves the row where
r·(v_target − v) = cfm·λ, λ the impulse it pushed with and r the mass the row sees between the
two bodies alone (1 / (aᵀ I_parent⁻¹ a + aᵀ I_child⁻¹ a) for a hinge). A motor that moves far
more than its own two bodies (a robot's shoulder, a PSM's yaw) is a stiff damper toward its
target rather than a lock on it: it falls short under a steady load (gravity, body damping) by
cfm·λ/r and reaches a new target over several steps. The rows of a chain's motors settle
together: with λ the joint impulses and W = M⁻¹ over the driven joints (M the joint-space mass
matrix, the chain's other joints free), v = v_free + W·λ and R·(v_target − v) = C·λ, so
λ = (R·W + C)⁻¹·R·(v_target − v_free) (``soft_row_impulses``), which is what AMBF's rows reach
given enough solver iterations (measured: AMBF at 100 iterations, the KUKA's velocity program
0.08 mm, the PSM's 0.05 mm from this). The engine pushes each joint with λ/dt as an effort;
v_free, where the step would leave the joints without the rows, is this step's velocity plus
what the other forces changed in the step before (read back from the velocities it left). An
engine that supplies ``joint_mobility(art, idxs)`` and ``joint_row_mass(art, index)`` plays
that; another drives its motors to the targets themselves. AMBF's own ten solver iterations do
not settle a chain's rows: an engine that supplies ``chain_velocities(art, motors, efforts)``
(the PyBullet runner under AMBF's bodies: runner/chain_rows.py) tells where they leave the joints
instead, and the impulses take them there."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.semantics import (
    DEFAULT_JOINT_CFM,
    DEFAULT_JOINT_ERP,
    DEFAULT_JOINT_MAX_MOTOR_IMPULSE,
    SLIDER_LIMIT_ERP,
    JointKind,
    joint_kind,
)

#: AMBF's joint controller without a `controller` block: a velocity command P·e + D·de/dt
DEFAULT_PID = (10.0, 0.0, 1.0)
#: AMBF's step for a prismatic motor's force (impulse / 0.001, whatever the physics rate)
AMBF_SLIDER_DT = 0.001
#: the shortest time between two controller updates AMBF divides by (afJointController.m_min_dt)
MIN_DT = 1e-5
KINDS = ("position", "velocity", "effort")
#: the joints AMBF pushes with an effort and does not move by position or velocity
SPRINGS = (JointKind.TORSION_SPRING, JointKind.LINEAR_SPRING)
#: the joints a command drives: AMBF's hinges and sliders, and its limited springs (by effort)
DRIVEN_KINDS = (JointKind.REVOLUTE, JointKind.PRISMATIC, *SPRINGS)


def spring_pushed(world, joint, effort: float) -> bool:
    """Whether ``world`` pushes spring ``joint`` by ``effort`` itself (an engine whose springs are
    not joints of its articulations: the MuJoCo engine's ``spring_effort``)."""
    push = getattr(world, "spring_effort", None)
    return push is not None and joint_kind(joint.type) in SPRINGS and bool(push(joint, effort))


def motor_enabled(joint) -> bool:
    """AMBF's `enable motor`: on by default; when the key is there, AMBF reads `enable
    feedback`'s value instead (its loader's slip)."""
    if joint.enable_motor is None:
        return True
    return bool(joint.enable_feedback)


def controller_of(joint) -> tuple[tuple[float, float, float], str]:
    """((P, I, D), "force" | "velocity") AMBF builds the joint's controller with."""
    c = joint.controller
    if c is not None:
        pid = (c.P if c.P is not None else 10.0, c.I if c.I is not None else 0.0, c.D if c.D is not None else 1.0)
        out = "force"
    else:
        pid, out = DEFAULT_PID, "velocity"
    t = joint.controller_output_type
    if t is not None:
        out = "velocity" if t in ("VELOCITY", "velocity", "POSITION", "position") else "force"
    return pid, out


def limits_of(joint) -> tuple[float, float] | None:
    """The joint's limits when AMBF enables them (both `low` and `high` given)."""
    lim = joint.joint_limits
    if lim is None or lim.low is None or lim.high is None:
        return None
    return float(lim.low), float(lim.high)


#: AMBF's joint `erp` default, which its hinge's motor slows with near a limit (motor_factor)
AMBF_JOINT_ERP = DEFAULT_JOINT_ERP
#: N·m (N) a limit may push with when an effort presses a joint past it (a limit row is unbounded)
LIMIT_FORCE = 1e4


def motor_factor(
    q: float, limits: tuple[float, float] | None, velocity: float, dt: float, erp: float = AMBF_JOINT_ERP
) -> float:
    """Bullet's btTypedConstraint::getMotorFactor for a motor of AMBF's joints: 1 away from the
    limits, falling to 0 over the last step's worth of travel toward one (at erp·rate), 0 past
    it. The motor stops at a limit however the joint engine keeps its limits (PyBullet forgets a
    multibody link's changeDynamics limits while other joints of it are driven: measured, the
    LND PSM's jaw 0.068 rad past its lower limit in 0.4 s)."""
    if limits is None:
        return 1.0
    lo, hi = limits
    if lo > hi:
        return 1.0
    if lo == hi:
        return 0.0
    delta = velocity * dt / erp
    if delta < 0.0:
        if lo <= q < lo - delta:
            return (lo - q) / delta
        return 0.0 if q < lo else 1.0
    if delta > 0.0:
        if hi >= q > hi - delta:
            return (hi - q) / delta
        return 0.0 if q > hi else 1.0
    return 0.0


def row_mass(axis, ends, prismatic: bool) -> float:
    """The mass (kg·m², kg) a Bullet constraint row along a joint's world ``axis`` sees between
    the joint's two bodies alone, as AMBF's hinge or slider motor row does: 1 / (aᵀ I_p⁻¹ a +
    aᵀ I_c⁻¹ a) for a hinge, 1 / (1/m_p + 1/m_c) for a slider. ``ends``: (mass, principal
    inertia (3,), rotation of the principal frame in the world (3x3)) of each body that can move
    (a static one adds nothing); infinite where neither can."""
    inverse = 0.0
    for mass, inertia, rot in ends:
        if prismatic:
            inverse += 1.0 / mass
            continue
        a = np.asarray(rot).T @ np.asarray(axis)  # the axis in the body's principal frame
        inverse += float(sum(a[i] ** 2 / inertia[i] for i in range(3) if inertia[i] > 0.0))
    return 1.0 / inverse if inverse > 0.0 else math.inf


def soft_row_impulses(mobility, row_mass, cfm, target, free) -> np.ndarray:
    """The impulses with which soft motor rows on joints of one chain settle together: W =
    ``mobility`` (M⁻¹ over those joints), R = diag(``row_mass``), C = diag(``cfm``): λ = (R·W +
    C)⁻¹·R·(``target`` − ``free``). On one joint of inertia I (W = 1/I) the joint goes the share
    1/(1 + cfm·I/r) of the way from ``free`` to ``target``."""
    r = np.asarray(row_mass, dtype=float)
    return np.linalg.solve(r[:, None] * mobility + np.diag(cfm), r * (np.asarray(target) - np.asarray(free)))


def shortest_angle(current: float, target: float) -> float:
    """AMBF's afJoint::getShortestAngle: the way from ``current`` to ``target`` for a joint
    without limits, in (-π, π]."""
    if current < 0.0:
        current += 2 * math.pi
    return math.fmod(target - current + 3 * math.pi, 2 * math.pi) - math.pi


@dataclass
class Controller:
    """afJointController's PID: the error's trapezoid integral and its backward difference."""

    P: float
    I: float
    D: float
    t_prev: float = 0.0
    e_prev: float = 0.0
    integral: float = 0.0

    def output(self, current: float, target: float, t: float) -> float:
        e = target - current
        dt = t - self.t_prev
        if dt <= MIN_DT:
            dt = MIN_DT
        de = (e - self.e_prev) / dt
        self.integral += (e + self.e_prev) / 2 * dt
        self.t_prev, self.e_prev = t, e
        return self.P * e + self.I * self.integral + self.D * de


@dataclass
class DrivenJoint:
    """A revolute or prismatic joint of an articulation, with what AMBF drives it with."""

    joint: object
    kind: JointKind
    art: object
    index: int
    controller: Controller
    output: str
    limits: tuple[float, float] | None
    max_force: float
    motor: bool
    cfm: float = 0.0
    erp: float = AMBF_JOINT_ERP
    row_mass: float = math.inf
    last_read: tuple[float, float] | None = None  # (t, position) of the last position command's read
    limit_erp: float = AMBF_JOINT_ERP  # the share of an overshoot its limit row takes back a physics step
    command: tuple[str, float] | None = None


class JointCommands:
    """The commands given to a world's joints, applied as AMBF applies them."""

    def __init__(self, world) -> None:
        self.world = world
        self.joints: dict[int, DrivenJoint] = {}
        # per articulation, what its soft rows did last: (joints, W, impulses, velocities before)
        self._rows: dict[int, tuple[list[int], np.ndarray, np.ndarray, np.ndarray]] = {}

    def drivable(self, joint, child) -> DrivenJoint | None:
        """The joint (an ADF joint, its engine child body) as a driven joint, or None when the
        engine did not make it a joint of an articulation: a revolute or prismatic joint, or a
        limited torsion or linear spring (which AMBF pushes with an effort and does not move by
        position or velocity: SPRINGS). A joint the articulation took reversed (its file parent
        hangs on its file child, which the articulation holds) is found by its file joint."""
        kind = joint_kind(joint.type)
        art = getattr(child, "articulation", None)
        if kind not in DRIVEN_KINDS or art is None:
            return None
        idx = next((i for i, r in enumerate(art.records) if getattr(r[0], "joint", r[0]) is joint), None)
        if idx is None or art.kinds[idx] not in DRIVEN_KINDS:
            return None
        (p, i, d), out = controller_of(joint)
        erp = joint.joint_erp if joint.joint_erp is not None else AMBF_JOINT_ERP
        imp = joint.max_motor_impulse if joint.max_motor_impulse is not None else DEFAULT_JOINT_MAX_MOTOR_IMPULSE
        dt = AMBF_SLIDER_DT if kind in (JointKind.PRISMATIC, JointKind.LINEAR_SPRING) else self.world.dt
        w = self.world
        soft = hasattr(w, "joint_row_mass") and hasattr(w, "joint_mobility")
        return DrivenJoint(
            joint,
            kind,
            art,
            idx,
            Controller(p, i, d),
            out,
            limits_of(joint),
            imp / dt,
            motor_enabled(joint),
            cfm=joint.joint_cfm if joint.joint_cfm is not None else DEFAULT_JOINT_CFM,
            erp=erp,
            row_mass=w.joint_row_mass(art, idx) if soft else math.inf,
            # a slider's limit row takes the world's erp (AMBF's joint erp goes where it does not read)
            limit_erp=SLIDER_LIMIT_ERP if kind is JointKind.PRISMATIC else erp,
        )

    def command(self, joint, child, kind: str, value: float) -> None:
        """From now on ``joint`` follows ``kind`` ("position", "velocity", "effort") ``value``."""
        if kind not in KINDS:
            raise ValueError(f"joint command {kind!r} is not one of {', '.join(KINDS)}")
        dj = self.joints.get(id(joint))
        if dj is None:
            dj = self.drivable(joint, child)
            if dj is None and joint_kind(joint.type) in SPRINGS and kind != "effort":
                return  # AMBF moves a spring by effort only: a position or velocity command does nothing
            if dj is None and kind == "effort" and spring_pushed(self.world, joint, value):
                return  # the engine pushes the spring itself (the MuJoCo engine: MujocoWorld.spring_effort)
            if dj is None:
                raise ValueError(f"{joint.identifier}: not a revolute, prismatic or spring joint of an articulation")
            self.joints[id(joint)] = dj
            # the engine's own hold past a limit, and the free stops' chain step (free_stops.py)
            for hold in (getattr(self.world, "limit_rows", None), getattr(self.world, "limit_chains", None)):
                if hold is not None:
                    hold.leave(dj.art, dj.index)
        dj.command = (kind, float(value))

    def _effort(self, dj: DrivenJoint, effort: float) -> None:
        """An effort, held at the joint's limits as AMBF's limit rows hold them, where the
        engine's own limits do not (World.hold_limits_under_efforts: PyBullet drops a multibody
        link's limits while others of it are driven; the LND PSM's jaw, pushed on its stop,
        turned 141° past it; the KUKA flailing under its controllers' efforts, its base joint
        5.3 rad where AMBF's stay within their ±2.09): past a limit, the joint is driven back at
        erp·error per step instead, whatever took it there, erp the joint's (a slider's the
        world's, 0.2, as AMBF's btSliderConstraint reads it: the parity slider pushed onto its
        stops 0.41 -> 0.00 mm from AMBF's). A limit row only pushes: a joint leaving its limit faster
        than that once the step's effort has acted (by the joint's row mass where the engine tells
        it) is left to the effort (the PSM's
        effort program: a jaw pushed shut, its yaw link kicked by the other jaw's stop, opened
        0.52 rad in AMBF and stayed shut under a motor that held it both ways). The MuJoCo
        engine's limits are AMBF's rows at their rates (mujoco/limits.py) and act under an
        effort: it is not held (the parity slider 0.61 -> 0.29 mm from AMBF's, the MTM's effort
        program 11.4 -> 1.7 mm, where a hold at the slider's rate kept the MuJoCo block a
        micrometre past its soft limit once the effort turned)."""
        w = self.world
        if dj.limits is not None and w.hold_limits_under_efforts:
            q, v = (float(x[0]) for x in w.joint_state(dj.art, [dj.index]))
            lo, hi = dj.limits
            err = q - hi if q > hi else (q - lo if q < lo else 0.0)
            back = -dj.limit_erp * err / w.dt
            after = v + effort * w.dt / dj.row_mass  # what the row meets: the step's effort added (none untold)
            if err != 0.0 and (after - back) * err > 0.0:
                w.joint_motor(dj.art, dj.index, back, LIMIT_FORCE)
                return
        w.joint_effort(dj.art, dj.index, effort)

    def _motor(self, dj: DrivenJoint, velocity: float, soft: dict) -> None:
        """The joint's motor driven toward ``velocity`` as AMBF's motor row drives it: slowed
        near a limit (motor_factor) and, where the engine tells the masses, as soft as the
        joint's cfm makes it: left in ``soft``, by articulation, for ``_soft_rows``."""
        w = self.world
        q = float(w.joint_state(dj.art, [dj.index])[0][0])
        target = velocity * motor_factor(q, dj.limits, velocity, w.dt, dj.erp)
        if not (math.isfinite(dj.row_mass) and dj.cfm > 0.0):
            w.joint_motor(dj.art, dj.index, target, dj.max_force)
            return
        soft.setdefault(id(dj.art), []).append((dj, target))

    def _soft_rows(self, rows: list[tuple[DrivenJoint, float]]) -> None:
        """The soft motor rows of one articulation: where the engine plays AMBF's solver on the
        chain's bodies (``chain_velocities``) and these rows drive every joint of it, the impulses
        that take the joints where its ten iterations leave them; otherwise settled together
        (``soft_row_impulses``). Each joint is pushed with its impulse over the control step,
        within its motor's force where the rows are settled here. The other forces' change in the
        step before is taken to last, less what the contacts gave the joints where the chain step
        took them in (World.chain_contacts)."""
        w = self.world
        art = rows[0][0].art
        idx = [dj.index for dj, _ in rows]
        v = np.asarray(w.joint_state(art, idx)[1], dtype=float)
        last = self._rows.get(id(art))
        mobility = w.joint_mobility(art, idx)
        chain = getattr(w, "chain_velocities", None)
        after = None
        if chain is not None and len(rows) == len(art.records):
            after = chain(art, {dj.index: (t, dj.cfm, dj.max_force * w.dt) for dj, t in rows}, {})
        free = v
        if last is not None and last[0] == idx:  # the other forces' change in the step before
            change = v - last[1] @ last[2] - last[3]
            # less the contacts' share where the chain's rows met them (as pushes, within the
            # motors' caps) and the engine meets them again in its step: AMBF's contact rows are
            # solved with its motor rows, not pushed against as a force that lasts
            contact = w.chain_contacts(art) if after is not None else None
            free = v + (change if contact is None else change - contact[idx])
        if after is not None:
            impulse = np.linalg.lstsq(mobility, after[idx] - free, rcond=None)[0]
        else:
            impulse = soft_row_impulses(
                mobility, [dj.row_mass for dj, _ in rows], [dj.cfm for dj, _ in rows], [t for _, t in rows], free
            )
        cdt = w.dt * w.opt.control_substeps
        if after is None:  # the rows settled here: each within its motor's `max motor impulse`
            cap = np.array([dj.max_force * cdt for dj, _ in rows])
            impulse = np.clip(impulse, -cap, cap)
        # (the chain step's rows hold each motor within it already; the push that carries the
        # articulation where its bodies went carries what the chain's other rows gave them too)
        for (dj, _t), lam in zip(rows, impulse):
            w.joint_effort(art, dj.index, float(lam) / cdt)
        self._rows[id(art)] = (idx, mobility, impulse, v)

    def _as_ambf_reads(self, dj: DrivenJoint, q: float, t: float) -> float:
        """A slider's position as AMBF's controller reads it (btSliderConstraint::getLinearPos: the
        value cached when the last physics step's solve began, so a physics step old; a hinge's
        angle it reads fresh), where each control step is one physics step under AMBF's bodies
        (`adfkit parity` with a joint program); else ``q`` as read."""
        w, last = self.world, dj.last_read
        dj.last_read = (t, q)
        if dj.kind is not JointKind.PRISMATIC or w.opt.control_substeps != 1 or w.opt.bodies != "ambf":
            return q
        return last[1] if last is not None and abs(t - last[0] - w.dt) < 1e-9 else q

    def apply(self, t: float) -> None:
        """Every joint's last command, at simulated time ``t`` (call it between control steps)."""
        w = self.world
        soft: dict[int, list] = {}  # an articulation's soft motor rows, settled together below
        for dj in self.joints.values():
            kind, value = dj.command
            if dj.kind in SPRINGS and kind != "effort":
                continue  # AMBF moves a spring by effort only (afJoint::commandPosition, commandVelocity)
            if kind == "velocity":
                self._motor(dj, value, soft)
            elif kind == "effort":
                self._effort(dj, value)
            elif dj.motor:  # AMBF ignores a position command (with a warning) without a motor
                current = self._as_ambf_reads(dj, float(w.joint_state(dj.art, [dj.index])[0][0]), t)
                target = value
                if dj.limits is not None:
                    target = min(max(target, dj.limits[0]), dj.limits[1])
                elif dj.kind is JointKind.REVOLUTE:
                    target, current = shortest_angle(current, target), 0.0
                out = dj.controller.output(current, target, t)
                if dj.output == "force":
                    self._effort(dj, out)
                else:
                    self._motor(dj, out, soft)
        for rows in soft.values():
            self._soft_rows(rows)
