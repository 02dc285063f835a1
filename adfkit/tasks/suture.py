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
from dataclasses import dataclass

import numpy as np

from ..adf.paths import collision_mesh_path
from ..runner.psm import JAW_OPEN, PSM
from ..runner.rotations import invert
from . import sweep
from .clearance import Tissue, ToolShape
from .grasping import (  # noqa: F401 - JAW_DEPTH, JAW_APPROACH and SutureError are the task's too
    JAW_APPROACH,
    JAW_DEPTH,
    SURE_CLEARANCE,
    TOOL_CLEARANCE,
    Grasp,
    GraspChoice,
    SutureError,
)
from .holes import boundary_body, ghost_box, hole_frame, hole_label, hole_name, opening_half_extents, slope_note
from .motions import Motions, interpolate, smooth
from .needle import fit_needle, obj_vertices, wire_radius
from .plan_warnings import plan_warnings
from .roles import body_roles

LIFT = 0.015  # m the needle is lifted when carried between the phantom and a hole
APPROACH = math.radians(15)  # the tip starts this far before the entry on its arc
MAX_GRASP = math.radians(25)  # the grasps sit at most this far from the tip / the tail ...
CLEAR = math.radians(10)  # ... and at least this far outside the tissue
MAX_BITE = math.radians(65)  # the arc between entry and exit; wider bites aim inside the holes
HOLE_MARGIN = 0.0008  # m kept from a hole ghost's side when aiming inside it
#: the pull ends with the tail this far beyond the exit: the first of these at which the puller
#: keeps SURE_CLEARANCE from the tissue (SutureTask.plan_pull)
TAIL_CLEARS = tuple(math.radians(a) for a in (25, 20, 15, 10))
JITTER_FORCE = 0.03  # N, the seeded push on the needle before the suture
#: s the puller takes to carry the needle over the next pair: the thread, through the earlier
#: pairs, drags behind it and the carried needle turns in the grasp (in 1.2 s it slipped 2.1-2.5 mm
#: on 2 of 10 seeds; in 2.4 s it turned up to 3 degrees, its far end 1.07 mm; in 3.0 s 0.94 mm)
HAND_BACK_S = 3.0
#: rad/s the needle turns about its centre as the puller draws it out (at 0.6 the thread, through
#: three pairs, dragged the needle 2.0 mm in the grasp during pull 4 on 1 of 10 seeds)
PULL_RATE = 0.4
#: m the pull ends with the needle lifted over where its tail cleared the exit
PULL_LIFT = 2 * LIFT
#: m over the next pair's start of the arc at which the puller hands the needle back
HAND_BACK_LIFT = 2 * LIFT
PARK_RETRACT = 0.03  # m a waiting tool is drawn back along its shaft
CHECK_STEP = math.radians(5)  # the tool's clearance is checked at needle poses this far apart
#: rad the insertion may be driven on past where the arc outside the tissue is shared evenly
#: between the two grasps, where the puller's tool would come nearer the tissue than
#: SURE_CLEARANCE as it takes the needle (SutureTask._plan_pair). On a phantom sloping 30 degrees
#: across, the exit the high side, the puller's pitch link came 0.09 mm from the tissue as planned
#: and struck it (10.9 kN) as it came for the tip; driven 15 degrees further, 1.5 mm, and it passed
FURTHER = tuple(math.radians(a) for a in (2.5, 5.0, 7.5, 10.0, 12.5, 15.0))
#: the plan's lists that _plan_pair makes again for a pair when it drives further, each with how
#: many pairs before the one planned its entries start (a hand-back is planned with the pair after it)
PLANNED = (("drive_grasps", 0), ("pull_grasps", 0), ("tail_clears", 0), ("pulls", 0), ("handbacks", 1))
PLANNED += (("handback_about_tail", 1),)
#: m from the pairs' centre (where the arms are set up, and a --phantom's placed) beyond which an
#: arm that reaches no grasp is told how far each pair lies (the bundled pairs lie within 36 mm)
SPREAD_NOTE = 0.04


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


def _in_plane_room(ghost, direction) -> float:
    """How far from its centre the tip may go through a hole: as far as its ghost reaches in its
    plane, or its boundary's opening where that is wider (a ghost smaller than the opening made
    the planner bite 14 mm at the holes' centres, and the wrist reached its limit on the way;
    the verdict then says the tip missed the ghost)."""
    box = ghost_box(ghost)
    room = min(box[0], box[1]) / 2 if box is not None else 0.0
    b = boundary_body(ghost)
    return max(room, float(min(opening_half_extents(b.body)))) if b is not None else room


