"""The suture replayed in AMBF (``adfkit parity --suture``): adfkit's scripted suture is played
and recorded (every PSM joint set-point it gives, each grasp and release, the push that settles
the needle, where the setup puts the arms, the body pairs it lets pass through each other), the
recording is replayed in AMBF through adfkit's plugin (the set-points as AMBF's joint position
commands, the grasps through AMBF's own constraint actuators), and the needle's path on each
side is judged by the same verdict code (``tasks.verdicts.pair_verdict``).

The set-points are played at AMBF's own time, where its joint controller (P 10, D 1 into a
velocity motor by default) trails a moving set-point by about a tenth of a second; or paced
(``PACE``), as a client that sends a set-point and waits for the measured joints: the plugin
reads the recording on a command clock that advances only while every driven joint stands within
a tolerance of its set-point, physics running all the while, and the paths are compared by that
clock.

Or the arms follow the path adfkit's arms took (``follow="measured"``): the recording also holds
every PSM joint's measured position each control step (``follow`` lines), and the plugin, each
1 ms step, gives each such joint AMBF's velocity command of that path's slope plus a gain times
the path less AMBF's measured joint, as a client servoing the measured joint state would; its
set-points are then left unplayed (grasps, releases and the push are played as recorded).

AMBF's side is judged from the poses the plugin records: the tip's crossings of each hole's
plane (inside its opening, tip first), the thread through both holes when each pull ended, the
needle slipping in a grasp. The plugin records no contact force, so the rules that read forces
(a tool pressing on the tissue, a tip forced through) are judged on adfkit's side only."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..diagnostics import AdfError, error
from ..model.semantics import JointKind, joint_kind
from ..runner.rotations import invert, matrix_to_pq, pose_matrix
from . import ambf
from .traces import ambf_name, joint_key

#: a sample of AMBF's poses every so many simulated seconds (the tip's path, the crossings)
EVERY = 0.02


@dataclass(frozen=True)
class Pace:
    """A paced replay's rule: the command clock waits while a driven joint stands farther than
    ``rad`` (revolute) or ``m`` (prismatic) from its set-point, for ``wait_s`` of AMBF's time at
    most (a jaw closed on the needle never gets there); the replay ends at ``max_factor`` times
    the recording's length of AMBF's time if its clock has not reached the end by then."""

    rad: float = 0.01
    m: float = 0.001
    wait_s: float = 0.1
    max_factor: float = 20.0

    def plugin(self) -> tuple[float, float, float]:
        return (self.rad, self.m, self.wait_s)


PACE = Pace()

#: how a replay drives AMBF's PSM joints: the set-points adfkit's planner gave (AMBF's position
#: commands), or the path adfkit's joints took, followed on AMBF's measured joints
FOLLOWS = ("commands", "measured")

#: the follow's feedback gain (1/s): each 1 ms step a followed joint is commanded the path's
#: slope plus this times the path less its measured position, the velocity that brings it onto
#: the path within the step (measured on the corpus suture's first 30 s: the tip paths 1.8 mm
#: apart at most through insert 1 at 1000/s, 3.4 mm at 500/s, 3.5 mm at 300/s)
FOLLOW_GAIN = 1000.0

#: where a replay's grasps hold the needle in AMBF's jaws: ``lies``, where AMBF's needle lies when
#: the jaws take it (``afConstraintActuator::actuate(body)``, as the challenge's scene grasps);
#: ``adfkit``, where adfkit's grasp held it (the recording's needle frame in the tool's, given to
#: AMBF's constraint actuator as its offset, ``actuate(body, offset)``). Measured on the bundled
#: suture (seed 0, following): taken where it lies, each grasp keeps what AMBF's needle turned in
#: the other jaws before, and the needle-in-jaws offset grows grasp by grasp (0.6 mm and 4.6° at
#: the pick-up, 5.7 mm and 17° at hand back 3; the tips 4.8, 7.0, 7.2 and 6.7 mm apart at most per
#: pair); held where adfkit's was, within 0.5 mm and 1° 0.1 s after every grasp (3.9, 4.0, 4.3 and
#: 4.1 mm)
GRASPS = ("lies", "adfkit")


@dataclass
class Recording:
    """What adfkit's suture did, as commands AMBF's plugin follows, and what it judged."""

    commands: list[ambf.Command]
    seconds: float
    phase_log: list[tuple[str, float]]
    tip_path: np.ndarray  # (n, 4): t, x, y, z
    verdicts: list[dict]
    task: object  # the adfkit task (its pairs, needle geometry): what the verdict code reads
    holes: list[dict]  # per hole: pair, kind, body (AMBF name), half, label, ghost, ghost_offset
    needle: str  # the needle's AMBF name
    thread: list[str]  # the thread elements' AMBF names, from the needle on
    grasps: list[tuple[float, str, str | None]] = field(default_factory=list)  # (t, arm, body or None)
    tools: dict[str, str] = field(default_factory=dict)  # arm -> the AMBF name of the body its actuator is on
    wall_s: float = 0.0
    options: dict = field(default_factory=dict)  # the Options adfkit's suture was recorded under (RECORD_OPTIONS)
    prismatic: frozenset[str] = frozenset()  # the PSM joints (AMBF names) whose values are lengths, not angles

    def commands_for(self, follow: str, grasp: str = "lies") -> list[ambf.Command]:
        """The commands a replay plays: ``commands``, the set-points (no ``follow`` lines);
        ``measured``, the measured paths instead of the set-points of the joints they cover; each
        grasp holding the needle where adfkit's held it, or (``grasp="lies"``) where it lies."""
        if grasp not in GRASPS:
            raise ValueError(f"grasp is one of {GRASPS}, not {grasp!r}")
        cmds = self.commands
        if grasp == "lies":
            cmds = [replace(c, numbers=()) if c.kind == "grasp" else c for c in cmds]
        followed = {c.target for c in cmds if c.kind == "follow"}
        if follow == "commands":
            return [c for c in cmds if c.kind != "follow"]
        if follow != "measured":
            raise ValueError(f"follow is one of {FOLLOWS}, not {follow!r}")
        if not followed:
            raise ValueError("the recording holds no measured joint paths (record it with measured=True)")
        return [c for c in cmds if not (c.kind == "position" and c.target in followed)]

    def measured_paths(self) -> dict[str, np.ndarray]:
        """Each PSM joint's measured path in adfkit, (n, 2): time, position."""
        out: dict[str, list] = {}
        for c in self.commands:
            if c.kind == "follow":
                out.setdefault(c.target, []).append((c.t, c.value))
        return {k: np.array(v, float) for k, v in out.items()}


