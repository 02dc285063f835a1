"""The suture's motion primitives, generators that yield once per control step: Cartesian and
joint-space moves of a PSM, carrying the needle, taking it (a guarded approach along the jaw
axis, then the constraint actuator) and letting it go. A mixin of SutureTask."""

from __future__ import annotations

import numpy as np

from ..runner.psm import JAW_OPEN, PSM
from ..runner.psm_kinematics import JointLimitError
from ..runner.rotations import invert, rotation_exp, rotation_log
from .contact_forces import limit_scale
from .grasping import BACK_OFF, JAW_APPROACH, JAW_DEPTH, ROLL, Grasp, SutureError

CLIP_TOLERANCE = 0.15  # rad (m for the insertion) a set-point may pass a limit and be clipped
#: N (times the engine's limit scale, contact_forces.py): a tool coming onto the needle stops
#: where it presses on the tissue this hard ...
GUARD_N = 20.0
GUARD_BACK = 0.0005  # m ... and draws back this far the way it came
#: rad the jaws close back from the finger that got least far, while they press on the tissue as
#: they open (0.05 rad a finger, 0.4 mm at its middle: at 0.02 the finger stayed on the boundary
#: with 50-60 N for 24 ms while the jaws closed a step at a time)
GUARD_JAW_BACK = 0.1
#: m: where the grasp on the needle has moved farther than this while a tool came over it (the
#: needle turning in the other arm's grasp), the tool is brought over the grasp where it is now,
#: in REAIM_S, before it comes down. The jaws, JAW_APPROACH apart, leave the wire 1.35 mm either
#: side; a needle settling on the tissue moves its grasp 0.5-0.6 mm while the arm comes (the
#: springy-holes copy's pick-up), a needle turning in the puller's jaws 3.4 mm (its seed 1, hand
#: back 3, where the driver's jaws came down on the wire and missed the grasp by 6 mm)
REAIM = 0.001
REAIM_S = 0.3


def _backed_off(ee: np.ndarray) -> np.ndarray:
    """The end-effector pose BACK_OFF back along its jaw axis."""
    out = ee.copy()
    out[:3, 3] -= BACK_OFF * ee[:3, 2]
    return out


def _apart(a: np.ndarray, b: np.ndarray) -> float:
    """How far pose b is from pose a: metres, or the turn between them as the arc it sweeps at
    the jaws' depth (m)."""
    turn = float(np.linalg.norm(rotation_log(a[:3, :3].T @ b[:3, :3])))
    return max(float(np.linalg.norm(b[:3, 3] - a[:3, 3])), turn * JAW_DEPTH)


def interpolate(a: np.ndarray, b: np.ndarray, s: float) -> np.ndarray:
    """Pose between a and b: straight line, rotation about one axis."""
    t = np.eye(4)
    t[:3, :3] = a[:3, :3] @ rotation_exp(s * rotation_log(a[:3, :3].T @ b[:3, :3]))
    t[:3, 3] = (1 - s) * a[:3, 3] + s * b[:3, 3]
    return t


def smooth(s: float) -> float:
    return s * s * (3 - 2 * s)


