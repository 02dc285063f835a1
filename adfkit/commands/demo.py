"""`adfkit demo`: what `make run` does — load the bundled sample scene and show it."""
from __future__ import annotations

from pathlib import Path

NAME = "demo"
HELP = "load the bundled suturing-pad sample scene and print its summary"

BUNDLED = Path(__file__).resolve().parents[2] / "sample_scenes" / "suturing_pad" / "launch.yaml"


def add_arguments(p) -> None:
    p.add_argument("--scene", default=None, help="launch file to use instead of the bundled sample scene")


def run(args) -> int:
    import sys
    import tempfile

    from ..adf import load_scene
    from ..diagnostics import Severity
    from ..report import print_diagnostics
    from ..scenes import write_suturing_pad
    from ..summary import format_summary, scene_summary

    launch = Path(args.scene) if args.scene else BUNDLED
    if not launch.exists():  # installed without the repository's sample_scenes/: author it now
        launch = write_suturing_pad(Path(tempfile.mkdtemp(prefix="adfkit-demo-")))
    diags: list = []
    scene = load_scene(launch, None, diags)
    print_diagnostics(diags, sys.stderr)
    print(f"scene: {launch}")
    print(format_summary(scene_summary(scene)))
    return 2 if any(d.severity >= Severity.ERROR for d in diags) else 0