class _Recorder:
    """Wraps a world's step, actuate, release and set_collision and the needle's force, and
    writes them down as plugin commands: joint set-points when they change, grasps, releases,
    the pairs let pass through each other, forces; with ``measured``, each PSM joint's measured
    position every control step too (``follow`` lines)."""

    def __init__(self, world, task, measured: bool = False) -> None:
        self.world, self.task, self.measured = world, task, measured
        self.commands: list[ambf.Command] = []
        self.grasps: list[tuple[float, str, str | None]] = []
        self.arms = {id(psm.art): name for name, psm in task.psms.items()}
        self.joint_names = {}
        self.prismatic: set[str] = set()
        for j, _p, child in world.joints_made:
            art = getattr(child, "articulation", None)
            if art is None or id(art) not in self.arms:
                continue
            idx = next((i for i, r in enumerate(art.records) if r[0] is j), None)
            if idx is not None:
                name = ambf_name(joint_key(world, j), j)
                self.joint_names[(id(art), idx)] = name
                if joint_kind(j.type) is JointKind.PRISMATIC:
                    self.prismatic.add(name)
        self.last: dict[tuple, float] = {}
        self.placed = False
        self.forced = False
        self._force_now = None
        step, actuate, release, set_collision = world.step, world.actuate, world.release, world.set_collision
        needle = task.needle
        force = needle.force

        def rec_step(n: int = 1) -> None:
            for _ in range(n):
                self._before_step()
                step(1)

        def rec_actuate(act, body) -> None:
            actuate(act, body)
            arm = self._arm_of(act)
            # where the grasp holds the body: its frame in the actuator's parent's (GRASPS)
            p, q = matrix_to_pq(invert(act.parent.world_matrix()) @ body.world_matrix())
            self.commands.append(ambf.Command(world.sim_time, "grasp", _name(act), body=_name(body), numbers=(*p, *q)))
            self.grasps.append((world.sim_time, arm, _name(body)))

        def rec_release(act) -> None:
            held = getattr(act, "target", None) is not None or getattr(act, "constraint", None) is not None
            release(act)
            if held:
                self.commands.append(ambf.Command(world.sim_time, "release", _name(act)))
                self.grasps.append((world.sim_time, self._arm_of(act), None))

        def rec_force(f, at) -> None:
            force(f, at)
            self._force_now = (tuple(map(float, f)), tuple(map(float, at)))

        def rec_set_collision(a, b, enabled: bool) -> None:
            # the task's own choice (the two arms' links pass through each other): AMBF is told
            # the same, or its arms push each other off their set-points
            set_collision(a, b, enabled)
            self.commands.append(ambf.Command(world.sim_time, "collide", _name(a), float(enabled), body=_name(b)))

        world.step, world.actuate, world.release = rec_step, rec_actuate, rec_release
        world.set_collision = rec_set_collision
        needle.force = rec_force

    def _arm_of(self, act) -> str:
        art = getattr(act.parent, "articulation", None)
        return self.arms.get(id(art), "") if art is not None else ""

    def _before_step(self) -> None:
        w, t = self.world, self.world.sim_time
        if not self.placed:  # the arms where adfkit's setup put them (their bases slid, jaws open)
            self.placed = True
            for psm in self.task.psms.values():
                for sb in w.bodies:
                    if sb.articulation is psm.art:
                        p, q = matrix_to_pq(sb.world_matrix())
                        self.commands.append(ambf.Command(t, "place", _name(sb), numbers=(*p, *q)))
        for psm in self.task.psms.values():
            art = psm.art
            for i, v in enumerate(art.targets):
                key = (id(art), i)
                name = self.joint_names.get(key)
                if name is not None and self.last.get(key) != v:
                    self.last[key] = v
                    self.commands.append(ambf.Command(t, "position", name, float(v)))
            if self.measured:
                for i, q in enumerate(art.joint_values()):
                    name = self.joint_names.get((id(art), i))
                    if name is not None:
                        self.commands.append(ambf.Command(t, "follow", name, float(q)))
        needle = _name(self.task.needle)
        if self._force_now is not None:
            f, at = self._force_now
            self.commands.append(ambf.Command(t, "force", needle, numbers=(*f, *at)))
            self.forced, self._force_now = True, None
        elif self.forced:
            at = tuple(map(float, self.task.needle.com_position()))
            self.commands.append(ambf.Command(t, "force", needle, numbers=(0.0, 0.0, 0.0, *at)))
            self.forced = False


