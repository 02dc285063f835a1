"""`adfkit suture [SCENE]`: the scripted suture (adfkit/tasks): one PSM picks the needle up and
drives it along its arc through entry k and out of exit k, the other pulls it through; writes
DIR/metrics.json, DIR/trajectory.png, DIR/cameraL.gif and, with --record, DIR/dataset/.

Exit status: 0 when every requested pair was passed (the per-pair verdict of
adfkit/tasks/verdicts.py: the tip in through entry k's opening and out through exit k's, tip
first, through their ghosts, the thread following, no slip past 2 mm; docs/suture.md), 1
otherwise (each failed pair printed with its rule and reason), 2 for bad input."""

from __future__ import annotations

import sys
from pathlib import Path

NAME = "suture"
HELP = "play the scripted suture through hole pairs and write metrics, a trajectory plot and a GIF"

ROOT = Path(__file__).resolve().parents[2]
BUNDLED = ROOT / "sample_scenes" / "suturing" / "launch.yaml"
CORPUS_LAUNCH = ROOT.parent / "shared" / "corpus" / "src" / "launch.yaml"
CORPUS_INDICES = "6-11"


def add_arguments(p) -> None:
    p.add_argument(
        "scene",
        nargs="?",
        help="launch file (default: the bundled sample_scenes/suturing, else the corpus suturing set with -l 6-11)",
    )
    p.add_argument("-l", "--indices", help="launch indices, e.g. 6-11")
    p.add_argument(
        "--pairs",
        default="1",
        help="how many hole pairs (pairs 1..N), a list such as 2,3, or all (every pair of the phantom)",
    )
    p.add_argument(
        "--phantom",
        metavar="MODEL.yaml",
        help="your phantom's model file (as the Blender add-on exports it, with Entry k / Exit k hole ghosts), "
        "or a launch file listing its model files, "
        "played in the bundled scene in place of its phantom, the arms, needle and cameras placed for its holes",
    )
    p.add_argument(
        "--not-tissue",
        action="append",
        default=[],
        metavar="BODY",
        help="a body the verdicts do not judge as tissue (every body but the arms, the needle and the thread is); "
        "repeat for more",
    )
    p.add_argument("--out", default="suture-output", help="output folder (default suture-output)")
    p.add_argument("--seed", type=int, default=0, help="seed of the plan's small randomisation")
    p.add_argument("--gui", action="store_true", help="open the PyBullet window")
    p.add_argument(
        "--engine",
        choices=("pybullet", "mujoco"),
        default="pybullet",
        help="physics engine (default pybullet; docs/mujoco.md says how the suture fares in MuJoCo)",
    )
    p.add_argument("--record", action="store_true", help="write the dataset (RGB, depth, segmentation, poses)")
    p.add_argument("--every", type=int, default=10, help="with --record: a frame every N control steps")
    p.add_argument(
        "--format",
        choices=("dataset", "rosbag"),
        help="with --record: a dataset folder (default) or a ROS 1 bag, OUT/episode.bag (images, depth, joints, TF)",
    )
    p.add_argument(
        "--episodes",
        type=int,
        default=1,
        help="episodes (seeds SEED..SEED+N-1) as Ray tasks, each in OUT/episode_<seed>, merged in OUT/index.json",
    )
    p.add_argument("--workers", type=int, default=None, help="Ray workers on a local Ray (default 2 with --episodes)")
    p.add_argument("--address", help="Ray cluster address (auto, ray://head:10001); default: a local Ray")


def parse_pairs(text: str) -> list[int]:
    """``--pairs``: a count (pairs 1..N) or a list of pair numbers."""
    from ..diagnostics import AdfError, error

    try:
        if "," in text:
            pairs = [int(x) for x in text.split(",")]
        else:
            pairs = list(range(1, int(text) + 1))
    except ValueError:
        pairs = []
    if not pairs or any(k < 1 for k in pairs) or len(set(pairs)) != len(pairs):
        raise AdfError(
            error(
                "bad-option",
                f"--pairs {text!r} is not a count 1..4 or a list of pair numbers",
                None,
                "e.g. --pairs 4 or --pairs 2,3",
            )
        )
    return pairs


