"""A parity run from end to end: the scene loaded by adfkit and built in each engine asked
for, the same scene staged for AMBF (a launch file as it is; a world or a model file inside a
launch file written for it, a model with the floor adfkit gives a model played alone), both
played for the same time with the same commands and samples, and compared."""

from __future__ import annotations

import sys
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..diagnostics import AdfError, Diagnostic, Severity, error
from . import ambf as ambf_run
from . import commandfile
from .compare import Comparison, compare
from .openings import opening, shut_pivots
from .spread import NUDGE_HINT, no_nudge
from .traces import AdfkitPlayer, from_ambf, tool_tips


@dataclass
class Request:
    path: Path
    indices: list[int] | None
    build: ambf_run.AmbfBuild
    seconds: float = 2.0
    every: float = 0.02
    engines: tuple[str, ...] = ("pybullet",)
    commands: Path | None = None
    control_substeps: int | None = None  # None: 4 (adfkit run's), 1 with joint commands (AMBF's rate)
    ground: bool = True
    ghosts: str = "ambf"  # adfkit's ghost rule (Options.ghosts): AMBF's own, unless asked otherwise
    springs: str = "ambf"  # how the PyBullet runner plays six-dof springs (Options.springs): as AMBF's Bullet
    link_shapes: str = "body"  # where the PyBullet runner puts a link's shapes (Options.link_shapes): the file's
    bodies: str = "ambf"  # what the PyBullet runner's bodies are (Options.bodies): AMBF's btRigidBodies
    tolerance_m: float = 1e-3
    tolerance_deg: float = 1.0
    spread_by: float | None = None  # AMBF played again with its dynamic roots nudged so far (m): its own spread


@dataclass
class Outcome:
    comparisons: list[Comparison]
    request: Request
    diagnostics: list[Diagnostic] = field(default_factory=list)
    ambf_process_s: float = 0.0
    log: str = ""


def check(req: Request) -> None:
    """The request's numbers, as a located error when one makes no sense."""
    bad_sub = req.control_substeps is not None and req.control_substeps < 1
    if req.seconds <= 0 or req.every < 0 or bad_sub or req.tolerance_m < 0 or req.tolerance_deg < 0:
        raise AdfError(
            error(
                "bad-option",
                "--seconds and --spread-by must be positive, --every, --tolerance-mm and --tolerance-deg not "
                "negative, --control-substeps ≥ 1",
                None,
                "e.g. --seconds 2 --every 0.02",
            )
        )
    if req.spread_by is not None and (why := no_nudge(req.spread_by, req.tolerance_m)):
        raise AdfError(error("bad-option", why, None, NUDGE_HINT))
    per = 0.001 * (req.control_substeps or 1)
    for name, v in (("--seconds", req.seconds), ("--every", req.every)):
        if abs(v / per - round(v / per)) > 1e-6:
            raise AdfError(
                error(
                    "bad-option",
                    f"{name} {v:g} is not a whole number of adfkit's control steps ({per * 1e3:g} ms)",
                    None,
                    f"round it to a multiple of {per:g} s",
                )
            )


def _stage(scene, req: Request, floor_z: float | None) -> ambf_run.Stage:
    path = req.path.resolve()
    if scene.launch is not None:
        n = len(scene.launch.multibody_configs or [])
        return ambf_run.Stage(path, list(req.indices) if req.indices is not None else list(range(n)))
    if scene.world is not None:
        return ambf_run.write_stage(path, [], None)
    return ambf_run.write_stage(None, [path], floor_z)


