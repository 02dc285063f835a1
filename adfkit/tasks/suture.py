"""The scripted suture: phases and planner over the CRTK-style PSM API (adfkit.runner.psm.PSM)
and the closed-form IK, engine-neutral (the runner's World interface only).

One PSM (the driver, on the entry side) picks the needle up near its tail, carries it to
entry hole k and drives the tip along the needle's own arc (a rotation about the needle's
centre, planned in Cartesian space, servoed through the IK) through entry k and out of exit k.
The other PSM (the puller) grasps the needle near its tip, the driver lets go, the puller turns
the needle on along its arc until the tail is out and lifts it, pulling the thread through;
the driver takes the needle back at its tail for the next pair.

The needle pose comes from the simulation (ground truth). Every grasp fixes the needle to the
tool where it lies (the scene's constraint actuator), so after a grasp the planner measures
the needle in the tool frame and plans tool poses from needle poses.

``SutureTask.steps()`` is a generator: it commands set-points and yields once per control
step (the phase name); whoever drives it steps the world after each yield (run_episode,
a Gymnasium env, an expert policy).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from ..adf.paths import collision_mesh_path
from ..runner.psm import JAW_OPEN, PSM
from ..runner.psm_kinematics import JointLimitError
from ..runner.rotations import invert, rotation_exp, rotation_log
from .clearance import Tissue, ToolShape, clearances
from .holes import hole_frame
from .needle import fit_needle, obj_vertices

JAW_DEPTH = 0.01  # m from the end effector to the point between the jaws (LND: along z_E)
#: m from the end effector to where the wire is held: 1 mm short of the fingers' ends (11.5 mm), so
#: that the jaws reach no farther than the wire's far side (a needle lying on the tissue is taken
#: from above without the fingers pressing into the tissue)
GRASP_DEPTH = 0.0105
BACK_OFF = 0.012  # m along -z_E before a grasp and after a release
LIFT = 0.015  # m the needle is lifted when carried between the phantom and a hole
APPROACH = math.radians(15)  # the tip starts this far before the entry on its arc
MAX_GRASP = math.radians(25)  # the grasps sit at most this far from the tip / the tail ...
CLEAR = math.radians(10)  # ... and at least this far outside the tissue
MAX_BITE = math.radians(65)  # the arc between entry and exit; wider bites aim inside the holes
HOLE_MARGIN = 0.0008  # m kept from a hole ghost's side when aiming inside it
TAIL_CLEAR = math.radians(25)  # the pull ends with the tail this far beyond the exit
CLIP_TOLERANCE = 0.15  # rad (m for the insertion) a set-point may pass a limit and be clipped
JITTER_FORCE = 0.03  # N, the seeded push on the needle before the suture
TOOL_CLEARANCE = 0.0015  # m the planner keeps the tool's shapes from the tissue's where it can
#: rad between the jaws as they come onto the wire: a 3.9 mm gap at the wire for its 1.2 mm, and
#: fingers 2.5 mm to each side instead of the 5.6 mm of a fully opened jaw, beside the tissue
JAW_APPROACH = 0.35
GRASP_STEP = math.radians(6)  # the planner tries grasps this far apart along the wire ...
MIN_GRASP = math.radians(8)  # ... from this far from the tip or the tail (the jaws' width)
GUARD_N = 20.0  # N: a tool coming onto the needle stops where it presses on the tissue this hard ...
GUARD_BACK = 0.0005  # m ... and draws back this far the way it came
PARK_RETRACT = 0.03  # m a waiting tool is drawn back along its shaft
CHECK_STEP = math.radians(5)  # the tool's clearance is checked at needle poses this far apart


class SutureError(RuntimeError):
    """The planner cannot go on (no reachable grasp, a lost needle, ...)."""


@dataclass
class HolePair:
    index: int
    entry: object  # SimGhost
    exit: object
    entry_name: str
    exit_name: str


def _rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    t = np.eye(4)
    t[:2, :2] = [[c, -s], [s, c]]
    return t


def interpolate(a: np.ndarray, b: np.ndarray, s: float) -> np.ndarray:
    """Pose between a and b: straight line, rotation about one axis."""
    t = np.eye(4)
    t[:3, :3] = a[:3, :3] @ rotation_exp(s * rotation_log(a[:3, :3].T @ b[:3, :3]))
    t[:3, 3] = (1 - s) * a[:3, 3] + s * b[:3, 3]
    return t


def _smooth(s: float) -> float:
    return s * s * (3 - 2 * s)


def _in_plane_room(ghost, direction) -> float:
    """How far from its centre a hole ghost reaches along ``direction`` (in its plane)."""
    geo = getattr(ghost.ghost, "geometry", None)
    if geo is None or geo.x is None or geo.y is None:
        return 0.0
    return min(geo.x, geo.y) / 2 * (ghost.ghost.scale or 1.0)


def hole_pairs(world) -> list[HolePair]:
    """Entry k / Exit k hole ghosts of the scene, by their number."""
    found: dict[int, dict] = {}
    for g in world.ghosts:
        name = (g.ghost.name or g.ghost.identifier).lower()
        m = re.search(r"(entry|exit)\D*(\d+)\s*$", name)
        if m and g.friction:
            found.setdefault(int(m.group(2)), {})[m.group(1)] = g
    out = []
    for k in sorted(found):
        d = found[k]
        if "entry" in d and "exit" in d:
            out.append(
                HolePair(
                    k,
                    d["entry"],
                    d["exit"],
                    d["entry"].ghost.name or d["entry"].ghost.identifier,
                    d["exit"].ghost.name or d["exit"].ghost.identifier,
                )
            )
    return out


def find_needle(world):
    """The needle body and its measured geometry (tail: where the thread is attached)."""
    needle = world.body("Needle")
    b, m = needle.body, needle.model
    path = collision_mesh_path(m, b)
    if path is None or not path.is_file():
        raise SutureError(f"{needle.key}: no collision mesh to measure the needle from")
    v = obj_vertices(path) * (b.scale or 1.0)
    hint = None
    for j in m.joints:
        if j.parent and j.parent.split()[-1] == b.identifier.split()[-1] and j.parent_pivot is not None:
            hint = np.array([j.parent_pivot.x, j.parent_pivot.y, j.parent_pivot.z], float) * (b.scale or 1.0)
            break
    return needle, fit_needle(v, hint)


@dataclass
class Grasp:
    """Where a PSM holds the needle: the end effector's pose in the needle frame."""

    ee_in_needle: np.ndarray
    margin: float
    clearance: float = math.inf  # m the tool keeps from the tissue where the plan checked it