def hole_ghosts(world) -> dict[int, dict]:
    """The hole ghosts (those with the viscous friction) named Entry k / Exit k: {k: {"entry":
    ghost, "exit": ghost}}, either missing where the scene lacks it."""
    found: dict[int, dict] = {}
    for g in world.ghosts:
        hole = hole_name(g.ghost.name or g.ghost.identifier)
        if hole and g.friction:
            found.setdefault(hole[1], {})[hole[0]] = g
    return found


def _missing_pair(k: int, found: dict[int, dict]) -> str:
    """What pair k lacks, in a modeller's words."""
    d = found.get(k, {})
    if not d:
        return f"pair {k}: no hole ghost named Entry{k} or Exit{k}"
    have, lack = ("entry", "exit") if "entry" in d else ("exit", "entry")
    g = d[have]
    return f"pair {k}: {g.ghost.name or g.ghost.identifier} has no {lack} hole ghost ({lack.capitalize()}{k}) beside it"


def hole_pairs(world) -> list[HolePair]:
    """Entry k / Exit k hole ghosts of the scene, by their number."""
    found = hole_ghosts(world)
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


class SutureTask(GraspChoice, Motions):
    """The scripted suture on a SimWorld with two PSMs (see the module docstring)."""

    def __init__(
        self,
        world,
        pairs: list[int],
        seed: int = 0,
        psm_names=("psm1", "psm2"),
        speed: float = 1.0,
        tools_collide_with_tissue: bool = True,
        not_tissue=(),
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
            found = hole_ghosts(world)
            lacks = "; ".join(_missing_pair(k, found) for k in missing)
            raise SutureError(f"{lacks} (the scene's whole pairs: {have})")
        self.pairs = [all_pairs[k] for k in pairs]
        self.psms = {n: PSM(world, n) for n in psm_names}
        # the needle, the thread, the arms' links and the tissue (everything else), for the plan
        # and the verdicts alike
        self.roles = body_roles(world, self.needle, self.psms, not_tissue)
        self.phase = "start"
        self.clipped = 0  # set-points clipped to the joint limits
        self.reaimed = 0  # takes brought over the needle again where it moved as the tool came (Motions.take)
        self.phase_log: list[tuple[str, float]] = []  # (phase, simulated start time)
        self.plan_warnings: list = []  # what the plan knows will go wrong (plan_warnings.py), once planned
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
        least = 2 * CLEAR + math.radians(16)  # two jaws' clearances and room for a grasp
        if free < least:
            farthest = 2 * r * math.sin(max(self.geom.span - least, 0.0) / 2)
            raise SutureError(
                f"pair {pair.index}: the needle bites {dist * 1000:.1f} mm from entry to exit (between the "
                f"holes' openings), {math.degrees(psi_x):.0f}° of its {math.degrees(self.geom.span):.0f}° arc: "
                f"the {math.degrees(free):.0f}° left outside the tissue is too little to hold it "
                f"(this needle, {r * 1000:.1f} mm radius, can drive a pair at most {farthest * 1000:.1f} mm apart)"
            )
        g = min(MAX_GRASP, free / 2 - CLEAR - math.radians(2))
        g_tip, g_tail = g + self.grasp_jitter[0] * g / MAX_GRASP, g + self.grasp_jitter[1] * g / MAX_GRASP
        beyond = (g_tip + CLEAR + free - g_tail - CLEAR) / 2
        return b, psi_x, beyond, g_tip, g_tail

    def check_sweep(self) -> dict[int, str]:
        """The needle's swept arc at each pair against the tissue's collision shapes, and the
        surface at the holes (sweep.py), in words per pair: what the physics will meet, said
        before it; kept as ``self.sweep`` for the verdicts' reasons."""
        self.sweep = sweep.check(self, wire_radius(self))
        return self.sweep

    def needle_at(self, b: np.ndarray, psi: float) -> np.ndarray:
        """Needle body pose with its tip at angle psi in arc frame B."""
        return b @ _rot_z(psi) @ invert(self.geom.arc_in_needle)

    def lifted(self, pose: np.ndarray, dz: float) -> np.ndarray:
        out = pose.copy()
        out[2, 3] += dz
        return out

    # ---- the task ------------------------------------------------------------------------
    def _sides(self):
        """Driver: the PSM whose base lies on the entry side of the first pair."""
        p = self.pairs[0]
        d = self.world.ghost_pose(p.exit)[:3, 3] - self.world.ghost_pose(p.entry)[:3, 3]
        names = sorted(self.psms, key=lambda n: float(np.dot(self.psms[n].base_in_world()[:3, 3], d)))
        return names[0], names[-1]

    def setup_joints(self, reach: float = 0.17) -> dict:
        """Where a PSM's remote centre of motion is farther from the holes than ``reach`` (the
        corpus set: 0.26 m against 0.24 m of insertion), slide its base across toward them, at
        its height, until it is that near, as a surgeon places the arm on its setup joints.
        Returns {psm: metres moved}."""
        target = np.mean(
            [self.world.ghost_pose(g)[:3, 3] for p in self.pairs for g in (p.entry, p.exit)]
            + [self.needle_pose()[:3, 3]],
            axis=0,
        )
        up = -np.asarray(self.world.gravity, dtype=float)
        up = up / np.linalg.norm(up) if np.linalg.norm(up) > 0 else np.array([0.0, 0.0, 1.0])
        moved = {}
        for name, psm in self.psms.items():
            rcm = psm.base_in_world()[:3, 3]
            d = float(np.linalg.norm(target - rcm))
            if d <= reach + 1e-6:
                moved[name] = 0.0
                continue
            # across, at the height the scene gives it, so that the arm's links below its remote
            # centre stay as far above the tissue as the scene placed them: the corpus PSM's pitch
            # end link reaches 80 mm below it; slid straight at the holes, 65 mm lower, that link
            # came 20 mm over the phantom's Barrier (a static box level with the slab) and pressed
            # on it with 730 kN as the arm pitched to hand the needle back over pair 2
            rise = float(np.dot(target - rcm, up))
            across = (target - rcm) - rise * up
            room = math.sqrt(max(reach * reach - rise * rise, 0.0))
            shift = across * max(0.0, 1 - room / max(float(np.linalg.norm(across)), 1e-12))
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
        centres = [
            (hole_frame(self.world, p.entry)[:3, 3] + hole_frame(self.world, p.exit)[:3, 3]) / 2 for p in self.pairs
        ]
        self.tissue_shapes = Tissue(self.roles.tissue, centres, triangles=sweep.triangles(self.world))
        self.tools = {n: ToolShape(self.world, psm) for n, psm in self.psms.items()}
        if not hasattr(self, "tools_wide"):  # planned without steps(): the jaws as they are
            self.tools_wide = self.tools
        self.frames = {p.index: self.arc_frame(p) for p in self.pairs}
        if not hasattr(self, "sweep"):
            self.check_sweep()
        self.drive_grasps, self.pull_grasps, self.handbacks, self.tail_clears = [], [], [], []
        self.handback_about_tail: list[bool] = []  # per hand-back: carried with the tail on a line
        self.pulls: list[tuple[float, list, tuple]] = []  # per pair: the grasp's angle, the poses, where clear
        for k, p in enumerate(self.pairs):
            try:
                self._plan_pair(k, p, n0)
            except SutureError as exc:
                ends = (p.entry, p.exit)
                steep = slope_note([(*map(hole_label, ends), *(hole_frame(self.world, g) for g in ends))])
                raise SutureError(f"{exc}{self._spread(centres)}{steep}") from exc
        self.plan_warnings = plan_warnings(self)

    def _spread(self, centres: list) -> str:
        """ "; the pairs lie ... from their centre" where one lies more than SPREAD_NOTE from it:
        a pair far from the others takes the arms' reach from all (a phantom's pair 2 moved
        200 mm away left pair 1 out of reach, and the message named pair 1 alone)."""
        if len(centres) < 2:
            return ""
        mid = np.mean(centres, axis=0)
        away = [float(np.linalg.norm(c - mid)) for c in centres]
        if max(away) <= SPREAD_NOTE:
            return ""
        each = ", ".join(f"pair {p.index} {a * 1000:.1f} mm" for p, a in zip(self.pairs, away))
        return (
            f"; the pairs lie up to {max(away) * 1000:.1f} mm from their centre, for which the arms are set up ({each})"
        )

    def _plan_pair(self, k: int, p: HolePair, n0: np.ndarray) -> None:
        """The driver's grasp (the pick-up's, or the hand-back's) and the puller's for pair p,
        the k-th visited; where the puller's tool comes nearer the tissue than SURE_CLEARANCE,
        the insertion driven on FURTHER: as far as keeps the puller farthest from it (the first
        that keeps it TOOL_CLEARANCE off) while the driver keeps its own clearance."""
        self._plan_drive_and_pull(k, p, n0)
        if self.pull_grasps[k].clearance >= SURE_CLEARANCE:
            return
        kept = self._planned(k)
        # the driver keeps what it had (up to SURE_CLEARANCE): on a slope its pick-up, on the
        # needle's bed, is often what comes nearest, and stays so however far it drives
        keep = min(self.drive_grasps[k].clearance, SURE_CLEARANCE) - 1e-4
        best = self.pull_grasps[k].clearance
        frame = self.frames[p.index]
        b, psi_x, beyond, g_tip, g_tail = frame
        for extra in FURTHER:
            self.frames[p.index] = (b, psi_x, beyond + extra, g_tip, g_tail)
            self._planned(k, drop=True)
            try:
                self._plan_drive_and_pull(k, p, n0)
            except SutureError:
                continue
            if self.drive_grasps[k].clearance >= keep and self.pull_grasps[k].clearance > best:
                best, frame, kept = self.pull_grasps[k].clearance, self.frames[p.index], self._planned(k)
            if best >= TOOL_CLEARANCE:
                break
        self.frames[p.index] = frame
        self._planned(k, drop=True)
        for (n, _), v in zip(PLANNED, kept):
            getattr(self, n).extend(v)

    def _planned(self, k: int, drop: bool = False) -> list:
        """What the plan holds for the k-th pair visited (PLANNED), dropped from it with ``drop``."""
        out = []
        for n, before in PLANNED:
            held = getattr(self, n)
            out.append(held[max(k - before, 0) :])
            if drop:
                del held[max(k - before, 0) :]
        return out

    def _plan_drive_and_pull(self, k: int, p: HolePair, n0: np.ndarray) -> None:
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
                    joint_moves=(2,),  # carry_to: from over the pick-up to over the entry
                )
            )
        else:
            self.drive_grasps.append(self.hand_back(k, g_tail, insertion))
        self.plan_pull(p, b, psi_x, psi_end, g_tip)

    def plan_pull(self, p: HolePair, b: np.ndarray, psi_x: float, psi_end: float, g_tip: float) -> None:
        """The puller's grasp for pair p and how far its pull turns the needle: the tail
        25 degrees beyond the exit (the thread drawn through; less, and the next hand-back drags
        it through the channel and the needle slips), or less where the wrist, turning with the
        needle, would bring the jaws nearer the tissue than SURE_CLEARANCE (measured at Exit1 of
        the bundled scene: 0.2-0.4 mm at 25 degrees, 0.8-1.4 mm at 12)."""
        best = None
        for tail in TAIL_CLEARS:
            done = psi_x + self.geom.span + tail
            out = self.lifted(self.needle_at(b, done), PULL_LIFT)
            pull = [self.needle_at(b, psi) for psi in np.linspace(psi_end, done, 7)] + [out]
            clear = (*self.along_arc(b, psi_end, done), out)
            try:
                g = self.choose_grasp(
                    self.psms[self.puller], -g_tip, pull, what=f"pair {p.index}, pulling", clear_at=clear
                )
            except SutureError:
                if tail == TAIL_CLEARS[-1] and best is None:
                    raise
                continue
            if best is None or g.clearance > best[0].clearance:
                best = (g, tail, (-g_tip, pull, clear))
            if g.clearance >= SURE_CLEARANCE:
                break
        g, tail, pull_plan = best
        self.pull_grasps.append(g)
        self.tail_clears.append(tail)
        self.pulls.append(pull_plan)

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
            return self.choose_grasp(
                self.psms[self.puller], phi, poses, clear_at=(now, *clear[1:]), joint_moves=(len(pull),)
            )
        except SutureError:
            return self.pull_grasps[k]

    def hand_back(self, k: int, g_tail: float, insertion: list) -> Grasp:
        """Where the puller, done with pair k-1, gives the needle back: over pair k, lifted,
        turned in its plane as little as both arms allow (the driver's grasp must reach it and
        the whole next insertion; the puller's grasp must reach it). Returns the driver's grasp
        and records the pose in self.handbacks."""
        b, psi_x, beyond, _, _ = self.frames[self.pairs[k].index]
        puller = self.psms[self.puller]
        prev = self.pull_grasps[k - 1]
        along = self.along_arc(b, -self.approach, psi_x + beyond)
        for psi in np.radians(np.arange(-15, 250, 15)) - self.approach:
            h = self.lifted(self.needle_at(b, psi), HAND_BACK_LIFT)
            if self._margin(puller, h @ prev.ee_in_needle) <= 0:
                continue
            try:
                g = self.choose_grasp(
                    self.psms[self.driver],
                    -self.geom.span + g_tail,
                    [h] + insertion,
                    clear_at=(h, insertion[0], *along),
                    joint_moves=(1,),  # carry_to: from over the pair before to over the entry
                )
            except SutureError:
                continue
            self.handbacks.append(h)
            self.handback_about_tail.append(self._tail_path_reached(k, h, puller, prev))
            return g
        raise SutureError(
            f"{self.driver}/{self.puller}: no pose over pair {self.pairs[k].index} where both "
            "arms can hand the needle over"
        )

    def about_tail(self, a: np.ndarray, b: np.ndarray):
        """Needle poses path(s), s in [0, 1], from a to b: the tail (where the thread is tied) on
        the straight line between, the needle turning about it."""
        t = np.eye(4)
        t[:3, 3] = self.geom.tail
        ta, tb = a @ t, b @ t
        return lambda s: interpolate(ta, tb, smooth(s)) @ invert(t)

    def _tail_path_reached(self, k: int, h: np.ndarray, puller: PSM, prev: Grasp) -> bool:
        """Whether the puller, holding the needle by ``prev``, reaches every pose of the path
        about the tail (about_tail) from where pull k-1 leaves the needle to the hand-back ``h``."""
        b, psi_x, _, _, _ = self.frames[self.pairs[k - 1].index]
        high = self.lifted(self.needle_at(b, psi_x + self.geom.span + self.tail_clears[k - 1]), PULL_LIFT)
        path = self.about_tail(high, h)
        return all(self._margin(puller, path(s) @ prev.ee_in_needle) > 0 for s in np.linspace(0.0, 1.0, 13))

    def tissue(self) -> list:
        """Every tissue body (roles.py)."""
        return self.roles.tissue

    def _arms_apart(self) -> None:
        """The two arms, brought closer on their setup joints, do not collide with each other's
        links (their links are coarse primitives). Everything else collides: the needle and the
        thread with the phantom and the hole boundaries at every step. The tools collide with the
        tissue when ``tools_collide_with_tissue`` (a touch is then recorded by the observer as an
        event with its force); otherwise that is switched off and named in the metrics."""
        arms = self.roles.robots
        if not self.tools_collide_with_tissue:
            for links in arms.values():
                for sb in links:
                    for t in self.roles.tissue:
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
            yield from self.carry(lambda s: interpolate(n_from, up, smooth(s)), 0.6)
            yield from self.carry_to(self.lifted(start, LIFT), 1.2)
            over = self.lifted(start, LIFT)
            yield from self.carry(lambda s: interpolate(over, start, smooth(s)), 0.8)
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
            done = psi_x + self.geom.span + self.tail_clears[k]
            # the pull turns the needle about its own centre from where the tissue holds it (a
            # few tenths of a millimetre off the plan), so that it follows its own channel
            b_now = self.needle_pose() @ self.geom.arc_in_needle @ _rot_z(-psi_end)
            yield from self.carry(
                lambda s: self.needle_at(b_now, psi_end + (done - psi_end) * s), (done - psi_end) / PULL_RATE
            )
            out = self.needle_at(b_now, done)
            high = self.lifted(out, PULL_LIFT)
            yield from self.carry(lambda s: interpolate(out, high, smooth(s)), 1.0)
            yield from self.wait(0.2)
            if k + 1 < len(self.pairs):
                self._set_phase(f"hand back {pair.index}")
                if self.handback_about_tail[k]:
                    yield from self.carry(self.about_tail(self.needle_pose(), self.handbacks[k]), HAND_BACK_S)
                else:
                    yield from self.carry_to(self.handbacks[k], HAND_BACK_S)
                yield from self.wait(0.2)
                yield from self.take(self.driver, self.drive_grasps[k + 1])
                yield from self.let_go(self.puller, holder=self.driver)
                yield from self.move_jp(p, park[self.puller], 0.8, settle=0.0)
                self.holder = self.driver
        self._set_phase("done")