def run(req: Request, progress: bool | None = None) -> Outcome:
    """Play the request's scene in AMBF and in each of its engines; their comparisons."""
    from ..adf import load_scene
    from ..report import Progress
    from ..runner import Options, open_world
    from ..validator.engine import SEVERITY_OVERRIDES

    check(req)
    commands_read = commandfile.read(req.commands) if req.commands is not None else []
    if req.control_substeps is None:
        drives = any(c.kind in commandfile.JOINT_KINDS + ("pose",) for c, _ in commands_read)
        req = replace(req, control_substeps=1 if drives else 4)
        check(req)
    diags: list[Diagnostic] = []
    scene = load_scene(req.path, req.indices, diags)
    diags = [replace(d, severity=SEVERITY_OVERRIDES.get(d.rule, d.severity)) for d in diags]
    if any(d.severity >= Severity.ERROR for d in diags):
        raise AdfError(diags)
    opt = Options(control_substeps=req.control_substeps, ground=req.ground, visuals=False, renderer="tiny")
    opt.ghosts = req.ghosts
    opt.springs = req.springs
    opt.link_shapes = req.link_shapes
    opt.bodies = req.bodies
    worlds = []
    try:
        for e in req.engines:  # one floor for every side: the first engine's, which AMBF gets too
            worlds.append(open_world(scene, opt, engine=e))
            if opt.ground_z is None and worlds[0].ground_z is not None:
                opt = replace(opt, ground_z=worlds[0].ground_z)
        players = [AdfkitPlayer(w) for w in worlds]
        for w in worlds:
            diags.extend(w.diagnostics)
        commands = commandfile.resolved(commands_read, players[0].made)
        _check_drivable(commands_read, commands, players)
        floor_z = worlds[0].ground_z if req.ground else None
        stage = _stage(scene, req, floor_z)
        rec = ambf_run.run(req.build, stage, req.seconds, req.every, commands)
        ambf_trace = from_ambf(rec, stage.staged_bodies)
        spread = _ambf_spread(req, scene, floor_z, commands, ambf_trace) if req.spread_by is not None else None
        out = Outcome([], req, diags, rec.process_s, rec.log)
        for p in players:
            steps = int(round(req.seconds / p.per))
            bar = Progress(steps, f"parity {p.world.engine}", enabled=progress)
            trace = p.play(req.seconds, req.every, commands, bar)
            bar.close()
            c = compare(ambf_trace, trace, req.tolerance_m, req.tolerance_deg)
            c.unstable = [str(e) for e in p.world.watch.events]
            if spread is not None:
                c.spread, c.nudge, c.spread_notes = spread
            if any(cmd.kind in commandfile.JOINT_KINDS for cmd, _ in commands_read):  # driven: its tips
                c.tips = tool_tips(list(zip(p.made["body"], p.bodies)), p.joints)
            pivots = shut_pivots(p.world, p.made)
            for t in (ambf_trace, trace):
                o = opening(t, pivots)
                if o is not None:
                    c.opening[t.side] = o
            out.comparisons.append(c)
        return out
    finally:
        for w in worlds:
            w.close()


def _ambf_spread(req: Request, scene, floor_z, commands, trace):
    """AMBF's own spread: the scene played again in AMBF once per nudge of spread.DIRECTIONS, every
    dynamic root moved ``req.spread_by`` that way (spread.nudge_dynamic_roots); each body's largest gap
    to ``trace`` over those runs (of two bodies of one name, the smaller), the nudge, and what the
    nudged runs met. A nudged run whose world blew up (a body flung or not a number) gives no spread:
    it is said and left out (AMBF's falling thread, moved 0.1 µm off its plane, blows up; in its
    plane it stands where it stood)."""
    import tempfile

    from .spread import DIRECTIONS, nudge_dynamic_roots

    by: dict[str, tuple[float, float]] = {}
    notes: list[str] = []
    for direction in DIRECTIONS:
        with tempfile.TemporaryDirectory(prefix="adfkit-spread-") as tmp:
            try:
                copy, nudge = nudge_dynamic_roots(req.path, req.indices, req.spread_by, direction, Path(tmp))
            except ValueError as e:
                raise AdfError(error("spread-nudge", f"--spread: {e}", None, "leave --spread out here")) from None
            if not nudge.moved:
                what = "no dynamic root could be nudged" if nudge.not_moved else "no dynamic body to nudge"
                return {}, nudge, [f"{what}: AMBF's spread not measured"]
            stage = _stage(scene, replace(req, path=copy), floor_z)
            rec = ambf_run.run(req.build, stage, req.seconds, req.every, commands)
        c = compare(from_ambf(rec, stage.staged_bodies), trace)  # the nudged run first: its flung bodies
        if c.flung or c.not_a_number:  # AMBF's world blew up: no answer of AMBF's to measure a gap against
            first = min(c.flung + c.not_a_number, key=lambda d: d["from_s"])
            notes.append(
                f"{direction}: AMBF's world blew up ({len(c.flung)} bodies flung, {len(c.not_a_number)} not a "
                f"number; the first {first['name']} at {first['from_s']:.3f} s), left out of the spread"
            )
            continue
        run: dict[str, tuple[float, float]] = {}
        for g in c.bodies:
            old = run.get(g.name, (np.inf, np.inf))
            run[g.name] = (min(old[0], g.max_position), min(old[1], g.max_angle))
        for name, (p, a) in run.items():
            old = by.get(name, (0.0, 0.0))
            by[name] = (max(old[0], p), max(old[1], a))
    return by, nudge, notes


