"""`adfkit parity SCENE --ambf DIR`: play a scene in AMBF itself (headless, through adfkit's
AMBF plugin) and in adfkit, and compare, body by body, where each puts it over time, and what
each created; exit 1 when they differ past the tolerances."""

from __future__ import annotations

import sys
from pathlib import Path

NAME = "parity"
HELP = "play a scene in AMBF and in adfkit and compare every body's pose over time"
DESCRIPTION = (
    "Play SCENE (a launch, world or model file) in AMBF's own simulator, headless, and in adfkit "
    "for the same simulated time, driven by the same commands, and compare every body's position "
    "and orientation over time and what each side created. Exit 1 when a body's gap passes the "
    "tolerances (with --spread, also AMBF's own spread) or one side created something the other did not; "
    "2 for bad input."
)


def add_arguments(p) -> None:
    p.add_argument(
        "path",
        nargs="?",
        help="launch, world or model ADF file (a folder: its launch.yaml); with --suture a suturing scene "
        "(default: the bundled sample_scenes/suturing)",
    )
    p.add_argument("-l", "--indices", help="launch file: the models to load, e.g. 6,7,8,9,10,11 or 6-11 (default: all)")
    p.add_argument(
        "--ambf",
        metavar="DIR",
        help="a built AMBF source tree (bin/lin-x86_64/ambf_simulator, build/); default $ADFKIT_AMBF, "
        "else the one `make ambf` builds into ~/.cache/adfkit",
    )
    p.add_argument("--seconds", type=float, default=2.0, help="simulated time (default 2)")
    p.add_argument("--every", type=float, default=0.02, help="a sample every so many seconds (default 0.02)")
    p.add_argument("--engine", choices=("pybullet", "mujoco", "both"), default="pybullet", help="adfkit's engine")
    p.add_argument(
        "--commands",
        metavar="FILE",
        help="drive both sides: lines `TIME, KIND, TARGET[, VALUE]`, KIND position|velocity|effort "
        "(a joint), grasp|release (a constraint actuator; grasp names the body) or pose (a free body, "
        "VALUE `x y z roll pitch yaw` or `x y z qx qy qz qw`)",
    )
    p.add_argument(
        "--control-substeps",
        type=int,
        help="adfkit's physics steps per control step (default 4, as adfkit run; 1 with a command file "
        "that drives joints: AMBF applies joint commands at every 1 ms step; --suture: the suture's 4)",
    )
    p.add_argument(
        "--ghosts",
        choices=("ambf", "hole-friction"),
        help="what adfkit's ghosts do (default ambf: AMBF's own ghost objects, gravity off and 10 %% of "
        "the velocity taken per contact point and step; hole-friction: the suture's rule, the paper's "
        "F = -K·v in hole ghosts, the default with --suture)",
    )
    p.add_argument(
        "--springs",
        choices=("ambf", "implicit"),
        help="how adfkit's PyBullet runner plays six-dof springs (default ambf: as AMBF's Bullet, explicit "
        "at every physics step with its caps; implicit: backward Euler over the control step, the suture's "
        "and the default with --suture)",
    )
    p.add_argument(
        "--bodies",
        choices=("ambf", "pybullet"),
        help="what adfkit's PyBullet bodies are: ambf (default; AMBF's btRigidBodies: AMBF's estimated inertia, "
        "the box of the collision shape's bounds, where the file gives none, and joints as fast as "
        "AMBF's bodies may turn, π/4 a physics step) or pybullet (PyBullet's estimate and its "
        "multibody's 100 rad/s joint cap: the suture's, and the default with --suture)",
    )
    p.add_argument(
        "--link-shapes",
        choices=("body", "com"),
        help="where adfkit's PyBullet runner puts a multibody link's collision shapes: body (default; where "
        "the file puts them, as AMBF) or com (about the link's centre of mass: the suture's, and the default "
        "with --suture)",
    )
    p.add_argument("--no-ground", action="store_true", help="a model file: no floor under it on either side")
    p.add_argument("--tolerance-mm", type=float, default=1.0, help="largest position gap that agrees (1 mm)")
    p.add_argument("--tolerance-deg", type=float, default=1.0, help="largest orientation gap that agrees (1°)")
    p.add_argument(
        "--spread",
        action="store_true",
        help="play AMBF six more times, each with every dynamic root (a body of positive mass no dynamic body "
        "holds by a joint: one on its own, a tree's first, one hanging from a static body) started --spread-by away along +x, -x, +y, -y, +z or -z, and give each body AMBF's own spread (its largest gap "
        "to the unnudged AMBF run over the six) beside its gap to adfkit; a body past the tolerances whose "
        "position and angle gaps are each within that spread plus the tolerance is reported within AMBF's own "
        "spread and does not make the exit 1",
    )
    p.add_argument(
        "--spread-by",
        type=float,
        metavar="M",
        help="--spread: the dynamic roots' nudge, in metres (default 1e-7; below --tolerance-mm and 1 mm)",
    )
    p.add_argument(
        "--ambf-iterations",
        metavar="N",
        help="Bullet's solver iterations a physics step in AMBF, every AMBF run of this command (default: "
        "AMBF's own, 10; with --suture the suture's own, 50, as adfkit records it)",
    )
    p.add_argument("--plot", metavar="PNG", help="draw each body's position gap over time")
    p.add_argument(
        "--suture",
        action="store_true",
        help="play adfkit's scripted suture, replay its PSM set-points and grasps in AMBF and judge the "
        "needle's path on both sides with the same verdicts (exit 1 when a pair's verdicts differ)",
    )
    p.add_argument("--pairs", default="1,2,3,4", help="--suture: the hole pairs, e.g. 4 or 1,2 (default 1,2,3,4)")
    p.add_argument("--seed", type=int, default=0, help="--suture: the plan's seed (default 0)")
    p.add_argument(
        "--pace",
        choices=("on", "off", "both"),
        default="off",
        help="--suture: off (default) plays the set-points at AMBF's own time; on replays on a command clock "
        "that waits for AMBF's joints to reach each set-point, as a client waits for measured_js (about 4x "
        "AMBF's time); both replays twice and reports both (verdicts judged on the unpaced one)",
    )
    p.add_argument(
        "--follow",
        choices=("commands", "measured", "both"),
        default=None,
        help="--suture: measured (the default without --pace) has each PSM joint follow the path adfkit's joint "
        "took (recorded each control step), a velocity command each 1 ms step closing the loop on AMBF's "
        "measured joint, as a client servoing measured_js would; commands (the default with --pace on or both) "
        "replays the set-points adfkit's planner gave as AMBF's position commands; both replays measured "
        "first (its verdicts judged), then the set-points",
    )
    p.add_argument(
        "--grasp",
        choices=("lies", "adfkit"),  # parity.suture.GRASPS
        default=None,  # lies; None tells a --grasp given without --suture
        help="--suture: where AMBF's grasps hold the needle: lies (default) where AMBF's needle lies when its "
        "jaws take it, as the challenge's constraint actuator does; adfkit where adfkit's grasp held it (the "
        "needle's frame in the tool's, given to AMBF's constraint actuator as its offset), so that no grasp "
        "keeps what AMBF's needle turned in the jaws before it",
    )
    p.add_argument(
        "--trials",
        type=int,
        default=1,
        metavar="K",
        help="--suture: replay the one recording K times in AMBF (following adfkit's measured joints), all but "
        "the first nudged (every PSM joint offset by --nudge, its sign random per joint), and report each "
        "pair's AMBF verdicts and how often they are adfkit's (default 1: one replay)",
    )
    p.add_argument(
        "--nudge",
        type=float,
        default=1e-4,
        metavar="RAD",
        help="--trials: the offset of each revolute PSM joint (rad; a prismatic one a tenth of it in m) (default 1e-4)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object (a list of them for --engine both)")