def run(args) -> int:
    from ..diagnostics import AdfError, error

    # all: every whole pair the scene has (run_episode finds them)
    pairs = None if args.pairs.strip().lower() == "all" else parse_pairs(args.pairs)
    if args.every < 1:
        raise AdfError(error("bad-option", "--every must be ≥ 1", None, "e.g. --every 10"))
    if args.format and not args.record:
        raise AdfError(error("bad-option", "--format says how --record writes", None, "add --record"))
    record = (args.format or "dataset") if args.record else False
    if args.phantom and args.scene:
        raise AdfError(
            error(
                "bad-option",
                "--phantom puts your phantom into the bundled scene; it does not go with a SCENE",
                None,
                "drop SCENE (adfkit suture --phantom MODEL.yaml), or play your whole scene (adfkit suture SCENE)",
            )
        )
    if args.scene:
        from .. import inputs

        launch, indices = inputs.scene_file(args.scene), args.indices  # a folder: its launch.yaml
        if not launch.is_file():
            raise AdfError(error("no-file", f"{launch} does not exist", None, "give a launch file"))
    elif BUNDLED.is_file():
        launch, indices = BUNDLED, args.indices
    elif CORPUS_LAUNCH.is_file():
        launch, indices = CORPUS_LAUNCH, args.indices or CORPUS_INDICES
    else:
        raise AdfError(
            error(
                "no-scene",
                "no suturing scene: neither sample_scenes/suturing/launch.yaml nor ../shared/corpus is here",
                None,
                "run `adfkit build-scene suturing DIR` and give DIR/launch.yaml",
            )
        )
    from ..adf import load_scene, parse_indices
    from ..diagnostics import Severity
    from ..report import print_diagnostics

    diags: list = []
    load_scene(launch, parse_indices(indices) if indices else None, diags)
    if args.phantom:
        from .. import inputs
        from ..scenes.suturing.own_phantom import load_phantom

        phantom = Path(args.phantom)
        inputs.check_path_text(phantom)
        if not phantom.is_file():
            raise AdfError(error("no-file", f"{phantom} does not exist", None, "give the phantom's model file"))
        load_phantom(phantom, diags)
        if launch != BUNDLED:
            raise AdfError(
                error(
                    "no-scene",
                    "--phantom needs the bundled scene (sample_scenes/suturing), which is not here",
                    None,
                    "run from a checkout of adfkit",
                )
            )
    if any(d.severity >= Severity.ERROR for d in diags):
        print_diagnostics(diags, sys.stderr)
        return 2
    out = Path(args.out)
    if args.episodes > 1 or args.workers or args.address:
        if args.episodes < 1 or (args.workers is not None and args.workers < 1):
            raise AdfError(
                error(
                    "bad-option", "--episodes and --workers must be at least 1", None, "e.g. --episodes 4 --workers 2"
                )
            )
        from ..fanout import suture_episodes

        return suture_episodes(
            launch,
            indices,
            pairs,
            args.seed,
            args.episodes,
            args.workers or 2,
            args.address,
            out,
            record,
            args.every,
            engine=args.engine,
            phantom=args.phantom,
            not_tissue=args.not_tissue,
        )
    from ..tasks.episode import run_episode

    if args.gui and args.engine == "mujoco":
        raise AdfError(
            error(
                "bad-option",
                "--gui opens PyBullet's window; the MuJoCo engine plays headless",
                None,
                "drop --gui, or use --engine pybullet",
            )
        )
    m = run_episode(
        launch,
        indices,
        pairs,
        args.seed,
        out,
        record,
        args.gui,
        progress=True,
        every=args.every,
        engine=args.engine,
        phantom=args.phantom,
        not_tissue=args.not_tissue,
    )
    if m.get("failure", "").startswith("setup:") if m.get("failure") else False:
        raise AdfError(
            error(
                "suture-setup",
                m["failure"].removeprefix("setup: "),
                None,
                "the phantom needs Entry k/Exit k hole ghosts (the add-on's hole helpers make them; docs/phantom.md)"
                if args.phantom
                else "the scene needs a Needle, Entry k/Exit k hole ghosts and two PSMs",
            )
        )
    for p in m["pairs"]:
        state = "passed" if p["passed"] else "NOT passed"
        print(
            f"pair {p['pair']}: {p['entry']} -> {p['exit']} {state}"
            + (
                f" (entry {p['entry_passed_s']:.2f} s, exit {p['exit_passed_s']:.2f} s)"
                if p["passed"]
                else f" [{p.get('rule')}]: {p.get('reason')}"
            )
        )
    if any(d["free"] for d in m.get("tissue_moved") or []):
        from ..tasks.tissue_moved import said

        print(
            f"the tissue moved during the run: {said(m['tissue_moved'])} (a phantom body with a mass and "
            "no joint holding it is pushed by the needle; give it mass 0, or a fixed joint to a body of mass 0)",
            file=sys.stderr,
        )
    if m.get("failure"):
        print(f"stopped: {m['failure']}", file=sys.stderr)
    rtf = m.get("real_time_factor")
    angles = (m.get("joint_angle_error_by_phase_deg") or {}).values()
    err = m.get("max_constraint_error_m")
    print(
        f"simulated {m.get('simulated_time_s', 0):.2f} s, {rtf:.2f}x real time, thread "
        f"{m.get('thread_length_through_tissue_m', 0) * 1000:.1f} mm through the tissue, "
        + (f"max constraint error {err * 1000:.2f} mm" if err is not None else "no loop-closing joint to measure")
        + (f" (fixed joints {max(angles):.1f}° off)" if angles else "")
        + (", EXPLODED" if m.get("exploded") else "")
    )
    print(f"metrics: {(out / 'metrics.json').resolve()}")
    for e in m.get("instabilities", []):
        print(f"  unstable at t = {e['time_s']:.3f} s, {e['body'] or 'the scene'}: {e['message']}")
    return 0 if m.get("all_passed") and not m.get("exploded") else 1
