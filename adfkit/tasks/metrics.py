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
from .contact_forces import limit_scale
from .holes import (
    DEFAULT_HALF_OPENING,
    boundary_body,
    chain_crossing,
    hole_frame,
    opening_half_extents,
    plane_crossing,
    tip_leading,
)
from .needle import wire_radius
from .roles import task_roles
from .tissue_moved import TissueStart, said
from .verdicts import SLIP_LIMIT, SLIP_SETTLE_S, force_limits, pair_verdict, phase_pair

#: N: a needle's or thread's touch this strong at its peak is written in the metrics (times the
#: engine's limit scale, contact_forces.py, as the verdicts' limits: force_limits_n in the metrics)
NEEDLE_EVENT_N = 1.0
SUSTAIN_STEPS = 5  # control steps (20 ms at 250 Hz) over which a touch's force is held (sustained_force_n)
NEAR_HOLE = 0.005  # m: a crossing of a hole's plane farther than this beside its opening is not an attempt at it
TIP_CONTACT = 0.002  # m: a contact this near the tip is the tip's
THREAD_TOLERANCE = 0.001  # m beyond a hole's opening a thread element's centre line may cross


def _name(sb) -> str:
    return sb.body.name or sb.body.identifier


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
        return hole_frame(self.world, self.ghost)  # z out of the tissue, as the planner reads the hole

    def inverse_frame(self) -> np.ndarray:
        """The world-to-hole transform (read once where the hole cannot move: a static body)."""
        if self._inv is None or not self._static:
            self._inv = invert(self.frame())
        return self._inv