def run(args) -> int:
    from ..diagnostics import AdfError, error
    from ..parity import ambf

    iterations = None
    if args.ambf_iterations is not None and (iterations := ambf.read_iterations(args.ambf_iterations)) is None:
        why = f"--ambf-iterations {args.ambf_iterations!r}: AMBF's solver iterations are a positive whole number"
        raise AdfError(error("bad-option", why, None, ambf.ITERATIONS_HINT))
    iterations, args.ambf_iterations_from = ambf.iterations_for(iterations, args.suture)
    with ambf.iterations_set(iterations) as args.ambf_solver_iterations:
        return _run(args)


def _run(args) -> int:
    from .. import inputs
    from ..adf import parse_indices
    from ..diagnostics import AdfError, error
    from ..jsonout import dumps
    from ..parity import ambf, session
    from ..parity.spread import NUDGE_HINT, no_nudge

    if args.spread_by is not None and not args.spread:
        raise AdfError(error("bad-option", "--spread-by is the nudge of --spread", None, "add --spread"))
    if args.spread_by is not None and (why := no_nudge(args.spread_by, args.tolerance_mm / 1e3)):
        raise AdfError(error("bad-option", why, None, NUDGE_HINT))
    if args.suture:
        if args.spread:
            raise AdfError(
                error(
                    "bad-option",
                    "--spread plays a scene's dynamic roots nudged; a suture's AMBF replays are compared by --trials",
                    None,
                    "adfkit parity --suture [SCENE] --trials K (AMBF's verdicts under nudged joints)",
                )
            )
        return _suture(args)
    if args.trials != 1:
        raise AdfError(
            error("bad-option", "--trials replays a suture", None, "adfkit parity --suture [SCENE] --trials K")
        )
    if args.grasp is not None:
        raise AdfError(
            error(
                "bad-option",
                "--grasp is how a suture's replay grasps",
                None,
                "adfkit parity --suture [SCENE] --grasp adfkit",
            )
        )
    if not args.path:
        raise AdfError(error("bad-option", "name the scene to compare", None, "adfkit parity SCENE [-l 6-11]"))
    path = inputs.scene_file(args.path)
    inputs.check_file(path, what="ADF file")
    build = ambf.find_build(args.ambf)
    req = session.Request(
        path=Path(path),
        indices=parse_indices(args.indices),
        build=build,
        seconds=args.seconds,
        every=args.every,
        engines=("pybullet", "mujoco") if args.engine == "both" else (args.engine,),
        commands=Path(args.commands) if args.commands else None,
        control_substeps=args.control_substeps,  # None: session.Request decides
        ground=not args.no_ground,
        ghosts=args.ghosts or "ambf",
        springs=args.springs or "ambf",
        bodies=args.bodies or "ambf",
        link_shapes=args.link_shapes or "body",
        tolerance_m=args.tolerance_mm / 1e3,
        tolerance_deg=args.tolerance_deg,
        spread_by=(1e-7 if args.spread_by is None else args.spread_by) if args.spread else None,
    )
    out = session.run(req, progress=None if not args.json else False)
    from ..report import print_diagnostics

    print_diagnostics(out.diagnostics, sys.stderr)
    if args.plot:
        from ..parity.plot import plot_gaps

        plot_gaps(out.comparisons, Path(args.plot), str(path))
    if args.json:
        objs = [{**c.as_json(), "ambf_solver_iterations": args.ambf_solver_iterations} for c in out.comparisons]
        print(dumps(objs[0] if len(objs) == 1 else objs, indent=1))
    else:
        print(iterations_line(args))
        session.print_text(out)
    return 1 if any(c.failures() for c in out.comparisons) else 0


