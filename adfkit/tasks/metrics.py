"""Metrics of a suture episode, like the challenge's: per hole pair whether the needle tip
passed its entry then its exit (through the hole ghosts, in order), the time of each phase,
the needle's final pose, the thread pulled through the tissue, the grasp's drift, the largest
constraint error, the real-time factor and whether anything exploded.

``SutureObserver.observe()`` is called once per control step after the world stepped; it
reads the world (ground truth) and the task's state, never commands anything.
"""

from __future__ import annotations

import math

import numpy as np

from ..runner.rotations import invert, matrix_to_quat
from .holes import (
    DEFAULT_HALF_OPENING,
    boundary_body,
    chain_crossing,
    opening_half_extents,
    plane_crossing,
    tip_leading,
    tissue_bodies,
)
from .verdicts import SLIP_LIMIT, SLIP_SETTLE_S, TIP_FORCE_N, pair_verdict

TOOL_TOUCH_N = 0.05  # N: a tool-tissue contact at least this strong is recorded as an event
SUSTAIN_STEPS = 5  # control steps (20 ms at 250 Hz) over which a touch's force is held (sustained_force_n)
NEAR_HOLE = 0.005  # m: a crossing of a hole's plane farther than this beside its opening is not an attempt at it
TIP_CONTACT = 0.002  # m: a contact this near the tip is the tip's
THREAD_TOLERANCE = 0.001  # m beyond a hole's opening a thread element's centre line may cross


def _name(sb) -> str:
    return sb.body.name or sb.body.identifier


def wire_radius(task) -> float:
    """The needle wire's radius, m, measured from its collision mesh (the 90th percentile of
    the vertices' distances from the fitted circle: the tip's taper does not count)."""
    from ..adf.paths import collision_mesh_path
    from .needle import obj_vertices

    b = task.needle.body
    path = collision_mesh_path(task.needle.model, b)
    if path is None or not path.is_file():
        return 0.0
    v = obj_vertices(path) * (b.scale or 1.0)
    a = invert(task.geom.arc_in_needle)
    p = v @ a[:3, :3].T + a[:3, 3]
    rho = np.hypot(np.hypot(p[:, 0], p[:, 1]) - task.geom.radius, p[:, 2])
    return float(np.percentile(rho, 90))


class _Hole:
    """One entry or exit hole watched by the observer: its frame is its boundary body's (the
    ghost is where the friction acts and must overlap the needle at the crossing)."""

    def __init__(self, world, pair: int, kind: str, name: str, ghost) -> None:
        self.pair, self.kind, self.name, self.ghost = pair, kind, name, ghost
        self.body = boundary_body(ghost)
        self.label = _name(self.body) if self.body is not None else name
        self.half = opening_half_extents(self.body.body) if self.body is not None else np.full(2, DEFAULT_HALF_OPENING)
        self.world = world
        owner = self.body if self.body is not None else ghost.parent
        self._static = owner is not None and owner.static
        self._inv = None
        self.prev_local = None
        self.crossings: list[dict] = []
        self.closest = math.inf  # m, the tip's nearest approach to the opening
        self.ghost_offset = 0.0
        if self.body is not None:
            g = invert(self.frame()) @ world.ghost_pose(ghost)
            self.ghost_offset = float(np.linalg.norm(g[:3, 3]))

    def frame(self) -> np.ndarray:
        return self.body.world_matrix() if self.body is not None else self.world.ghost_pose(self.ghost)

    def inverse_frame(self) -> np.ndarray:
        """The world-to-hole transform (read once where the hole cannot move: a static body)."""
        if self._inv is None or not self._static:
            self._inv = invert(self.frame())
        return self._inv