def _name(obj) -> str:
    """An adfkit world object's AMBF name (a body, an actuator)."""
    inner = getattr(obj, "body", None) or getattr(obj, "actuator", None)
    return ambf_name(obj.key, inner)


#: the Options a recording may be made under (``record``'s ``options``); what it is not given is the
#: suture's own (``Options()``'s, which ``adfkit suture`` plays and was accepted on)
RECORD_OPTIONS = ("springs", "bodies", "ghosts", "link_shapes", "control_substeps")


def record_options(options: dict | None = None):
    """The runner's Options a suture is recorded under: the suture's own (``adfkit suture``'s:
    50 solver iterations, the rest ``Options()``'s), with ``options`` (keys of ``RECORD_OPTIONS``,
    None values left out) in their place."""
    from ..runner import Options
    from ..tasks.episode import SOLVER_ITERATIONS

    given = {k: v for k, v in (options or {}).items() if v is not None}
    unknown = sorted(set(given) - set(RECORD_OPTIONS))
    if unknown:
        raise ValueError(f"a suture is recorded under {', '.join(RECORD_OPTIONS)}, not {', '.join(unknown)}")
    return Options(renderer="tiny", visuals=False, solver_iterations=SOLVER_ITERATIONS, **given)


def recording_world(launch: Path, indices, options: dict | None = None):
    """The PyBullet world a suture is recorded in: the scene under ``record_options(options)``."""
    from ..adf import load_scene
    from ..runner import open_world

    return open_world(load_scene(Path(launch), indices), record_options(options))