class SutureTask:
    """The scripted suture on a SimWorld with two PSMs (see the module docstring)."""

    def __init__(
        self,
        world,
        pairs: list[int],
        seed: int = 0,
        psm_names=("psm1", "psm2"),
        speed: float = 1.0,
        tools_collide_with_tissue: bool = True,
    ) -> None:
        self.world = world
        self.tools_collide_with_tissue = tools_collide_with_tissue
        self.switched_off: list[str] = []  # what of the physics the task does not carry out (reported)
        self.rng = np.random.default_rng(seed)
        self.speed = speed
        self.cdt = world.dt * world.opt.control_substeps
        self.needle, self.geom = find_needle(world)
        all_pairs = {p.index: p for p in hole_pairs(world)}
        missing = [k for k in pairs if k not in all_pairs]
        if missing:
            have = ", ".join(str(k) for k in sorted(all_pairs)) or "none"
            raise SutureError(f"the scene has no entry/exit hole pair {missing} (pairs: {have})")
        self.pairs = [all_pairs[k] for k in pairs]
        self.psms = {n: PSM(world, n) for n in psm_names}
        self.phase = "start"
        self.clipped = 0  # set-points clipped to the joint limits
        self.phase_log: list[tuple[str, float]] = []  # (phase, simulated start time)
        self.holder: str | None = None  # the PSM holding the needle
        self.held_ee_in_needle: np.ndarray | None = None
        # seeded variation of the plan
        self.grasp_jitter = self.rng.uniform(-0.04, 0.04, 2)
        self.approach = APPROACH + self.rng.uniform(-0.05, 0.05)

    # ---- geometry ----------------------------------------------------------------------
    def needle_pose(self) -> np.ndarray:
        return self.needle.world_matrix()

    def tip_world(self) -> np.ndarray:
        return (self.needle_pose() @ np.r_[self.geom.tip, 1.0])[:3]

    def arc_frame(self, pair: HolePair):
        """Frame B at the circle's centre for this pair (x toward the entry point, z the axis
        about which the tip goes from entry to exit), the exit's angle in it, how far the tip
        goes beyond the exit and how far from the ends the two grasps sit.

        The needle's circle goes through an aim point in each hole: the hole's centre, or,
        where the holes are farther apart than a bite of MAX_BITE, a point inside each hole
        ghost toward the other one (the tip still passes through both ghosts). A hole is where
        its boundary body is (holes.hole_frame), the ghost only where there is none."""
        e = hole_frame(self.world, pair.entry)
        x = hole_frame(self.world, pair.exit)
        pe, px = e[:3, 3], x[:3, 3]
        up = e[:3, 2] + x[:3, 2]
        if up[2] < 0:
            up = -up
        r = self.geom.radius
        d = px - pe
        dist = float(np.linalg.norm(d))
        dn = d / dist
        want = 2 * r * math.sin(MAX_BITE / 2)
        if dist > want:
            room = min(_in_plane_room(g, dn) for g in (pair.entry, pair.exit))
            inset = min((dist - want) / 2, max(0.0, room - HOLE_MARGIN))
            pe, px = pe + inset * dn, px - inset * dn
            dist -= 2 * inset
        if dist >= 2 * r * 0.98:
            raise SutureError(
                f"entry and exit of pair {pair.index} are {dist * 1000:.1f} mm apart; "
                f"the needle spans {2 * r * 1000:.1f} mm"
            )
        w = up - np.dot(up, dn) * dn
        w /= np.linalg.norm(w)
        c = (pe + px) / 2 + math.sqrt(r * r - dist * dist / 4) * w
        xa = (pe - c) / np.linalg.norm(pe - c)
        za = np.cross(pe - c, px - c)
        za /= np.linalg.norm(za)
        b = np.eye(4)
        b[:3, :3] = np.c_[xa, np.cross(za, xa), za]
        b[:3, 3] = c
        psi_x = math.acos(float(np.clip(np.dot(xa, (px - c) / r), -1, 1)))
        free = self.geom.span - psi_x  # arc outside the tissue when the bite is full
        if free < 2 * CLEAR + math.radians(16):
            raise SutureError(
                f"pair {pair.index}: the needle's arc ({math.degrees(self.geom.span):.0f}°) leaves "
                f"{math.degrees(free):.0f}° outside a {math.degrees(psi_x):.0f}° bite; too little to hold it"
            )
        g = min(MAX_GRASP, free / 2 - CLEAR - math.radians(2))
        g_tip, g_tail = g + self.grasp_jitter[0] * g / MAX_GRASP, g + self.grasp_jitter[1] * g / MAX_GRASP
        beyond = (g_tip + CLEAR + free - g_tail - CLEAR) / 2
        return b, psi_x, beyond, g_tip, g_tail

    def needle_at(self, b: np.ndarray, psi: float) -> np.ndarray:
        """Needle body pose with its tip at angle psi in arc frame B."""
        return b @ _rot_z(psi) @ invert(self.geom.arc_in_needle)

    def lifted(self, pose: np.ndarray, dz: float) -> np.ndarray:
        out = pose.copy()
        out[2, 3] += dz
        return out

    # ---- grasp selection ---------------------------------------------------------------
    def grasp_candidates(self, phi: float):
        """End-effector poses in the needle frame that hold the wire at arc angle phi between
        the jaws (the wire across the opening direction y_E): around the wire in 15° steps,
        both ways, the wire square to the jaws or turned up to 45° about y_E. Each comes with
        its turn (rad), which the choice penalises slightly."""
        g = self.geom
        a = g.arc_in_needle
        p = g.point(phi)
        t = a[:3, :3] @ np.array([-math.sin(phi), math.cos(phi), 0.0])
        radial = a[:3, :3] @ np.array([math.cos(phi), math.sin(phi), 0.0])
        n = a[:3, 2]
        out = []
        for turn in np.radians([0.0, 25.0, -25.0, 45.0, -45.0]):
            for sign in (1.0, -1.0):
                for beta in np.radians(np.arange(0, 360, 15)):
                    z0 = math.cos(beta) * -radial + math.sin(beta) * n
                    x0 = sign * t
                    x = math.cos(turn) * x0 - math.sin(turn) * z0
                    z = math.sin(turn) * x0 + math.cos(turn) * z0
                    m = np.eye(4)
                    m[:3, :3] = np.c_[x, np.cross(z, x), z]
                    m[:3, 3] = p - GRASP_DEPTH * z
                    out.append((m, abs(float(turn))))
        return out

    def _along_wire(self, phi: float, clear_at: tuple):
        """Candidates at phi and, where the tool's clearance is checked, at other places of the
        same end of the wire (from MIN_GRASP up to phi), nearest to phi first."""
        yield from self.grasp_candidates(phi)
        if not clear_at:
            return
        tail_end = phi < -self.geom.span / 2
        end = -self.geom.span if tail_end else 0.0
        room = abs(phi - end) - MIN_GRASP
        for d in np.arange(GRASP_STEP, room + 1e-9, GRASP_STEP):
            yield from self.grasp_candidates(phi - d if tail_end else phi + d)

    def _margin(self, psm: PSM, ee_world: np.ndarray) -> float:
        try:
            q = psm.kin.ik(invert(psm.base_in_world()) @ ee_world)
        except ValueError:
            return -1.0
        lo, hi = psm.kin.lower_limits[:6], psm.kin.upper_limits[:6]
        return float(np.min(np.minimum(q - lo, hi - q) / (hi - lo)))

    def choose_grasp(
        self,
        psm: PSM,
        phi: float,
        needle_poses: list,
        down_at: np.ndarray | None = None,
        what: str = "",
        clear_at: tuple = (),
    ) -> Grasp:
        """The candidate grasp reachable at every needle pose that keeps the tool farthest from
        the tissue (up to TOOL_CLEARANCE) at the needle poses ``clear_at`` (the first one also
        on the approach along the jaw axis), then with the widest joint margin (with
        ``down_at``: the jaws must point down at that needle pose, to come from above)."""
        cands = [
            (m, turn) for m, turn in self._along_wire(phi, clear_at) if down_at is None or (down_at @ m)[2, 2] <= -0.5
        ]
        if not cands:
            raise SutureError(f"{psm.name}: no grasp of the needle from above ({what})")
        ee_in_n = np.array([m for m, _ in cands])
        clear = np.full(len(cands), TOOL_CLEARANCE)
        for i, pose in enumerate(clear_at):
            # the jaws as they come onto the wire there: wide open onto a needle lying on the tissue
            tool = self.tools_wide[psm.name] if i == 0 and down_at is not None else self.tools[psm.name]
            ee = pose[None] @ ee_in_n
            clear = np.minimum(clear, clearances(self.tissue_shapes, tool, ee, TOOL_CLEARANCE))
            if i == 0:  # and on the way in, along the jaw axis
                for f in (1.0, 2 / 3, 1 / 3):
                    back = ee.copy()
                    back[:, :3, 3] -= f * BACK_OFF * ee[:, :3, 2]
                    clear = np.minimum(clear, clearances(self.tissue_shapes, tool, back, TOOL_CLEARANCE))
        # the choice: the clearance (up to TOOL_CLEARANCE, in tenths of a millimetre), then the
        # wider joint margin
        clear_q = np.round(clear / 1e-4)
        best, best_key = None, None
        for i in np.argsort(-clear_q, kind="stable"):
            if best_key is not None and clear_q[i] < best_key[0]:
                break  # the rest come nearer the tissue
            m, turn = cands[i]
            first = needle_poses[0] @ m
            back = first.copy()
            back[:3, 3] -= BACK_OFF * first[:3, 2]
            worst = self._margin(psm, back)  # the jaws come onto the wire along their axis
            for pose in needle_poses:
                if worst <= 0:
                    break
                worst = min(worst, self._margin(psm, pose @ m))
            margin = worst - 0.02 * turn
            key = (float(clear_q[i]), margin)
            if worst > 0 and (best_key is None or key > best_key):
                best, best_key = Grasp(m, margin, float(clear[i])), key
        if best is None:
            raise SutureError(f"{psm.name}: no grasp of the needle reachable along the whole plan ({what})")
        return best

    # ---- motion primitives (generators: one yield per control step) ----------------------
    def _set_phase(self, name: str):
        self.phase = name
        self.phase_log.append((name, self.world.sim_time))

    def _steps(self, seconds: float) -> int:
        return max(1, int(round(seconds / self.speed / self.cdt)))

    def servo_world(self, psm: PSM, ee_world: np.ndarray) -> None:
        """Cartesian set-point in the world; a pose a little past a joint limit (the grasp
        as measured differs from the planned one by a few degrees) is servoed with the joints
        clipped to their limits, and counted."""
        try:
            psm.servo_cp(invert(psm.base_in_world()) @ ee_world)
        except JointLimitError as exc:
            lo, hi = psm.kin.lower_limits[:6], psm.kin.upper_limits[:6]
            if np.max(np.maximum(lo - exc.q, exc.q - hi)) > CLIP_TOLERANCE:
                raise
            psm.servo_jp(np.clip(exc.q, lo, hi))
            self.clipped += 1

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
        q0 = psm.setpoint_jp()
        q1 = np.asarray(q1, dtype=float)
        n = self._steps(seconds)
        for i in range(1, n + 1):
            psm.servo_jp(q0 + (q1 - q0) * _smooth(i / n))
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
        links = [sb for sb in self.world.bodies if sb.articulation is psm.art] if guarded else []
        tissue = {id(sb) for sb in self.world.bodies if sb.model is self.needle.model and sb.static}
        for i in range(1, n + 1):
            self.servo_world(psm, interpolate(a, b, _smooth(i / n)))
            yield self.phase
            if links and any(f >= GUARD_N for sb in links for o, f, _ in self.world.contacts(sb) if id(o) in tissue):
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
        above = goal.copy()
        above[:3, 3] -= BACK_OFF * goal[:3, 2]
        psm.servo_jaw(opening)
        yield from self.move(psm, above, 0.8)
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
        yield from self.wait(0.15)

    def let_go(self, name: str, holder: str | None = None):
        """``name`` releases the needle and backs off. ``holder``, the arm that keeps it, is then
        put where the needle settled (once): freed from the other grasp, the needle settles where
        the tissue holds it, up to 2.7 mm from where both grasps had it, and a grasp that stayed
        put would stay strained by that much."""
        psm = self.psms[name]
        act = next(a for a in self.world.actuators if f"/{name}/" in a.key or f"/{name}/" in a.parent.key)
        self.world.release(act)
        psm.servo_jaw(JAW_APPROACH)
        yield from self.wait(0.15)
        if holder is not None:
            keep = self.psms[holder]
            yield from self.line(keep, self.setpoint_world(keep), self.needle_pose() @ self.held_ee_in_needle, 0.2)
        here = self.setpoint_world(psm)
        back = here.copy()
        back[:3, 3] -= BACK_OFF * here[:3, 2]
        back[2, 3] += 0.01
        yield from self.move(psm, back, 0.5, settle=0.0)

    # ---- the task ------------------------------------------------------------------------
    def _sides(self):
        """Driver: the PSM whose base lies on the entry side of the first pair."""
        p = self.pairs[0]
        d = self.world.ghost_pose(p.exit)[:3, 3] - self.world.ghost_pose(p.entry)[:3, 3]
        names = sorted(self.psms, key=lambda n: float(np.dot(self.psms[n].base_in_world()[:3, 3], d)))
        return names[0], names[-1]

    def setup_joints(self, reach: float = 0.17) -> dict:
        """Where a PSM's remote centre of motion is farther from the holes than the tool reaches
        (the corpus set: 0.26 m against 0.24 m of insertion), slide its base toward them, as a
        surgeon places the arm on its setup joints. Returns {psm: metres moved}."""
        target = np.mean(
            [self.world.ghost_pose(g)[:3, 3] for p in self.pairs for g in (p.entry, p.exit)]
            + [self.needle_pose()[:3, 3]],
            axis=0,
        )
        moved = {}
        for name, psm in self.psms.items():
            rcm = psm.base_in_world()[:3, 3]
            d = float(np.linalg.norm(target - rcm))
            if d <= reach + 1e-6:
                moved[name] = 0.0
                continue
            shift = (target - rcm) * (1 - reach / d)
            t = psm.base.world_matrix()
            t[:3, 3] += shift
            self.world.move_base(psm.base, t)
            moved[name] = float(np.linalg.norm(shift))
        return moved

    def plan(self):
        """Needle poses of the whole suture and, per pair, the grasps that reach them: the
        driver's (from where it takes the needle, over the approach, along the insertion) and
        the puller's (along the pull and the lift)."""
        n0 = self.needle_pose()
        self.driver, self.puller = self._sides()
        static = [sb for sb in self.world.bodies if sb.model is self.needle.model and sb.static]
        centres = [
            (hole_frame(self.world, p.entry)[:3, 3] + hole_frame(self.world, p.exit)[:3, 3]) / 2 for p in self.pairs
        ]
        self.tissue_shapes = Tissue(static, centres)
        self.tools = {n: ToolShape(self.world, psm) for n, psm in self.psms.items()}
        if not hasattr(self, "tools_wide"):  # planned without steps(): the jaws as they are
            self.tools_wide = self.tools
        self.frames = {p.index: self.arc_frame(p) for p in self.pairs}
        self.drive_grasps, self.pull_grasps, self.out_poses, self.handbacks = [], [], [], []
        self.pulls: list[tuple[float, list, tuple]] = []  # per pair: the grasp's angle, the poses, where clear
        for k, p in enumerate(self.pairs):
            b, psi_x, beyond, g_tip, g_tail = self.frames[p.index]
            psi_end = psi_x + beyond
            insertion = [self.lifted(self.needle_at(b, -self.approach), LIFT)]
            insertion += [self.needle_at(b, psi) for psi in np.linspace(-self.approach, psi_end, 7)]
            along = self.along_arc(b, -self.approach, psi_end)
            if k == 0:
                self.drive_grasps.append(
                    self.choose_grasp(
                        self.psms[self.driver],
                        -self.geom.span + g_tail,
                        [n0, self.lifted(n0, LIFT)] + insertion,
                        down_at=n0,
                        what=f"pair {p.index}, driving",
                        clear_at=(n0, insertion[0], *along),
                    )
                )
            else:
                self.drive_grasps.append(self.hand_back(k, g_tail, insertion))
            done = psi_x + self.geom.span + TAIL_CLEAR
            out = self.lifted(self.needle_at(b, done), 2 * LIFT)
            pull = [self.needle_at(b, psi) for psi in np.linspace(psi_end, done, 7)] + [out]
            clear = (*self.along_arc(b, psi_end, done), out)
            self.pulls.append((-g_tip, pull, clear))
            self.pull_grasps.append(
                self.choose_grasp(self.psms[self.puller], -g_tip, pull, what=f"pair {p.index}, pulling", clear_at=clear)
            )
            self.out_poses.append(out)

    def along_arc(self, b: np.ndarray, psi0: float, psi1: float) -> tuple:
        """Needle poses from psi0 to psi1 on its arc in frame b, CHECK_STEP apart (where the
        planner checks the tool's clearance)."""
        n = max(2, int(math.ceil(abs(psi1 - psi0) / CHECK_STEP)) + 1)
        return tuple(self.needle_at(b, psi) for psi in np.linspace(psi0, psi1, n))

    def pull_grasp_now(self, k: int) -> Grasp:
        """The puller's grasp for pair k chosen again on the needle where it is (the tissue
        holds it a little off the planned arc), reaching the rest of the pull and the hand-back
        pose the plan has; the planned grasp where none does."""
        phi, pull, clear = self.pulls[k]
        now = self.needle_pose()
        poses = [now, *pull[1:]] + self.handbacks[k : k + 1]
        try:
            return self.choose_grasp(self.psms[self.puller], phi, poses, clear_at=(now, *clear[1:]))
        except SutureError:
            return self.pull_grasps[k]

    def hand_back(self, k: int, g_tail: float, insertion: list) -> Grasp:
        """Where the puller, done with pair k-1, gives the needle back: over pair k, lifted,
        turned in its plane as little as both arms allow (the driver's grasp must reach it and
        the whole next insertion; the puller's grasp must reach it). Returns the driver's grasp
        and records the pose in self.handbacks."""
        b, _, _, _, _ = self.frames[self.pairs[k].index]
        puller = self.psms[self.puller]
        prev = self.pull_grasps[k - 1]
        for psi in np.radians(np.arange(-15, 250, 15)) - self.approach:
            h = self.lifted(self.needle_at(b, psi), 2 * LIFT)
            if self._margin(puller, h @ prev.ee_in_needle) <= 0:
                continue
            b_k, psi_x, beyond, _, _ = self.frames[self.pairs[k].index]
            try:
                g = self.choose_grasp(
                    self.psms[self.driver],
                    -self.geom.span + g_tail,
                    [h] + insertion,
                    clear_at=(h, insertion[0], *self.along_arc(b_k, -self.approach, psi_x + beyond)),
                )
            except SutureError:
                continue
            self.handbacks.append(h)
            return g
        raise SutureError(
            f"{self.driver}/{self.puller}: no pose over pair {self.pairs[k].index} where both "
            "arms can hand the needle over"
        )

    def tissue(self):
        m = self.needle.model
        return [
            sb
            for sb in self.world.bodies
            if sb.model is m and sb.static and "phantom" in (sb.body.name or sb.body.identifier).lower()
        ]

    def _arms_apart(self) -> None:
        """The two arms, brought closer on their setup joints, do not collide with each other's
        links (their links are coarse primitives). Everything else collides: the needle and the
        thread with the phantom and the hole boundaries at every step. The tools collide with the
        tissue when ``tools_collide_with_tissue`` (a touch is then recorded by the observer as an
        event with its force); otherwise that is switched off and named in the metrics."""
        arms = {n: [sb for sb in self.world.bodies if sb.articulation is psm.art] for n, psm in self.psms.items()}
        if not self.tools_collide_with_tissue:
            m = self.needle.model
            static = [sb for sb in self.world.bodies if sb.model is m and sb.static]
            for links in arms.values():
                for sb in links:
                    for t in static:
                        self.world.set_collision(t, sb, False)
            self.switched_off.append("tool-tissue collisions (asked for: SutureTask(tools_collide_with_tissue=False))")
        names = list(arms)
        for i, a in enumerate(names):
            for b in names[i + 1 :]:
                for x in arms[a]:
                    for y in arms[b]:
                        self.world.set_collision(x, y, False)

    @staticmethod
    def parked(psm: PSM) -> np.ndarray:
        """Where an arm waits while the other holds the needle: its joints as they are, the tool
        drawn PARK_RETRACT back along its shaft, out of the needle's and the thread's way (the
        carried needle hit a waiting tool's jaws with 28 N and moved 5 mm in the other grasp)."""
        lo, hi = psm.kin.lower_limits[:6], psm.kin.upper_limits[:6]
        q = np.clip(psm.setpoint_jp(), lo, hi)
        q[2] = max(lo[2], q[2] - PARK_RETRACT)
        return q

    def jitter(self, seconds: float = 0.05):
        """Seeded initial-pose jitter: a small random horizontal push on the needle."""
        f = self.rng.uniform(-1, 1, 2)
        f = JITTER_FORCE * f / max(np.linalg.norm(f), 1e-9)
        at = np.array(self.needle.com_position()) + self.rng.uniform(-0.004, 0.004, 3) * [1, 1, 0]
        for _ in range(self._steps(seconds)):
            self.needle.force([float(f[0]), float(f[1]), 0.0], at.tolist())
            yield self.phase
        yield from self.wait(0.4)

    def steps(self):
        """The whole suture, one yield per control step."""
        self._set_phase("settle")
        for name in self.psms:
            self.psms[name].servo_jaw(JAW_OPEN)
        self.base_moves = self.setup_joints()
        self._arms_apart()
        yield from self.jitter()
        # the tools' shapes as the jaws come onto the wire: wide open (the pick-up), then at
        # JAW_APPROACH (every other grasp)
        self.tools_wide = {n: ToolShape(self.world, psm) for n, psm in self.psms.items()}
        for name in self.psms:
            self.psms[name].servo_jaw(JAW_APPROACH)
        yield from self.wait(0.3)
        self.plan()
        d, p = self.psms[self.driver], self.psms[self.puller]
        park = {n: self.parked(self.psms[n]) for n in self.psms}
        self._set_phase("pick up")
        # a needle lying on the tissue is taken with the jaws wide open (0.8 rad): narrower,
        # a finger landing beside the wire shoves it (3.4 mm, 22 degrees at 0.35 rad)
        yield from self.take(self.driver, self.drive_grasps[0], opening=JAW_OPEN)
        for k, pair in enumerate(self.pairs):
            b, psi_x, beyond, _, _ = self.frames[pair.index]
            n_from = self.needle_pose()
            start = self.needle_at(b, -self.approach)
            self._set_phase(f"carry {pair.index}")
            up = self.lifted(n_from, LIFT)
            yield from self.carry(lambda s: interpolate(n_from, up, _smooth(s)), 0.6)
            yield from self.carry_to(self.lifted(start, LIFT), 1.2)
            over = self.lifted(start, LIFT)
            yield from self.carry(lambda s: interpolate(over, start, _smooth(s)), 0.8)
            yield from self.wait(0.2)
            self._set_phase(f"insert {pair.index}")
            psi_end = psi_x + beyond
            a0 = -self.approach
            yield from self.carry(lambda s: self.needle_at(b, a0 + (psi_end - a0) * s), (psi_end - a0) / 0.5)
            yield from self.wait(0.2)
            self._set_phase(f"regrasp {pair.index}")
            yield from self.take(self.puller, self.pull_grasp_now(k))
            yield from self.let_go(self.driver, holder=self.puller)
            yield from self.move_jp(d, park[self.driver], 0.8, settle=0.0)
            self.holder = self.puller
            self._set_phase(f"pull {pair.index}")
            done = psi_x + self.geom.span + TAIL_CLEAR
            # the pull turns the needle about its own centre from where the tissue holds it (a
            # few tenths of a millimetre off the plan), so that it follows its own channel
            b_now = self.needle_pose() @ self.geom.arc_in_needle @ _rot_z(-psi_end)
            yield from self.carry(
                lambda s: self.needle_at(b_now, psi_end + (done - psi_end) * s), (done - psi_end) / 0.6
            )
            out = self.needle_at(b_now, done)
            high = self.lifted(out, 2 * LIFT)
            yield from self.carry(lambda s: interpolate(out, high, _smooth(s)), 1.0)
            yield from self.wait(0.2)
            if k + 1 < len(self.pairs):
                self._set_phase(f"hand back {pair.index}")
                yield from self.carry_to(self.handbacks[k], 1.2)
                yield from self.wait(0.2)
                yield from self.take(self.driver, self.drive_grasps[k + 1])
                yield from self.let_go(self.puller, holder=self.driver)
                yield from self.move_jp(p, park[self.puller], 0.8, settle=0.0)
                self.holder = self.driver
        self._set_phase("done")