def _suture(args) -> int:
    from .. import inputs
    from ..adf import parse_indices
    from ..diagnostics import AdfError, error
    from ..jsonout import dumps
    from ..parity import ambf
    from ..parity.suture import PACE, compare_suture
    from .suture import parse_pairs

    bundled = Path(__file__).resolve().parents[2] / "sample_scenes" / "suturing" / "launch.yaml"
    path = inputs.scene_file(args.path) if args.path else bundled
    inputs.check_file(path, what="ADF file")
    pairs = parse_pairs(args.pairs.strip())
    build = ambf.find_build(args.ambf)
    paces = {"on": (PACE,), "off": (None,), "both": (None, PACE)}[args.pace]
    follow = args.follow or ("measured" if args.pace == "off" else "commands")
    if follow == "measured" and args.pace != "off":
        raise AdfError(
            error(
                "bad-option",
                "--follow measured plays at AMBF's own time: it takes no --pace",
                None,
                "use --follow both to replay the set-points paced beside it",
            )
        )
    if args.trials < 1 or not 0 < args.nudge < float("inf"):
        raise AdfError(error("bad-option", "--trials takes 1 or more, --nudge a positive offset", None))
    if args.trials > 1:
        if args.pace != "off" or follow != "measured":
            raise AdfError(
                error(
                    "bad-option",
                    "--trials replays follow adfkit's measured joints: no --pace, no --follow commands",
                    None,
                    "leave --pace and --follow out with --trials",
                )
            )
        return _trials(args, Path(path), pairs, build)
    out = compare_suture(
        Path(path),
        parse_indices(args.indices),
        pairs,
        build,
        args.seed,
        progress=not args.json,
        paces=paces,
        follow=follow,
        grasp=args.grasp or "lies",
        # what the user names; the rest the suture's own, which its acceptance was run on
        options=recording_options(args),
    )
    out["ambf_solver_iterations"] = args.ambf_solver_iterations
    if args.json:
        print(dumps(out, indent=1))
    else:
        how = "following adfkit's measured joints" if out.get("follow") == "measured" else "unpaced"
        how = "paced" if out["paced"] else how
        print(
            f"{path}: the suture, seed {args.seed}, {out['seconds']:.1f} s, replayed in AMBF {how} "
            f"({out['commands']} commands; the needle held in AMBF's jaws "
            + ("where adfkit's grasp held it)" if out.get("grasp") == "adfkit" else "where it lay)")
        )
        print("  recorded with " + ", ".join(f"{k} {v}" for k, v in out["recorded_with"].items()))
        print("  " + iterations_line(args))
        for p in out["pairs"]:
            gap = p["tip_path_gap_m"]
            print(
                f"  pair {p['pair']}: adfkit {p['adfkit']}, AMBF {p['ambf']}"
                + (f" ({p['ambf_rule']}: {p['ambf_reason']})" if p["ambf_rule"] else "")
                + (f", tip paths {gap * 1e3:.1f} mm apart at most" if gap == gap and gap is not None else "")
                + "".join(
                    f"; {label}: AMBF {p[f'ambf_{label}']}"
                    for label in ("measured", "unpaced", "paced")
                    if f"ambf_{label}" in p
                )
            )
        for r in out["replays"]:
            worst = max(r.get("tracking", {}).items(), key=lambda kv: kv[1]["median"], default=None)
            if worst is not None:
                print(
                    f"  {r.get('follow', 'commands')}: AMBF's PSM joints a median {worst[1]['median']:.4g} at most "
                    f"({worst[0]}) from adfkit's, {max(v['max'] for v in r['tracking'].values()):.4g} at worst"
                )
        for pace in (r["pace"] for r in out["replays"] if r["pace"] is not None):
            print(
                f"  paced: AMBF played {pace['ambf_simulated_s']:.1f} s for the recording's {out['seconds']:.1f} s, "
                f"the clock held {pace['held_steps']} steps, {pace['give_ups']} wait(s) given up"
                + ("" if pace["clock_reached_end"] else " (it did not reach the end)")
            )
        if out["ambf_not_finite_from_s"] is not None:
            print(
                f"  AMBF's world blew up at {out['ambf_not_finite_from_s']:.2f} s (poses not finite): judged before it"
            )
        w = out["wall_s"]
        print(f"  stepping: adfkit {w['adfkit']:.1f} s (the whole episode), AMBF {w['ambf']:.1f} s")
    return 0 if out["same_verdicts"] else 1