def _check_drivable(read, commands, players: list[AdfkitPlayer]) -> None:
    """A located error for each pose command to a static body (AMBF's plugin refuses it, once
    AMBF has loaded the scene) and each joint command whose joint an adfkit world cannot drive: AMBF
    gives every hinge and slider a motor, adfkit drives the joints of its articulations only (a
    joint closing a kinematic loop is a constraint there, without a motor; the two engines may
    close a loop at different joints)."""
    from ..model.semantics import JointKind, joint_kind

    diags = []
    for (_, where), c in zip(read, commands):
        if c.kind == "pose" and players[0].by_name["body"][c.target].static:
            why = f"a pose command steers a dynamic body only, and {c.target!r} is static (mass 0)"
            diags.append(
                error("command-target", why, where, "give the body a mass, or leave it out of the command file")
            )
        if c.kind not in commandfile.JOINT_KINDS:
            continue
        first = players[0].by_name["joint"][c.target][0]
        if joint_kind(first.type) in (JointKind.TORSION_SPRING, JointKind.LINEAR_SPRING) and c.kind != "effort":
            continue  # AMBF moves a spring by effort only; a position or velocity command does nothing there
        if id(first) in players[0].inert:
            continue  # AMBF keeps the joint and it moves nothing (World.inert_joints): nor does the command
        for player in players:
            joint, child = player.by_name["joint"][c.target]
            pushed = c.kind == "effort" and getattr(player.world, "pushes_spring", lambda _j: False)(joint)
            if player.commands.drivable(joint, child) is None and not pushed:
                break
        else:
            continue
        kind = joint_kind(joint.type)
        if kind in (JointKind.REVOLUTE, JointKind.PRISMATIC):
            why = "it closes a kinematic loop, which adfkit plays as a constraint without a motor"
            hint = "drive the loop's other joints (those of its tree), or leave this one out"
        elif kind in (JointKind.TORSION_SPRING, JointKind.LINEAR_SPRING):
            if player.world.engine == "mujoco":
                why = "the MuJoCo engine pushes a spring with both limits only, and this one is not"
            else:
                why = "adfkit pushes a spring of a kinematic tree only (one with both limits), and this one is not"
            hint = "play it with --engine pybullet, or leave this joint out of the command file"
        else:
            why = f"adfkit drives revolute, prismatic and spring joints only, and this one is {joint.type!r}"
            hint = "leave this joint out of the command file"
        engine = f" in {player.world.engine}" if len(players) > 1 else ""
        diags.append(error("command-target", f"adfkit cannot drive joint {c.target!r}{engine}: {why}", where, hint))
    if diags:
        raise AdfError(diags)


#: said where neither side made a body both made (every body left out, e.g. for meshes not found)
NOTHING_COMPARED = (
    "AMBF and adfkit made no body of the same name (the warnings above say which bodies were left out and why)"
)


def print_text(out: Outcome, stream=None, rows: int = 12) -> None:
    """The comparisons for people: the largest gaps, the bodies past the tolerances, what one
    side made and the other did not, each side's stepping time. ``stream``: sys.stdout as it is
    when called (a default bound at import wrote to whatever stdout was then, a test's closed one)."""
    stream = sys.stdout if stream is None else stream
    req = out.request
    for c in out.comparisons:
        eng = c.adfkit.side
        print(
            f"{req.path}: {c.times[-1] if c.times.size else 0:g} s, {c.times.size} samples, AMBF against adfkit {eng} "
            f"(control step {req.control_substeps} ms)",
            file=stream,
        )
        pos, ang = c.worst
        if pos is not None:
            print(
                f"  {len(c.bodies)} bodies matched; largest gaps {pos.max_position * 1e3:.3f} mm ({pos.name}), "
                f"{ang.max_angle:.3f}° ({ang.name})",
                file=stream,
            )
            spread = f" {'AMBF±mm':>9} {'AMBF±°':>8}" if c.spread is not None else ""
            print(f"  {'body':<48} {'max mm':>9} {'max °':>8} {'end mm':>9} {'end °':>8}{spread}", file=stream)
            for g in c.bodies[:rows]:
                print(
                    f"  {g.name[-48:]:<48} {g.max_position * 1e3:9.3f} {g.max_angle:8.3f} "
                    f"{g.position[-1] * 1e3:9.3f} {g.angle[-1]:8.3f}{_spread_cells(c, g)}",
                    file=stream,
                )
            if len(c.bodies) > rows:
                print(f"  … {len(c.bodies) - rows} more (--json lists every body)", file=stream)
        tips = c.tip_gaps
        if tips:
            tip = max(tips, key=lambda g: g.max_position)
            print(
                f"  tool tips ({', '.join(g.name.rsplit('/', 1)[-1] for g in tips)}): at most "
                f"{tip.max_position * 1e3:.3f} mm ({tip.name.rsplit('/', 1)[-1]})",
                file=stream,
            )
        if c.opening:
            sides = "; ".join(
                f"{'AMBF' if side == 'ambf' else side} "
                + (
                    f"{o.widest_m * 1e3:.3f} mm ({o.widest}), {o.summed_m * 1e3:.3f} mm summed at most, "
                    f"{o.summed_end_m * 1e3:.3f} at the end"
                    if o.widest_m >= 1e-6
                    else "shut"
                )
                for side, o in c.opening.items()
            )
            print(f"  joints standing open (pivots apart), widest: {sides}", file=stream)
        for label, items in (("only in AMBF", c.only_in_ambf), ("only in adfkit", c.only_in_adfkit)):
            for d in items:
                print(f"  {label}: {d['kind']} {d['name']}", file=stream)
        for u in c.unstable:
            print(f"  adfkit {eng} unstable: {u}", file=stream)
        for d in c.not_a_number:
            who = "AMBF" if d["side"] == "ambf" else f"adfkit {d['side']}"
            print(f"  {who}'s {d['name']} is not a number from {d['from_s']:.3f} s", file=stream)
        if c.flung:
            d = min(c.flung, key=lambda d: d["from_s"])
            print(
                f"  AMBF's world blew up: {len(c.flung)} bodies flung, the first {d['name']} "
                f"({d['speed_m_s']:.3g} m/s) at {d['from_s']:.3f} s",
                file=stream,
            )
        print(
            f"  stepping: AMBF {c.ambf.wall_s:.2f} s, adfkit {eng} {c.adfkit.wall_s:.2f} s "
            f"(AMBF's whole process {out.ambf_process_s:.2f} s)",
            file=stream,
        )
        if c.spread is not None:
            _print_spread(c, stream)
        fails = c.failures()
        explained = c.spread_summary()["within_ambf_spread"] if c.spread is not None else []
        tol = f"{c.tolerance_m * 1e3:g} mm / {c.tolerance_deg:g}°"
        if fails:
            print(
                f"  differ: {len(fails)} past {tol} or made on one side only"
                + (" (and past AMBF's own spread)" if c.spread else ""),
                file=stream,
            )
        elif explained:
            print(
                f"  agree within AMBF's own spread: every body within {tol}, or ({len(explained)}) within "
                f"AMBF's spread and {tol} more",
                file=stream,
            )
        elif not c.bodies:
            print(f"  nothing compared: {NOTHING_COMPARED}", file=stream)
        else:
            print(f"  agree: every body within {c.tolerance_m * 1e3:g} mm and {c.tolerance_deg:g}°", file=stream)