def record(
    launch: Path,
    indices,
    pairs,
    seed: int = 0,
    progress: bool = False,
    measured: bool = False,
    options: dict | None = None,
) -> Recording:
    """Play adfkit's scripted suture (PyBullet) and record it for AMBF (with ``measured``, its
    PSM joints' measured paths too), under the suture's own Options or, where ``options`` names
    them, those (``record_options``)."""
    import time

    from ..tasks.episode import play_task
    from ..tasks.suture import SutureError, SutureTask

    world = recording_world(launch, indices, options)
    try:
        try:
            task = SutureTask(world, list(pairs), seed=seed)
        except (SutureError, KeyError, ValueError) as exc:  # as `adfkit suture` says it
            raise AdfError(
                error(
                    "suture-setup",
                    str(exc).strip('"'),
                    None,
                    "the scene needs a Needle, Entry k/Exit k hole ghosts and two PSMs",
                )
            ) from None
        rec = _Recorder(world, task, measured)
        t0 = time.perf_counter()
        try:
            metrics, obs, _ = play_task(world, task, None, gif=False, progress=progress)
        except SutureError as exc:  # play_task records a planner's failure itself; this is setup's
            raise RuntimeError(f"the suture could not start: {exc}") from None
        wall = time.perf_counter() - t0
        holes = [
            {
                "pair": h.pair,
                "kind": h.kind,
                "body": _name(h.body) if h.body is not None else None,
                "half": None if h.half is None else np.asarray(h.half, float),
                "label": h.label,
                "name": h.name,
                "ghost": h.ghost,
                "ghost_offset": h.ghost_offset,
            }
            for h in obs.holes
        ]
        thread = [_name(sb) for sb in obs.thread]
        tools = {}
        for a in world.actuators:
            arm = rec._arm_of(a)
            if arm:
                tools[arm] = _name(a.parent)
        return Recording(
            rec.commands,
            world.sim_time,
            list(task.phase_log),
            np.array(obs.tip_path, float),
            metrics["pairs"],
            task,
            holes,
            _name(task.needle),
            thread,
            grasps=rec.grasps,
            tools=tools,
            wall_s=wall,
            options={k: getattr(world.opt, k) for k in RECORD_OPTIONS},
            prismatic=frozenset(rec.prismatic),
        )
    finally:
        world.close()


class _Hole:
    """One hole as the verdict code reads it, its frame from AMBF's poses."""

    def __init__(self, d: dict) -> None:
        self.pair, self.kind, self.name, self.label = d["pair"], d["kind"], d["name"], d["label"]
        self.half, self.ghost, self.ghost_offset = d["half"], d["ghost"], d["ghost_offset"]
        self.body = d["body"]
        self.crossings: list[dict] = []
        self.closest = math.inf


