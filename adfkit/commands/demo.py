"""`adfkit demo`: what `make run` does — play the suturing scene headless for a few seconds in
the PyBullet runner and write a report and camera images into run-output/.

The scene is the corpus suturing set (launch indices 6-11) when ../shared/corpus is present,
else the bundled primitive-only suturing-pad sample scene."""
from __future__ import annotations

from pathlib import Path

NAME = "demo"
HELP = "play the suturing scene headless for a few seconds and write a report and camera images"

ROOT = Path(__file__).resolve().parents[2]
BUNDLED = ROOT / "sample_scenes" / "suturing_pad" / "launch.yaml"
CORPUS_LAUNCH = ROOT.parent / "shared" / "corpus" / "src" / "launch.yaml"
CORPUS_INDICES = "6-11"


def add_arguments(p) -> None:
    p.add_argument("--scene", default=None, help="launch file to play instead of the default scene")
    p.add_argument("-l", "--indices", default=None, help="launch indices with --scene (e.g. 6-11)")
    p.add_argument("--seconds", type=float, default=3.0, help="simulated time (default 3)")
    p.add_argument("--out", default="run-output", help="folder for report.json and images (default run-output)")


def run(args) -> int:
    import sys
    import tempfile

    from ..adf import load_scene, parse_indices
    from ..diagnostics import Severity
    from ..report import print_diagnostics
    from ..summary import format_summary, scene_summary

    if args.scene:
        launch, indices = Path(args.scene), args.indices
    elif CORPUS_LAUNCH.is_file():
        launch, indices = CORPUS_LAUNCH, CORPUS_INDICES
    else:
        launch, indices = BUNDLED, None
        if not launch.exists():  # installed without the repository's sample_scenes/: author it now
            from ..scenes import write_suturing_pad
            launch = write_suturing_pad(Path(tempfile.mkdtemp(prefix="adfkit-demo-")))
    diags: list = []
    scene = load_scene(launch, parse_indices(indices) if indices else None, diags)
    print_diagnostics(diags, sys.stderr)
    print(f"scene: {launch}" + (f" (indices {indices})" if indices else ""))
    print(format_summary(scene_summary(scene)))
    if any(d.severity >= Severity.ERROR for d in diags):
        return 2

    from ..runner.play import play, summary, unstable
    from ..runner.world import Options, SimWorld
    out = Path(args.out)
    world = SimWorld(scene, Options())
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