def _spread_cells(c: Comparison, g) -> str:
    if c.spread is None:
        return ""
    s = c.spread.get(g.name)
    if s is None:
        return f" {'-':>9} {'-':>8}"
    return f" {s[0] * 1e3:9.3f} {s[1]:8.3f}" + ("  within AMBF's spread" if c.within_spread(g) else "")


def _print_spread(c: Comparison, stream) -> None:
    """AMBF's own spread: what was nudged, the largest spreads, the bodies it explains."""
    s = c.spread_summary()
    if not s["nudged_bodies"]:
        print(f"  AMBF's own spread: {'; '.join(c.spread_notes)}", file=stream)
        for d in s["not_nudged"]:
            print(f"  not nudged: {d['name']}: {d['why']}", file=stream)
        return
    n = len(s["nudged_bodies"])
    names = ", ".join(s["nudged_bodies"][:6]) + (" …" if n > 6 else "")
    pos, ang = s["largest_position"], s["largest_angle"]
    found = (
        f"largest {pos['m'] * 1e3:.3f} mm ({pos['name']}), {ang['deg']:.3f}° ({ang['name']}); "
        f"{len(s['within_ambf_spread'])} of {s['past_tolerance']} bodies past the tolerances within it"
        if pos is not None
        else "not measured: every nudged run blew up"
        if c.spread_notes
        else "not measured: AMBF made no body the comparison matches"
    )
    print(
        f"  AMBF's own spread (AMBF {len(s['nudges'])} more times, {n} dynamic {'root' if n == 1 else 'roots'} "
        f"({names}) moved {s['nudge_m']:g} m along {', '.join(s['nudges'])}): {found}",
        file=stream,
    )
    past = [g for g in c.bodies if c.past(g) and not c.within_spread(g) and g.name in c.spread]
    if past:
        print(
            "  past AMBF's own spread: "
            + ", ".join(
                f"{g.name.rsplit('/', 1)[-1]} ({g.max_position * 1e3:.3f} mm {g.max_angle:.2f}°; AMBF "
                f"{c.spread[g.name][0] * 1e3:.3f} mm {c.spread[g.name][1]:.2f}°)"
                for g in past[:6]
            )
            + (f" and {len(past) - 6} more" if len(past) > 6 else ""),
            file=stream,
        )
    for d in s["not_nudged"]:
        print(f"  not nudged: {d['name']}: {d['why']}", file=stream)
    for note in c.spread_notes:
        print(f"  AMBF nudged {note}", file=stream)
