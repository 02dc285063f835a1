"""`adfkit build-scene NAME OUT_DIR`: author a sample scene from code."""
from __future__ import annotations

NAME = "build-scene"
HELP = "write one of adfkit's own sample scenes (ADF files) into a folder"


def add_arguments(p) -> None:
    from ..scenes import BUILDERS

    p.add_argument("name", choices=sorted(BUILDERS), help="which scene")
    p.add_argument("out_dir", help="folder to write the scene into (created if needed)")


def run(args) -> int:
    from ..scenes import BUILDERS

    launch = BUILDERS[args.name](args.out_dir)
    print(f"wrote {args.name} to {args.out_dir} (launch file: {launch})")
    return 0