class AmbfObservation:
    """What ``tasks.verdicts.pair_verdict`` reads, from AMBF's recorded poses."""

    def __init__(self, rec: Recording, trace, grasp: str = "lies") -> None:
        from ..tasks.holes import plane_crossing, tip_leading
        from ..tasks.metrics import NEAR_HOLE

        self.task = rec.task
        self.holes = [_Hole(d) for d in rec.holes]
        self.thread_by_pair: dict[int, dict] = {}
        self.slips: list[dict] = []
        self.tool_events: list[dict] = []  # no contact forces recorded in AMBF
        self.needle_contacts: dict = {}
        self.tip_contacts: dict = {}
        self.first_forced: dict = {}
        geom = rec.task.geom
        self.wire_radius = 0.0
        names = trace.body_names
        idx = {n: i for i, n in enumerate(names)}
        # judged up to where AMBF's world blew up, if it did (its poses not finite from there on)
        n_ok = finite_samples(trace)
        # a paced replay's events happened on its command clock: the recording's own time
        self.times = (trace.clock if trace.clock is not None else trace.times)[:n_ok]
        frames = _frames(trace.poses[:n_ok])
        needle = frames[:, idx[rec.needle]]
        tip = needle @ np.r_[geom.tip, 1.0]
        self.tip_path = np.column_stack([self.times, tip[:, :3]])
        tangent_in_needle = geom.arc_in_needle[:3, :3] @ np.array([0.0, 1.0, 0.0])
        phase_at = _phases(rec.phase_log)
        for h in self.holes:
            hf = frames[:, idx[h.body]] if h.body in idx else None
            if hf is None or h.half is None or not n_ok:
                continue
            inv = np.linalg.inv(hf)
            local = np.einsum("nij,nj->ni", inv, tip)[:, :3]
            beyond = np.maximum(np.abs(local[:, :2]) - h.half, 0.0)
            h.closest = float(np.min(np.hypot(np.linalg.norm(beyond, axis=1), local[:, 2])))
            for k in range(1, len(local)):
                hit = plane_crossing(local[k - 1], local[k], h.half)
                if hit is None or hit[1] > NEAR_HOLE:
                    continue
                at, outside = hit
                tangent = inv[k, :3, :3] @ (needle[k, :3, :3] @ tangent_in_needle)
                h.crossings.append(
                    {
                        "t": float(self.times[k]),
                        "phase": phase_at(self.times[k]),
                        "inward": bool(local[k - 1][2] > 0),
                        "at_mm": [float(v) * 1000 for v in at],
                        "outside_opening_m": outside,
                        # the holes' ghosts sit on their openings: a crossing inside an opening
                        # goes through its ghost (the plugin records where ghosts are, not what
                        # they hold)
                        "ghost_overlap": outside <= 0.0,
                        "tip_leading": tip_leading(tangent, local[k - 1], local[k]),
                    }
                )
        self._thread(rec, frames, idx, needle, geom)
        self._slips(rec, frames, idx, needle, phase_at, grasp)

    def _thread(self, rec, frames, idx, needle, geom) -> None:
        """Through each pair's holes when its pull ended, as the observer judges it."""
        from ..tasks.holes import chain_crossing
        from ..tasks.metrics import THREAD_TOLERANCE

        ends = {}
        for (name, _start), nxt in zip(rec.phase_log, rec.phase_log[1:] + [("end", rec.seconds)]):
            if name.startswith("pull "):
                ends[int(name.split()[1])] = nxt[1]
        elements = [idx[n] for n in rec.thread if n in idx]
        if len(elements) < 2 or not len(self.times):
            return
        for k, t_end in ends.items():
            s = min(int(np.searchsorted(self.times, t_end)), len(self.times) - 1)
            c = frames[s, elements, :3, 3]
            tail = (needle[s] @ np.r_[geom.tail, 1.0])[:3]
            if np.linalg.norm(c[-1] - tail) < np.linalg.norm(c[0] - tail):
                c = c[::-1]
            c = np.vstack([tail, c])
            step = float(np.median(np.linalg.norm(np.diff(c[1:], axis=0), axis=1)))
            out = {}
            for h in self.holes:
                if h.pair != k or h.half is None or h.body not in idx:
                    continue
                f = np.linalg.inv(frames[s, idx[h.body]])
                local = c @ f[:3, :3].T + f[:3, 3]
                out[h.kind] = chain_crossing(local, h.half, THREAD_TOLERANCE)
            self.thread_by_pair[k] = {
                "t": float(self.times[s]),
                "through_entry": out.get("entry") is not None,
                "through_exit": out.get("exit") is not None,
                "length_m": min(len(elements), out["entry"] + 0.5) * step if out.get("entry") is not None else 0.0,
            }

    def _slips(self, rec, frames, idx, needle, phase_at, grasp: str = "lies") -> None:
        """The needle moving in a grasp, while one arm alone holds it, once that grasp has
        settled after the other arm let go (the observer's slip), from where the grasp took it:
        where the needle lay in the jaws at the grasp (``grasp="lies"``), or, where the grasp
        was given where to hold it (``"adfkit"``: AMBF's constraint pulls the needle there from
        where it lay), SLIP_SETTLE_S after the grasp."""
        from ..tasks.verdicts import SLIP_LIMIT, SLIP_SETTLE_S

        holding: dict[str, np.ndarray] = {}  # arm -> the needle in its tool where the grasp took it
        events = sorted(rec.grasps)
        e = 0
        alone_since = None
        for s, t in enumerate(self.times):
            changed = False
            while e < len(events) and events[e][0] <= t + 1e-9:
                _, arm, body = events[e]
                tool = rec.tools.get(arm)
                if body is None:
                    holding.pop(arm, None)
                elif tool in idx:
                    took = s
                    if grasp == "adfkit":
                        took = min(int(np.searchsorted(self.times, events[e][0] + SLIP_SETTLE_S)), len(self.times) - 1)
                    holding[arm] = invert(frames[took, idx[tool]]) @ needle[took]
                e += 1
                changed = True
            if len(holding) != 1:
                alone_since = None
                continue
            if changed or alone_since is None:
                alone_since = t
            if t - alone_since < SLIP_SETTLE_S:
                continue
            arm, rel = next(iter(holding.items()))
            expected = frames[s, idx[rec.tools[arm]]] @ rel
            slip = float(np.linalg.norm(expected[:3, 3] - needle[s, :3, 3]))
            phase = phase_at(t)
            if slip > SLIP_LIMIT and not any(x["phase"] == phase for x in self.slips):
                self.slips.append({"phase": phase, "t": float(t), "arm": arm, "slip_m": slip})