class SutureObserver:
    def __init__(self, task, error_every: int = 10, drift_every: int = 5) -> None:
        self.task, self.world = task, task.world
        self.error_every, self.drift_every = error_every, drift_every
        self.n = 0
        self.tip_path: list[list[float]] = []  # [t, x, y, z]
        self.max_constraint_error = 0.0
        self.error_by_phase: dict[str, float] = {}
        self.angle_by_phase: dict[str, float] = {}  # fixed joints' angle off their pose, rad
        self.max_drift = 0.0
        self.drift_samples = 0
        self.drift_by_phase: dict[str, float] = {}
        # the same while one arm alone holds it, from SLIP_SETTLE_S after the other let go (as slip)
        self.one_arm_drift_by_phase: dict[str, float] = {}
        self.slips: list[dict] = []  # phases where the needle slipped past SLIP_LIMIT
        self.thread = [
            sb
            for sb in self.world.bodies
            if sb.model is task.needle.model and "thread" in (sb.body.name or sb.body.identifier).lower()
        ]
        self.thread_by_pair: dict[int, dict] = {}
        self.holes = [_Hole(self.world, p.index, "entry", p.entry_name, p.entry) for p in task.pairs] + [
            _Hole(self.world, p.index, "exit", p.exit_name, p.exit) for p in task.pairs
        ]
        self.tissue = tissue_bodies(self.world, task.needle.model)
        self._tissue_ids = {id(sb) for sb in self.tissue}
        # the tools' links, watched for touches when they collide with the tissue
        self._tool = (
            {
                id(sb): n
                for n, psm in getattr(task, "psms", {}).items()
                for sb in self.world.bodies
                if sb.articulation is psm.art
            }
            if getattr(task, "tools_collide_with_tissue", False)
            else {}
        )
        self._tool_links = [sb for sb in self.world.bodies if id(sb) in self._tool]
        self.needle_contacts: dict[str, dict[str, float]] = {}  # phase -> {tissue body: max N}
        self.tip_contacts: dict[str, dict[str, float]] = {}  # the same, within TIP_CONTACT of the tip
        self.first_forced: dict[str, dict] = {}  # insert phase -> where the tip was first forced (_forced)
        self.tool_events: list[dict] = []
        self._open_touch: dict[tuple, dict] = {}
        self._recent: dict[tuple, list[float]] = {}  # the last SUSTAIN_STEPS forces of each touch (0: none)
        self._in_ghost: dict[str, bool] = {}
        self._last_phase = None
        self._slip_base = None
        g = task.geom
        self.tangent_in_needle = g.arc_in_needle[:3, :3] @ np.array([0.0, 1.0, 0.0])
        self._tip_h = np.r_[g.tip, 1.0]
        self.wire_radius = wire_radius(task)

    def _holders(self) -> int:
        return sum(1 for a in self.world.actuators if getattr(a, "target", None) is not None)

    def _watch_holes(self, t: float, tip: np.ndarray, needle_pose: np.ndarray) -> None:
        tangent = needle_pose[:3, :3] @ self.tangent_in_needle
        needle = self.task.needle
        tip_h = np.r_[tip, 1.0]
        for h in self.holes:
            inv = h.inverse_frame()
            local = (inv @ tip_h)[:3]
            in_ghost = needle in h.ghost.overlapping
            was_in = self._in_ghost.get(h.name, False)
            self._in_ghost[h.name] = in_ghost
            beyond = np.maximum(np.abs(local[:2]) - h.half, 0.0) if h.half is not None else np.zeros(2)
            h.closest = min(h.closest, float(math.hypot(float(np.linalg.norm(beyond)), float(local[2]))))
            prev, h.prev_local = h.prev_local, local
            if prev is None or h.half is None:
                continue
            hit = plane_crossing(prev, local, h.half)
            if hit is None:
                continue
            at, outside = hit
            if outside > NEAR_HOLE:  # the plane of another hole, far from this one
                continue
            h.crossings.append(
                {
                    "t": t,
                    "phase": self.task.phase,
                    "inward": bool(prev[2] > 0),
                    "at_mm": [float(v) * 1000 for v in at],
                    "outside_opening_m": outside,
                    "ghost_overlap": bool(in_ghost or was_in),
                    "tip_leading": tip_leading(inv[:3, :3] @ tangent, prev, local),
                }
            )

    def _forced(self, phase: str, t: float, body: str, force: float, tip) -> None:
        """Where the tip first pressed on the tissue hard enough to be forced (TIP_FORCE_N) in
        an insertion: how far from the pair's entry and exit openings, so that a verdict can
        tell a hole that stops the needle from a channel closed farther in."""
        k = int(phase.split()[1])
        near = {h.kind: float(np.linalg.norm(np.asarray(tip) - h.frame()[:3, 3])) for h in self.holes if h.pair == k}
        self.first_forced[phase] = {
            "t": t,
            "body": body,
            "force_n": float(force),
            "from_entry_m": near.get("entry", math.inf),
            "from_exit_m": near.get("exit", math.inf),
        }

    def _watch_contacts(self, t: float) -> None:
        phase = self.task.phase
        w = self.world
        tip = self.tip_path[-1][1:] if self.tip_path else None
        per_body: dict[str, float] = {}
        for other, f, at in w.contacts(self.task.needle):
            if id(other) in self._tissue_ids:
                n = _name(other)
                per_body[n] = per_body.get(n, 0.0) + f
                if tip is not None and f > 0 and math.dist(at, tip) < TIP_CONTACT:
                    d = self.tip_contacts.setdefault(phase, {})
                    d[n] = max(d.get(n, 0.0), f)
                    if f >= TIP_FORCE_N and phase.startswith("insert ") and phase not in self.first_forced:
                        self._forced(phase, t, n, f, tip)
        for n, f in per_body.items():
            d = self.needle_contacts.setdefault(phase, {})
            d[n] = max(d.get(n, 0.0), f)
        if not self._tool:
            return
        touching = set()
        per_touch: dict[tuple, float] = {}
        # asked of the tools (a query an arm), not of the tissue, which the thread lies on
        for link, other, f, _ in w.contacts_among(self._tool_links):
            if id(other) in self._tissue_ids:
                key = (self._tool[id(link)], _name(link), _name(other))
                per_touch[key] = per_touch.get(key, 0.0) + f
        for key, f in per_touch.items():
            if f < TOOL_TOUCH_N:
                continue
            touching.add(key)
            ev = self._open_touch.get(key)
            if ev is None:
                ev = self._open_touch[key] = {
                    "t_start": t,
                    "t_end": t,
                    "phase": phase,
                    "arm": key[0],
                    "link": key[1],
                    "tissue": key[2],
                    "max_force_n": f,
                    "sustained_force_n": 0.0,
                }
                self.tool_events.append(ev)
            ev["t_end"] = t
            ev["max_force_n"] = max(ev["max_force_n"], f)
            ev["sustained_force_n"] = max(ev["sustained_force_n"], self._held(key, f))
        for key in list(self._open_touch):
            if key not in touching:
                del self._open_touch[key]
        for key in list(self._recent):
            if key not in touching:
                self._held(key, 0.0)

    def _held(self, key: tuple, f: float) -> float:
        """The force a touch held over the last SUSTAIN_STEPS control steps: their mean, a step
        without the touch counting 0 (the window outlives a gap, so a tool chattering on the
        tissue is held), less the largest step: a rigid contact's one-step spike as a guarded
        tool stops is not the tool pressing on it (MuJoCo's rigid contacts: 780 N for one
        step where a guarded jaw touched the slab; PyBullet's: 15-60 N)."""
        recent = self._recent.setdefault(key, [])
        recent.append(f)
        del recent[:-SUSTAIN_STEPS]
        if not any(recent):
            del self._recent[key]
            return 0.0
        return (sum(recent) - max(recent)) / (SUSTAIN_STEPS - 1)

    def observe(self) -> None:
        t = self.world.sim_time
        needle_pose = self.task.needle_pose()  # read once a step: the holes, the tip and the drift use it
        tip = (needle_pose @ self._tip_h)[:3]
        self.tip_path.append([t, *map(float, tip)])
        phase = self.task.phase
        if self._last_phase is not None and phase != self._last_phase and self._last_phase.startswith("pull "):
            self._thread_at_end_of_pull(int(self._last_phase.split()[1]))
        self._last_phase = phase
        self._watch_holes(t, tip, needle_pose)
        self._watch_contacts(t)
        self.n += 1
        if self.n % self.error_every == 0:
            e = self.world.constraint_error()
            self.max_constraint_error = max(self.max_constraint_error, e)
            kind = phase.split()[0]
            self.error_by_phase[kind] = max(self.error_by_phase.get(kind, 0.0), e)
            angle = getattr(self.world, "joint_angle_error", None)  # PyBullet's fixed joints
            if angle is not None:
                self.angle_by_phase[kind] = max(self.angle_by_phase.get(kind, 0.0), angle())
        if self.n % self.drift_every == 0 and self.task.holder is not None and self.task.held_ee_in_needle is not None:
            psm = getattr(self.task, "psms", {})[self.task.holder]
            ee = psm.base_in_world() @ psm.measured_cp()
            expected = ee @ invert(self.task.held_ee_in_needle)
            offset = expected[:3, 3] - needle_pose[:3, 3]
            drift = float(np.linalg.norm(offset))
            self.max_drift = max(self.max_drift, drift)
            kind = phase.split()[0]
            self.drift_by_phase[kind] = max(self.drift_by_phase.get(kind, 0.0), drift)
            self.drift_samples += 1
            # slip: how far the needle sits from where this grasp took it, while one arm alone
            # holds it, once the grasp has settled after the other arm let go (while two hold,
            # the other arm's grasp strains this one; the strain relaxing is not a slip)
            holders = self._holders()
            key = (id(self.task.held_ee_in_needle), holders)
            if holders != 1:
                self._slip_base = None
            elif self._slip_base is None or self._slip_base[0] != key:
                self._slip_base = (key, t)
            settled = self._slip_base is not None and t - self._slip_base[1] >= SLIP_SETTLE_S
            slip = drift if settled else 0.0
            if settled:  # the drift while one arm alone holds it, its hand-over strain relaxed
                d = self.one_arm_drift_by_phase
                d[kind] = max(d.get(kind, 0.0), drift)
            if slip > SLIP_LIMIT and not any(s["phase"] == phase for s in self.slips):
                self.slips.append({"phase": phase, "t": t, "arm": self.task.holder, "slip_m": slip})
            for s in self.slips:
                if s["phase"] == phase:
                    s["slip_m"] = max(s["slip_m"], slip)

    def _thread_at_end_of_pull(self, k: int) -> None:
        """What of the thread is through pair k now that its pull ended: the chain (from the
        needle) crosses exit k and entry k inside their openings; the length on the needle's
        side of the entry is through (never more than the thread)."""
        if len(self.thread) < 2:
            return
        c = np.array([sb.com_position() for sb in self.thread])
        tail = (self.task.needle_pose() @ np.r_[self.task.geom.tail, 1.0])[:3]
        if np.linalg.norm(c[-1] - tail) < np.linalg.norm(c[0] - tail):
            c = c[::-1]
        c = np.vstack([tail, c])
        step = self.element_length()
        out = {}
        for h in self.holes:
            if h.pair != k or h.half is None:
                continue
            f = invert(h.frame())
            local = c @ f[:3, :3].T + f[:3, 3]
            i = chain_crossing(local, h.half, THREAD_TOLERANCE)
            out[h.kind] = None if i is None else i
        self.thread_by_pair[k] = {
            "t": self.world.sim_time,
            "through_entry": out.get("entry") is not None,
            "through_exit": out.get("exit") is not None,
            "length_m": min(len(self.thread), out["entry"] + 0.5) * step if out.get("entry") is not None else 0.0,
        }

    def element_length(self) -> float:
        if len(self.thread) < 2:
            return 0.0
        c = np.array([sb.com_position() for sb in self.thread])
        return float(np.median(np.linalg.norm(np.diff(c, axis=0), axis=1)))

    def pair_results(self, failure: str | None = None, failure_phase: str | None = None) -> list[dict]:
        return [pair_verdict(self, p, failure, failure_phase) for p in self.task.pairs]

    def phases(self) -> list[dict]:
        log = self.task.phase_log
        out = []
        for i, (name, t0) in enumerate(log):
            t1 = log[i + 1][1] if i + 1 < len(log) else self.world.sim_time
            out.append({"phase": name, "start_s": t0, "duration_s": t1 - t0})
        return out

    def finish(self) -> None:
        """The episode ended: a pull still under way ends here."""
        if self._last_phase and self._last_phase.startswith("pull "):
            k = int(self._last_phase.split()[1])
            if k not in self.thread_by_pair:
                self._thread_at_end_of_pull(k)

    def metrics(self, wall_s: float, failure: str | None = None) -> dict:
        self.finish()
        rep = self.world.report()
        n = self.task.needle_pose()
        pairs = self.pair_results(failure, self.task.phase if failure else None)
        through = min(
            max([d["length_m"] for d in self.thread_by_pair.values()], default=0.0),
            len(self.thread) * self.element_length(),
        )
        return {
            "pairs": pairs,
            "all_passed": (
                bool(pairs) and all(p["passed"] for p in pairs) and failure is None and not rep.get("instabilities")
            ),  # an engine that blew up passes nothing
            "thread_length_m": len(self.thread) * self.element_length(),
            "failure": failure,
            "phases": self.phases(),
            "needle_final_pose": {
                "position": [float(v) for v in n[:3, 3]],
                "orientation": [float(v) for v in matrix_to_quat(n[:3, :3])],
            },
            "thread_length_through_tissue_m": through,
            "grasp_drift_max_m": self.max_drift if self.drift_samples else None,
            "grasp_drift_by_phase_m": self.drift_by_phase,
            "grasp_drift_one_arm_by_phase_m": self.one_arm_drift_by_phase,
            "slip_limit_m": SLIP_LIMIT,
            "switched_off": list(getattr(self.task, "switched_off", [])),
            "slips": self.slips,
            "tool_tissue_events": self.tool_events,
            "needle_tissue_contact_n": self.needle_contacts,
            "tip_tissue_contact_n": self.tip_contacts,
            "tip_first_forced": self.first_forced,
            "constraint_error_by_phase_m": self.error_by_phase,
            "joint_angle_error_by_phase_deg": {k: float(np.degrees(a)) for k, a in self.angle_by_phase.items()},
            "needle_wire_radius_m": self.wire_radius,
            "max_constraint_error_m": max(self.max_constraint_error, rep["max_constraint_error_m"]),
            "simulated_time_s": self.world.sim_time,
            "physics_wall_time_s": self.world.wall_time,
            "episode_wall_time_s": wall_s,
            "real_time_factor": self.world.sim_time / wall_s if wall_s > 0 else None,
            "physics_real_time_factor": (self.world.sim_time / self.world.wall_time) if self.world.wall_time else None,
            "exploded": bool(rep["exploded"] or rep["nan"] or rep.get("instabilities")),
            "exploded_bodies": rep["exploded"]
            + rep["nan"]
            + [e["body"] for e in rep.get("instabilities", []) if e["body"]],
            "instabilities": rep.get("instabilities", []),  # runner/stability.py: time, body, kind, message
            "control_steps": self.n,
            "clipped_setpoints": self.task.clipped,
            "plan": self._plan(),
        }

    def _plan(self) -> list[dict]:
        """Per planned pair: how far the chosen grasps keep the tools off the tissue (by the
        planner's distance field) and how far beyond the exit the pull takes the tail."""
        t = self.task
        drive, pull = getattr(t, "drive_grasps", []), getattr(t, "pull_grasps", [])
        tails = getattr(t, "tail_clears", [])
        return [
            {
                "pair": p.index,
                "drive_clearance_m": finite(drive[k].clearance) if k < len(drive) else None,
                "pull_clearance_m": finite(pull[k].clearance) if k < len(pull) else None,
                "pull_tail_beyond_exit_deg": math.degrees(tails[k]) if k < len(tails) else None,
            }
            for k, p in enumerate(getattr(t, "pairs", []))
        ]


def finite(obj):
    """The metrics with every non-finite float replaced by None (strict JSON)."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite(v) for v in obj]
    if isinstance(obj, (np.floating, np.integer)):
        return finite(obj.item())
    return obj