def _trials(args, path: Path, pairs, build) -> int:
    from ..adf import parse_indices
    from ..jsonout import dumps
    from ..parity.trials import Nudge, compare_trials

    nudge = Nudge(args.nudge, args.nudge / 10)
    out = compare_trials(
        path,
        parse_indices(args.indices),
        pairs,
        build,
        args.trials,
        nudge,
        args.seed,
        progress=not args.json,
        options=recording_options(args),
        grasp=args.grasp or "lies",
    )
    t = out["trials"]
    out["ambf_solver_iterations"] = args.ambf_solver_iterations
    if args.json:
        print(dumps(out, indent=1))
    else:
        print(
            f"{path}: the suture, seed {args.seed}, {out['seconds']:.1f} s, replayed in AMBF {t['count']} times "
            f"following adfkit's measured joints, all but the first nudged {nudge.rad:g} rad / {nudge.m:g} m"
        )
        print("  " + iterations_line(args))
        for p in t["pairs"]:
            gaps = [g * 1e3 for g in p["tip_path_gap_m"] if g is not None and g == g]
            rules = ", ".join(f"{r or v}" for v, r in zip(p["ambf"], p["ambf_rules"], strict=True))
            print(
                f"  pair {p['pair']}: adfkit {p['adfkit_rule'] or p['adfkit']}; AMBF {rules}: "
                f"adfkit's verdict {p['same']} of {t['count']}"
                + (", AMBF's own verdict changes with the nudge" if p["ambf_flips"] else "")
                + (f"; tip paths {min(gaps):.1f}-{max(gaps):.1f} mm apart at most" if gaps else "")
            )
    return 0 if all(p["same"] == t["count"] for p in t["pairs"]) else 1


def recording_options(args) -> dict:
    """The Options ``--suture`` records adfkit's suture under, as the user named them
    (``--springs``, ``--bodies``, ``--ghosts``, ``--link-shapes``, ``--control-substeps``)."""
    return {
        "springs": args.springs,
        "bodies": args.bodies,
        "ghosts": args.ghosts,
        "link_shapes": args.link_shapes,
        "control_substeps": args.control_substeps,
    }


def iterations_line(args) -> str:
    """What AMBF's Bullet solver iterates a step, for the text output."""
    return f"AMBF's solver iterations: {args.ambf_solver_iterations} a step ({args.ambf_iterations_from})"
