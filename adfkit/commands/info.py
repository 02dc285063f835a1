"""`adfkit info PATH [PATH ...]`: a summary of each launch, world, input-devices or model file."""

from __future__ import annotations

import json
import sys

from .. import jsonout
from ..summary import format_summary, summarize

NAME = "info"
HELP = "summarise a launch, world, input-devices or model file"


def add_arguments(p) -> None:
    p.add_argument("path", nargs="+", help="ADF file(s); a folder stands for its launch.yaml")
    p.add_argument(
        "--kind",
        choices=["launch", "world", "input_devices", "model", "colors"],
        help="file kind (detected from the keys by default)",
    )
    p.add_argument("--json", action="store_true", help="print JSON for machines")
    p.add_argument("-l", "--indices", help="for a launch file: load these multibody configs (e.g. 6,7,8 or 6-11)")


def run(args) -> int:
    """Each file's summary in turn (JSON: the summary, or a list of them for several files);
    a file that cannot be read is reported where it stands and the others still summarised.
    Exit 2 when any file had an error."""
    from ..diagnostics import AdfError
    from ..report import print_diagnostics

    several = len(args.path) > 1
    summaries, status = [], 0
    for n, path in enumerate(args.path):
        try:
            summary, code = _one(path, args)
        except AdfError as exc:
            print_diagnostics(exc.diagnostics, sys.stderr)
            summary, code = None, 2
        status = max(status, code)
        if summary is None:
            continue
        summaries.append(summary)
        if not args.json:
            if several:
                print(("\n" if n else "") + f"== {path}")
            print(format_summary(summary))
    if args.json and summaries:
        jsonout.dump(summaries if several else summaries[0], sys.stdout, indent=2)
        sys.stdout.write("\n")
    return status


def _one(path, args) -> tuple[dict | None, int]:
    """(the summary of one file or None, its exit status), its diagnostics printed."""
    from .. import inputs
    from ..adf import load_scene, parse_indices, read_file
    from ..diagnostics import Severity
    from ..report import print_diagnostics

    path = inputs.scene_file(path)  # a folder: its launch.yaml
    if args.indices:
        diags: list = []
        doc = load_scene(path, parse_indices(args.indices), diags)
    else:
        doc, diags = read_file(path, args.kind)
    summary = summarize(doc)
    try:  # a sum of huge masses can overflow: never print `total mass: inf` (or NaN) with exit 0
        json.dumps(summary, allow_nan=False)
    except ValueError:
        from ..diagnostics import SourceLocation, error

        where = getattr(doc, "source", None) or SourceLocation(str(path), 1, 1)
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
        return None, 2
    print_diagnostics(diags, sys.stderr)
    return summary, 2 if any(d.severity >= Severity.ERROR for d in diags) else 0