#: a body farther than this from the world's origin (m) is in a world that blew up: the last
#: samples before Bullet's NaN are finite but far off (a needle at 8.6e9 m)
BLOWN_UP_M = 1000.0


def finite_samples(trace) -> int:
    """How many of the trace's samples come before the first pose that is not finite or is
    ``BLOWN_UP_M`` away (a world that blew up: Bullet's NaN spreads to every body it touches,
    and the steps before it fling them)."""
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(trace.poses).all(axis=(1, 2)) & (np.abs(trace.poses[..., :3]) < BLOWN_UP_M).all(axis=(1, 2))
    return len(ok) if ok.all() else int(np.argmin(ok))


def _frames(poses: np.ndarray) -> np.ndarray:
    """(S, B, 4, 4) world matrices from (S, B, 7) positions and quaternions."""
    s, b = poses.shape[:2]
    out = np.array([pose_matrix(p[:3], p[3:]) for p in poses.reshape(-1, 7)]).reshape(-1, 4, 4)
    return out.reshape(s, b, 4, 4)


def _phases(log: list[tuple[str, float]]):
    """The phase adfkit's task was in at a time."""
    starts = np.array([t for _, t in log]) if log else np.zeros(0)

    def at(t: float) -> str:
        i = int(np.searchsorted(starts, t + 1e-9, side="right")) - 1
        return log[i][0] if i >= 0 else "start"

    return at


def tip_gaps(adfkit_tip: np.ndarray, ambf_tip: np.ndarray, log, pairs) -> dict[int, float]:
    """The largest distance between the two tips over each pair's phases (m), adfkit's path
    taken at AMBF's sample times."""
    phase_at = _phases(log)
    from ..tasks.verdicts import in_pair

    out: dict[int, float] = {}
    t = ambf_tip[:, 0]
    mine = np.column_stack([np.interp(t, adfkit_tip[:, 0], adfkit_tip[:, i]) for i in (1, 2, 3)])
    d = np.linalg.norm(mine - ambf_tip[:, 1:], axis=1)
    for n, p in enumerate(pairs):
        mask = np.array([in_pair(phase_at(x), p.index, n == 0) for x in t])
        out[p.index] = float(d[mask].max()) if mask.any() else math.nan
    return out