class Motions:
    def _set_phase(self, name: str):
        self.phase = name
        self.phase_log.append((name, self.world.sim_time))

    def _steps(self, seconds: float) -> int:
        return max(1, int(round(seconds / self.speed / self.cdt)))

    def servo_world(self, psm: PSM, ee_world: np.ndarray) -> None:
        """Cartesian set-point in the world; a pose a little past a joint limit (the grasp
        as measured differs from the planned one by a few degrees) is servoed with the joints
        clipped to their limits, and counted.

        The IK gives the tool's roll in (-pi, pi], its limits are +-3.054 rad: a path that turns
        it past +pi comes back near -pi, inside the limits or, clipped, at the other limit, a
        full turn from where it is (in the corpus set the roll turned 5.2 rad in 60 ms toward
        it and threw the needle out of the tissue). The roll is taken the way nearest the
        set-point, so that a path past a limit stops at the limit it met, or is refused."""
        try:
            q = psm.kin.ik(invert(psm.base_in_world()) @ ee_world)
        except JointLimitError as exc:
            q = np.array(exc.q, dtype=float)
        now = psm.setpoint_jp()[ROLL]
        q[ROLL] = now + (q[ROLL] - now + np.pi) % (2 * np.pi) - np.pi
        lo, hi = psm.kin.lower_limits[:6], psm.kin.upper_limits[:6]
        past = float(np.max(np.maximum(lo - q, q - hi)))
        if past > CLIP_TOLERANCE:
            raise JointLimitError(q, psm.kin.violations(q))
        if past > 0:
            self.clipped += 1
        psm.servo_jp(np.clip(q, lo, hi))

    def setpoint_world(self, psm: PSM) -> np.ndarray:
        return psm.base_in_world() @ psm.setpoint_cp()

    def move(self, psm: PSM, goal: np.ndarray, seconds: float, settle: float = 0.15):
        """Free-space move: the IK at the goal, joints interpolated (the wrist never passes
        through an unreachable orientation on the way)."""
        try:
            q = psm.kin.ik(invert(psm.base_in_world()) @ goal)
        except JointLimitError as exc:  # a little past a limit: go as near as the joints allow
            lo, hi = psm.kin.lower_limits[:6], psm.kin.upper_limits[:6]
            if np.max(np.maximum(lo - exc.q, exc.q - hi)) > CLIP_TOLERANCE:
                raise
            q = np.clip(exc.q, lo, hi)
            self.clipped += 1
        yield from self.move_jp(psm, q, seconds, settle)

    def move_jp(self, psm: PSM, q1, seconds: float, settle: float = 0.15):
        """From the set-point to q1, each joint along a straight line in joint space. A joint
        whose ends are both within its limits stays within them on the way: q0 + (q1 - q0) * s
        can round one ulp past q1, and a goal clipped onto a limit (``move``) was then refused
        by servo_jp (a phantom's carry 1 stopped there, "outer_wrist_yaw = 1.396 (limits
        -1.396…1.396)", its plan good); the values within the limits are those of the line."""
        q0 = psm.setpoint_jp()
        q1 = np.asarray(q1, dtype=float)
        lo, hi = psm.kin.lower_limits[: len(q1)], psm.kin.upper_limits[: len(q1)]
        kept = (q0 >= lo) & (q0 <= hi) & (q1 >= lo) & (q1 <= hi)
        n = self._steps(seconds)
        for i in range(1, n + 1):
            q = q0 + (q1 - q0) * smooth(i / n)
            psm.servo_jp(np.where(kept, np.clip(q, lo, hi), q))
            yield self.phase
        yield from self.wait(settle)

    def wait(self, seconds: float):
        for _ in range(self._steps(seconds)):
            yield self.phase

    def line(self, psm: PSM, a: np.ndarray, b: np.ndarray, seconds: float, guarded: bool = False):
        """The end effector from pose a to pose b along a straight line (Cartesian). Guarded: it
        stops where the tool first presses on the tissue with GUARD_N (and stays there), as a
        hand stops on touching; the plan keeps the tools off the tissue, but a few tenths of a
        millimetre of clearance leave no room for the servo's overshoot."""
        n = self._steps(seconds)
        touch = self._touch(psm) if guarded else None
        for i in range(1, n + 1):
            self.servo_world(psm, interpolate(a, b, smooth(i / n)))
            yield self.phase
            if touch is not None and self._pressing(*touch):
                stop = psm.base_in_world() @ psm.measured_cp()
                stop[:3, 3] -= (
                    GUARD_BACK * (b[:3, 3] - a[:3, 3]) / max(float(np.linalg.norm(b[:3, 3] - a[:3, 3])), 1e-9)
                )
                self.servo_world(psm, stop)  # where it touched, a little back the way it came
                return

    def carry(self, path, seconds: float):
        """The holder moves the needle through needle poses path(s), s in [0, 1] (Cartesian)."""
        psm = self.psms[self.holder]
        n = self._steps(seconds)
        for i in range(1, n + 1):
            self.servo_world(psm, path(i / n) @ self.held_ee_in_needle)
            yield self.phase

    def carry_to(self, goal: np.ndarray, seconds: float):
        """The holder takes the needle to a pose through joint space."""
        yield from self.move(self.psms[self.holder], goal @ self.held_ee_in_needle, seconds, settle=0.0)

    def take(self, name: str, grasp: Grasp, opening: float = JAW_APPROACH):
        """``name`` opens its jaws (``opening`` rad), comes down along its jaw axis onto the
        grasp (on the needle where it is now) and holds the needle."""
        psm = self.psms[name]
        goal = self.needle_pose() @ grasp.ee_in_needle
        above = _backed_off(goal)
        psm.servo_jaw(opening)
        yield from self.move(psm, above, 0.8)
        now = self.needle_pose() @ grasp.ee_in_needle
        if _apart(goal, now) > REAIM:  # the needle moved (in the other arm's grasp) while this one came
            goal, above = now, _backed_off(now)
            self.reaimed += 1
            yield from self.move(psm, above, REAIM_S, settle=0.0)
        yield from self.line(psm, above, goal, 0.5, guarded=True)  # along the jaw axis, as the plan checked it
        yield from self.wait(0.2)
        ee = psm.base_in_world() @ psm.measured_cp()
        miss = float(np.linalg.norm(ee[:3, 3] - (self.needle_pose() @ grasp.ee_in_needle)[:3, 3]))
        if miss > 0.004:
            raise SutureError(f"{name} missed the needle by {miss * 1000:.1f} mm ({self.phase})")
        # the wire lies between the open jaws: the actuator holds it where it is (and the jaws
        # no longer collide with it), then the jaws close on it; closing them first would
        # squeeze the wire out toward their tips (measured: 3.6 mm and 26 degrees off the plan)
        act = next(a for a in self.world.actuators if f"/{name}/" in a.key or f"/{name}/" in a.parent.key)
        self.world.actuate(act, self.needle)
        self.holder = name
        self.held_ee_in_needle = invert(self.needle_pose()) @ ee
        psm.servo_jaw(0.0)
        yield from self.closing(psm, 0.15)

    def _touch(self, psm: PSM) -> tuple[list, set[int]]:
        """What a guard watches: the arm's links and the tissue (roles.py) they may press on."""
        return self.roles.robots[psm.name], self.roles.tissue_ids()

    def _pressing(self, links: list, tissue: set[int]) -> bool:
        """One of ``links`` presses on the tissue with GUARD_N or more (after the last step)."""
        guard = GUARD_N * limit_scale(self.world)
        return any(f >= guard for _, o, f, _ in self.world.contacts_among(links) if id(o) in tissue)

    def opening(self, psm: PSM, seconds: float):
        """Wait ``seconds`` while the jaws open; while they press on the tissue with GUARD_N they
        close back to GUARD_JAW_BACK less than the finger that got least far, as the guarded
        line stops on touching. The planner keeps the jaws off the tissue by its distance field, which can
        overstate the room by 0.6 mm: at pair 1 of the bundled scene the driver's jaws, opened
        to let go, came 0.15 mm into Entry1's boundary and, in MuJoCo's rigid contacts, pressed
        on it with 130-260 N."""
        yield from self._guarded_jaws(psm, seconds, lambda f: max(0.0, 2 * float(min(f)) - GUARD_JAW_BACK))

    def closing(self, psm: PSM, seconds: float):
        """Wait ``seconds`` while the jaws close on the held needle; while they press on the
        tissue with GUARD_N they open back to GUARD_JAW_BACK more than the finger that got least
        far, as the opening does (the actuator holds the needle either way). On a phantom's tray
        the driver's fingers, closing round the wire in its slot, pressed on it with 56 N held."""
        yield from self._guarded_jaws(psm, seconds, lambda f: min(JAW_OPEN, 2 * float(max(f)) + GUARD_JAW_BACK))

    def _guarded_jaws(self, psm: PSM, seconds: float, back):
        """Wait ``seconds``; after each step where the jaws press on the tissue with GUARD_N,
        command them to ``back(fingers)`` (the finger that got least far decides where both stop)."""
        touch = self._touch(psm)
        for _ in range(self._steps(seconds)):
            yield self.phase
            if self._pressing(*touch):
                psm.servo_jaw(back(self.world.joint_state(psm.art, psm.jaws)[0]))

    def let_go(self, name: str, holder: str | None = None):
        """``name`` releases the needle and backs off. ``holder``, the arm that keeps it, is then
        put where the needle settled (once): freed from the other grasp, the needle settles where
        the tissue holds it, up to 2.7 mm from where both grasps had it, and a grasp that stayed
        put would stay strained by that much."""
        psm = self.psms[name]
        act = next(a for a in self.world.actuators if f"/{name}/" in a.key or f"/{name}/" in a.parent.key)
        self.world.release(act)
        psm.servo_jaw(JAW_APPROACH)
        yield from self.opening(psm, 0.15)
        if holder is not None:
            keep = self.psms[holder]
            yield from self.line(keep, self.setpoint_world(keep), self.needle_pose() @ self.held_ee_in_needle, 0.2)
        back = _backed_off(self.setpoint_world(psm))
        back[2, 3] += 0.01
        yield from self.move(psm, back, 0.5, settle=0.0)
