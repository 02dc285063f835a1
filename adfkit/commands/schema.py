"""`adfkit schema KIND`: print the JSON Schema of an ADF file kind (for editors and CI)."""

from __future__ import annotations

import sys

NAME = "schema"
HELP = "print the JSON Schema (draft 2020-12) of an ADF file kind"
KINDS = ["launch", "world", "input_devices", "model", "colors"]


def add_arguments(p) -> None:
    p.add_argument("kind", choices=KINDS, help="file kind")
    p.add_argument("--path", action="store_true", help="print the installed schema file's path instead")


def run(args) -> int:
    from ..adf_schema import schema_file

    f = schema_file(args.kind)
    if args.path:
        print(f)
    else:
        sys.stdout.write(f.read_text(encoding="utf-8"))
    return 0