@dataclass
class Replay:
    """The recording played in AMBF, judged."""

    verdicts: list[dict]
    gaps: dict[int, float]  # the tip paths' largest distance per pair (m), by the command clock
    trace: object
    pace: Pace | None
    end: dict  # the plugin's end record: simulated time, the clock, the pace's figures
    follow: str = "commands"
    tracking: dict = field(default_factory=dict)  # joint -> how far AMBF's stood from adfkit's measured path
    grasp: str = "lies"  # where its grasps held the needle (GRASPS)

    @property
    def label(self) -> str:
        """How it was played: ``measured`` (following adfkit's measured joints), ``paced`` or
        ``unpaced`` (the set-points)."""
        return "measured" if self.follow == "measured" else ("paced" if self.pace is not None else "unpaced")

    def json(self) -> dict:
        return {
            "follow": self.follow,
            "follow_gain": FOLLOW_GAIN if self.follow == "measured" else None,
            "grasp": self.grasp,
            "paced": self.pace is not None,
            "pace": self.pace_json(),
            "ambf_not_finite_from_s": _blew_up(self.trace),
            "wall_s": self.trace.wall_s,
            "verdicts": [x["verdict"] for x in self.verdicts],
            "tip_path_gap_m": {str(k): v for k, v in self.gaps.items()},
            "tracking": self.tracking,
        }

    def pace_json(self) -> dict | None:
        if self.pace is None:
            return None
        got = self.end.get("pace") or {}
        return {
            "tolerance_rad": self.pace.rad,
            "tolerance_m": self.pace.m,
            "wait_s": self.pace.wait_s,
            "ambf_simulated_s": self.end.get("t"),
            "held_steps": got.get("held_steps"),
            "give_ups": got.get("give_ups"),
            "given_up_on": got.get("given_up_on", {}),
            "clock_reached_end": got.get("clock_reached"),
        }


def tracking(rec: Recording, trace) -> dict:
    """How far each PSM joint in AMBF stood from the path adfkit's took, at AMBF's samples (by
    the command clock) after the path's first point (the sample there comes before any command)
    and up to its last: ``{joint: {"median": .., "max": ..}}`` (rad or m; empty where the
    recording holds no measured paths)."""
    clock = trace.clock if trace.clock is not None else trace.times
    n_ok = finite_samples(trace)
    out = {}
    for name, path in sorted(rec.measured_paths().items()):
        if name not in trace.joint_names or len(path) < 2:
            continue
        t = clock[:n_ok]
        inside = (t > path[0, 0]) & (t <= path[-1, 0])
        d = trace.joints[:n_ok, trace.joint_names.index(name)][inside] - np.interp(t[inside], path[:, 0], path[:, 1])
        d = np.abs((d + math.pi) % (2 * math.pi) - math.pi)  # a revolute joint's turn either way
        d = d[np.isfinite(d)]
        if len(d):
            out[name] = {"median": float(np.median(d)), "max": float(d.max())}
    return out


def replay(
    rec: Recording,
    build: ambf.AmbfBuild,
    launch: Path,
    indices,
    pace: Pace | None = None,
    follow: str = "commands",
    grasp: str = "lies",
) -> Replay:
    """The recording played in AMBF (its set-points paced by ``pace``, None: at AMBF's own time;
    or ``follow="measured"``: the joints following adfkit's measured paths; its grasps holding the
    needle as ``grasp`` says, GRASPS), judged by the same verdicts, its tip path compared with
    adfkit's."""
    from ..tasks.verdicts import pair_verdict
    from .traces import from_ambf

    stage = ambf.Stage(Path(launch).resolve(), list(indices) if indices is not None else _all(launch))
    if follow == "measured" and pace is not None:
        raise ValueError("a replay following the measured joints plays at AMBF's own time: no pace")
    longest = rec.seconds * (pace.max_factor if pace is not None else 1.0)
    run = ambf.run(
        build,
        stage,
        rec.seconds,
        EVERY,
        rec.commands_for(follow, grasp),
        timeout=600 + 10 * longest,
        pace=None if pace is None else pace.plugin(),
        pace_max_s=None if pace is None else longest,
        follow_gain=FOLLOW_GAIN if follow == "measured" else None,
    )
    trace = from_ambf(run)
    obs = AmbfObservation(rec, trace, grasp)
    verdicts = [pair_verdict(obs, p) for p in rec.task.pairs]
    gaps = tip_gaps(rec.tip_path, obs.tip_path, rec.phase_log, rec.task.pairs)
    return Replay(verdicts, gaps, trace, pace, run.end, follow, tracking(rec, trace), grasp)


def _all(launch: Path) -> list[int]:
    from ..adf import read_file

    doc, _ = read_file(launch)
    return list(range(len(getattr(doc, "multibody_configs", None) or [])))