class SutureObserver:
    def __init__(self, task, error_every: int = 10, drift_every: int = 5) -> None:
        self.task, self.world = task, task.world
        self.error_every, self.drift_every = error_every, drift_every
        # the force limits in this engine's newtons (contact_forces.py), which the verdicts read here
        scale = limit_scale(self.world)
        self.force_limits = force_limits(scale)
        self.needle_event_n = NEEDLE_EVENT_N * scale
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
        self.roles = task_roles(task)
        self.thread = self.roles.thread  # in the chain's order from the needle
        self.thread_by_pair: dict[int, dict] = {}
        self.holes = [_Hole(self.world, p.index, "entry", p.entry_name, p.entry) for p in task.pairs] + [
            _Hole(self.world, p.index, "exit", p.exit_name, p.exit) for p in task.pairs
        ]
        self.tissue = self.roles.tissue
        self.tissue_start = TissueStart(self.tissue)  # where the tissue began (tissue_moved.py)
        # the tools' links, watched for touches when they collide with the tissue
        self._tool = (
            {id(sb): n for n, links in self.roles.robots.items() for sb in links}
            if getattr(task, "tools_collide_with_tissue", False)
            else {}
        )
        self._tool_links = [sb for sb in self.world.bodies if id(sb) in self._tool]
        self._whom = self._who()
        self.needle_contacts: dict[str, dict[str, float]] = {}  # phase -> {tissue body: max N}
        self.tip_contacts: dict[str, dict[str, float]] = {}  # the same, within TIP_CONTACT of the tip
        self.thread_contacts: dict[str, dict[str, float]] = {}  # the same for the thread (all its elements)
        self.tool_events: list[dict] = []
        self.needle_events: list[dict] = []  # the needle's (each part's) and the thread's touches
        self._open_touch: dict[tuple, dict] = {}
        self._recent: dict[tuple, list[float]] = {}  # the last SUSTAIN_STEPS forces of each touch (0: none)
        self._in_ghost: dict[str, bool] = {}
        self._last_phase = None
        self._slip_base = None
        g = task.geom
        self.tangent_in_needle = g.arc_in_needle[:3, :3] @ np.array([0.0, 1.0, 0.0])
        self._tip_h = np.r_[g.tip, 1.0]
        self._arc_inv = invert(g.arc_in_needle)
        self.wire_radius = wire_radius(task)
        # whether the engine built any of the scene's joints as a loop-closing constraint, whose
        # two ends can drift apart (PyBullet's thread); MuJoCo plays the thread and the arms as
        # trees of joints, exact by construction: nothing to measure there, and nothing is reported
        self.measures_constraints = bool(getattr(self.world, "constraints", None))

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

    def _who(self) -> dict[int, tuple]:
        """What touches the tissue, by body: ("needle", None), ("thread", element index, 1 the
        nearest the needle) or ("tool", arm) for the tools' links when they collide with it."""
        out: dict[int, tuple] = {id(self.task.needle): ("needle", None)}
        for i, sb in enumerate(self.thread):
            out[id(sb)] = ("thread", i + 1)
        for sb in self._tool_links:
            out[id(sb)] = ("tool", self._tool[id(sb)])
        return out

    def to_arc(self, needle_pose: np.ndarray) -> np.ndarray:
        """The world-to-arc-frame transform of the needle where it is."""
        return self._arc_inv @ invert(needle_pose)

    def needle_part(self, at, to_arc: np.ndarray) -> tuple[str, float]:
        """Which part of the needle a world point is on: "tip" or "tail" (within TIP_CONTACT of
        that end along the wire) or "body", and how far from the tip along the wire, m.
        ``to_arc``: the world-to-arc-frame transform (to_arc)."""
        g = self.task.geom
        x, y = to_arc[0, :3] @ at + to_arc[0, 3], to_arc[1, :3] @ at + to_arc[1, 3]
        s = -math.atan2(y, x) * g.radius  # 0 at the tip, growing toward the tail
        if s < TIP_CONTACT:
            return "tip", max(s, 0.0)
        if s > g.span * g.radius - TIP_CONTACT:
            return "tail", s
        return "body", s

    def place(self, at, phase: str) -> dict:
        """Where a contact point lies for a reason: its pair (from the phase), how far past the
        pair's entry along the needle's planned arc (m, negative before it), how far before the
        exit, and how far off the arc; the point itself."""
        out: dict = {"point_m": [float(v) for v in at]}
        k = phase_pair(phase, self.task)
        frames = getattr(self.task, "frames", {})
        if k is None:
            return out
        out["pair"] = k
        if k in frames:
            b, psi_x = frames[k][0], frames[k][1]
            q = invert(b) @ np.array([at[0], at[1], at[2], 1.0])
            r = self.task.geom.radius
            psi = math.atan2(q[1], q[0])
            out["past_entry_m"] = r * psi
            out["before_exit_m"] = r * (psi_x - psi)
            out["off_arc_m"] = float(math.hypot(math.hypot(q[0], q[1]) - r, q[2]))
        return out

    def _watch_contacts(self, t: float, needle_pose: np.ndarray) -> None:
        """Every contact of the needle, the thread and (when they collide with it) the tools
        with every tissue body after this step: the per-phase largest forces, and the touches
        as events with the force they held (see _touch)."""
        phase = self.task.phase
        to_arc = None
        per_touch: dict[tuple, list] = {}  # key -> [summed force, strongest contact's force, its point, element]
        needle_per_body: dict[str, float] = {}
        for tb, other, f, at in self.world.contacts_among(self.tissue):
            who = self._whom.get(id(other))
            if who is None:
                continue
            kind, what = who
            n = _name(tb)
            if kind == "tool":
                key: tuple = ("tool", what, _name(other), n)
            elif kind == "needle":
                if to_arc is None:
                    to_arc = self.to_arc(needle_pose)
                part, _ = self.needle_part(at, to_arc)
                key = ("needle", part, n)
                needle_per_body[n] = needle_per_body.get(n, 0.0) + f
            else:
                key = ("thread", None, n)
            acc = per_touch.setdefault(key, [0.0, -1.0, None, None])
            acc[0] += f
            if f > acc[1]:
                acc[1], acc[2], acc[3] = f, at, what
        for n, f in needle_per_body.items():
            d = self.needle_contacts.setdefault(phase, {})
            d[n] = max(d.get(n, 0.0), f)
        for (kind, part, n), (f, _, _, _) in ((k, v) for k, v in per_touch.items() if k[0] != "tool"):
            if kind == "needle" and part == "tip":
                d = self.tip_contacts.setdefault(phase, {})
                d[n] = max(d.get(n, 0.0), f)
            elif kind == "thread":
                d = self.thread_contacts.setdefault(phase, {})
                d[n] = max(d.get(n, 0.0), f)
        touching = set()
        touch = self.force_limits["touch_n"]
        for key, (f, _, at, what) in per_touch.items():
            if f < touch:
                continue
            touching.add(key)
            self._touch(key, t, phase, f, at, what, needle_pose)
        for key in list(self._open_touch):
            if key not in touching:
                del self._open_touch[key]
        for key in list(self._recent):
            if key not in touching:
                self._held(key, 0.0)

    def _touch(self, key: tuple, t: float, phase: str, f: float, at, what, needle_pose: np.ndarray) -> None:
        """One control step of a touch: its event opened or carried on, its largest and held
        force, and, the first time the force held reaches its limit (TOOL_HIT_N for a tool,
        FORCED_N for the needle, THREAD_FORCED_N for the thread), when, in which phase, where
        and how hard."""
        ev = self._open_touch.get(key)
        if ev is None:
            ev = self._open_touch[key] = {"t_start": t, "t_end": t, "phase": phase}
            if key[0] == "tool":
                ev.update(arm=key[1], link=key[2], tissue=key[3])
                self.tool_events.append(ev)
            else:
                ev.update(part=key[1] or "thread", tissue=key[2])
                self.needle_events.append(ev)
            ev.update(max_force_n=f, sustained_force_n=0.0)
        ev["t_end"] = t
        if f >= ev["max_force_n"] or "at_peak" not in ev:
            ev["max_force_n"] = max(ev["max_force_n"], f)
            if key[0] != "tool":
                ev["at_peak"] = self._where(key, phase, at, what, needle_pose)
        held = self._held(key, f)
        ev["sustained_force_n"] = max(ev["sustained_force_n"], held)
        lim = self.force_limits
        limit = {"tool": lim["tool_hit_n"], "thread": lim["thread_forced_n"]}.get(key[0], lim["forced_n"])
        if limit is not None and held >= limit and "over_limit" not in ev:
            ev["over_limit"] = {"t": t, "phase": phase, "force_n": held}
            if key[0] != "tool":
                ev["over_limit"].update(self._where(key, phase, at, what, needle_pose))
                tip = (needle_pose @ self._tip_h)[:3]
                ev["over_limit"]["tip"] = {k: v for k, v in self.place(tip, phase).items() if k != "point_m"}

    def _where(self, key: tuple, phase: str, at, what, needle_pose: np.ndarray) -> dict:
        out = self.place(at, phase)
        if key[0] == "needle":
            out["from_tip_m"] = self.needle_part(at, self.to_arc(needle_pose))[1]
        elif what is not None:
            out["element"] = what
        return out

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
        self._watch_contacts(t, needle_pose)
        self.n += 1
        if self.n % self.error_every == 0 and self.measures_constraints:
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
        moved = self.tissue_start.moved()
        for p in pairs:
            if any(d["free"] for d in moved) and not p["passed"] and p.get("reason"):
                p["reason"] += f"; the tissue moved during the run ({said(moved)})"
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
            # the force limits the touches were recorded and judged by, in this engine's newtons
            "force_limits_n": {**self.force_limits, "needle_event_n": self.needle_event_n},
            "switched_off": list(getattr(self.task, "switched_off", [])),
            "tissue_moved": moved,
            "slips": self.slips,
            "tool_tissue_events": self.tool_events,
            "needle_tissue_contact_n": self.needle_contacts,
            "tip_tissue_contact_n": self.tip_contacts,
            "thread_tissue_contact_n": self.thread_contacts,
            # the needle's and the thread's touches of needle_event_n or more (lighter ones: lying on the tissue)
            "needle_tissue_events": [e for e in self.needle_events if e["max_force_n"] >= self.needle_event_n],
            "joint_angle_error_by_phase_deg": {k: float(np.degrees(a)) for k, a in self.angle_by_phase.items()},
            "needle_wire_radius_m": self.wire_radius,
            # what the check of the needle's swept arc before the run found, per pair (sweep.py)
            "swept_arc_check": {str(k): v for k, v in getattr(self.task, "sweep", {}).items()},
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
            **self._constraint_errors(rep),
            "control_steps": self.n,
            "clipped_setpoints": self.task.clipped,
            "reaimed_takes": self.task.reaimed,
            "plan": self._plan(),
        }

    def _constraint_errors(self, rep: dict) -> dict:
        """The joints' constraint error where the engine has loop-closing constraints to measure;
        else no figure, and a note that says why."""
        if self.measures_constraints:
            return {
                "constraint_error_by_phase_m": self.error_by_phase,
                "max_constraint_error_m": max(self.max_constraint_error, rep["max_constraint_error_m"]),
            }
        return {
            "max_constraint_error_m": None,
            "constraint_error_note": (
                f"not measured: the {self.world.engine or 'engine'} world built none of the scene's joints as a "
                "loop-closing constraint (its joints form trees, exact by construction)"
            ),
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
