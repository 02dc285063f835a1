"""`adfkit demo`: what `make run` does — play the suturing scene headless for a few seconds in
the PyBullet runner and write a report and camera images into run-output/.

The scene is the project's own suturing scene, bundled in sample_scenes/suturing/ (two PSMs,
the phantom, the needle and its thread; see `adfkit build-scene suturing`). The challenge's
scene files play with ``--scene ../shared/corpus/src/launch.yaml -l 6-11``."""

from __future__ import annotations

from pathlib import Path

NAME = "demo"
HELP = "play the suturing scene headless for a few seconds and write a report and camera images"

ROOT = Path(__file__).resolve().parents[2]
BUNDLED = ROOT / "sample_scenes" / "suturing" / "launch.yaml"


def add_arguments(p) -> None:
    p.add_argument("--scene", default=None, help="launch file to play instead of the default scene")
    p.add_argument("-l", "--indices", default=None, help="launch indices with --scene (e.g. 6-11)")
    p.add_argument("--seconds", type=float, default=3.0, help="simulated time (default 3)")
    p.add_argument("--out", default="run-output", help="folder for report.json and images (default run-output)")


def run(args) -> int:
    import sys

    from ..adf import load_scene, parse_indices
    from ..diagnostics import Severity
    from ..report import print_diagnostics
    from ..summary import format_summary, scene_summary

    if args.scene:
        from .. import inputs

        launch, indices = inputs.scene_file(args.scene), args.indices  # a folder: its launch.yaml
    else:
        launch, indices = BUNDLED, None
        if not launch.exists():  # installed without the repository's sample_scenes/: author it now
            from .. import scratch
            from ..scenes import write_suturing

            launch = write_suturing(scratch.mkdtemp("adfkit-demo-"))
    diags: list = []
    scene = load_scene(launch, parse_indices(indices) if indices else None, diags)
    print_diagnostics(diags, sys.stderr)
    print(f"scene: {launch}" + (f" (indices {indices})" if indices else ""))
    print(format_summary(scene_summary(scene)))
    if any(d.severity >= Severity.ERROR for d in diags):
        return 2

    from ..runner import Options, open_world
    from ..runner.play import play, summary, unstable

    out = Path(args.out)
    world = open_world(scene, Options())
    try:
        report = play(world, args.seconds, out, True, str(launch))
    finally:
        world.close()
    print(summary(report) + (", UNSTABLE" if unstable(report) else ", stable"))
    print(f"report: {(out / 'report.json').resolve()}")
    for f in report["frames"]:
        if f.endswith(".png"):
            print(f"image:  {(out / f).resolve()}")
    return 1 if unstable(report) else 0