def replay_modes(paces: tuple[Pace | None, ...] = (None,), follow: str = "commands") -> list[tuple]:
    """The replays asked for, ``(pace, follow)`` each, the first judged against adfkit: the
    set-points once per pace (``follow="commands"``), the measured paths at AMBF's own time
    (``"measured"``, no pace), or the measured paths first and then the set-points (``"both"``)."""
    if follow == "commands":
        return [(p, "commands") for p in paces]
    if follow not in ("measured", "both"):
        raise ValueError(f"follow is one of commands, measured, both, not {follow!r}")
    if follow == "measured" and any(p is not None for p in paces):
        raise ValueError("a replay following the measured joints plays at AMBF's own time: no pace")
    return [(None, "measured")] + ([(p, "commands") for p in paces] if follow == "both" else [])


def compare_suture(
    launch: Path,
    indices,
    pairs,
    build: ambf.AmbfBuild,
    seed: int = 0,
    progress: bool = False,
    paces: tuple[Pace | None, ...] = (None,),
    follow: str = "measured",
    options: dict | None = None,
    grasp: str = "lies",
) -> dict:
    """The suture in adfkit, recorded under ``options`` (``record``), and replayed in AMBF (as
    ``replay_modes(paces, follow)`` lists, the first judged against adfkit's verdicts; the grasps
    as ``grasp`` says), judged alike: the issue's JSON."""
    modes = replay_modes(paces, follow)
    measured = any(f == "measured" for _, f in modes)
    rec = record(launch, indices, pairs, seed, progress, measured=measured, options=options)
    return compare_recorded(rec, launch, indices, build, modes, grasp) | {"scene": str(launch), "seed": seed}


def compare_recorded(
    rec: Recording, launch: Path, indices, build: ambf.AmbfBuild, modes=((None, "commands"),), grasp: str = "lies"
) -> dict:
    """A recording replayed in AMBF once per ``(pace, follow)`` mode, as ``compare_suture``
    reports it."""
    return judged(rec, [replay(rec, build, launch, indices, p, f, grasp) for p, f in modes])


def judged(rec: Recording, replays: list[Replay]) -> dict:
    """The replays' verdicts beside adfkit's, the first judged against them: the issue's JSON."""
    first = replays[0]
    mine = {v["pair"]: v for v in rec.verdicts}
    out = []
    for k, v in enumerate(first.verdicts):
        a = mine.get(v["pair"], {})
        row = {
            "pair": v["pair"],
            "adfkit": a.get("verdict", "not-tried"),
            "ambf": v["verdict"],
            "adfkit_rule": a.get("rule"),
            "ambf_rule": v["rule"],
            "ambf_reason": v["reason"],
            "tip_path_gap_m": first.gaps.get(v["pair"]),
        }
        for other in replays[1:]:
            how = other.label
            w = other.verdicts[k]
            row[f"ambf_{how}"] = w["verdict"]
            row[f"ambf_{how}_rule"] = w["rule"]
            row[f"tip_path_gap_{how}_m"] = other.gaps.get(v["pair"])
        out.append(row)
    return {
        "seconds": rec.seconds,
        "recorded_with": dict(rec.options),
        "commands": len(rec.commands_for(first.follow)),
        "follow": first.follow,
        "grasp": first.grasp,
        "pairs": out,
        "same_verdicts": all(p["adfkit"] == p["ambf"] for p in out),
        "paced": first.pace is not None,
        "pace": first.pace_json(),
        # AMBF's world blew up there (its poses not finite); judged on what came before
        "ambf_not_finite_from_s": _blew_up(first.trace),
        "wall_s": {"adfkit": rec.wall_s, "ambf": first.trace.wall_s},
        "replays": [r.json() for r in replays],
        "not_judged_on_ambf": ["tool-hit-tissue", "blocked-at-entry by force", "blocked-in-channel by force"],
    }


def _blew_up(trace) -> float | None:
    """The command clock's time at which AMBF's poses stopped being finite, or None."""
    n_ok = finite_samples(trace)
    clock = trace.clock if trace.clock is not None else trace.times
    return float(clock[n_ok]) if n_ok < len(clock) else None
