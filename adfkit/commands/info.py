"""`adfkit info PATH`: a summary of a launch, world, input-devices or model file."""

from __future__ import annotations

import json
import sys

from .. import jsonout

NAME = "info"
HELP = "summarise a launch, world, input-devices or model file"


def add_arguments(p) -> None:
    p.add_argument("path", help="ADF file")
    p.add_argument(
        "--kind",
        choices=["launch", "world", "input_devices", "model", "colors"],
        help="file kind (detected from the keys by default)",
    )
    p.add_argument("--json", action="store_true", help="print JSON for machines")
    p.add_argument("-l", "--indices", help="for a launch file: load these multibody configs (e.g. 6,7,8 or 6-11)")


def run(args) -> int:
    from .. import inputs
    from ..adf import load_scene, parse_indices, read_file
    from ..diagnostics import Severity
    from ..report import print_diagnostics
    from ..summary import format_summary, summarize

    args.path = inputs.scene_file(args.path)  # a folder: its launch.yaml
    if args.indices:
        diags: list = []
        doc = load_scene(args.path, parse_indices(args.indices), diags)
    else:
        doc, diags = read_file(args.path, args.kind)
    summary = summarize(doc)
    try:  # a sum of huge masses can overflow: never print `total mass: inf` (or NaN) with exit 0
        json.dumps(summary, allow_nan=False)
    except ValueError:
        from ..diagnostics import SourceLocation, error

        where = getattr(doc, "source", None) or SourceLocation(str(args.path), 1, 1)
        diags = [
            *diags,
            error(
                "non-finite-number",
                "a total (mass) overflows to infinity or NaN",
                where,
                "check the bodies' masses; `adfkit validate` shows the implausible values",
            ),
        ]
        print_diagnostics(diags, sys.stderr)
        return 2
    print_diagnostics(diags, sys.stderr)
    if args.json:
        jsonout.dump(summary, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        print(format_summary(summary))
    return 2 if any(d.severity >= Severity.ERROR for d in diags) else 0
