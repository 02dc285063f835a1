"""Run a ROS client script (AMBF's ambf_client examples, the challenge's scripts) with the
project's Python and ROS 1 from Debian's packages both visible:

    python -m adfkit.ros.pyrun [--path DIR]... [--ambf-msgs] SCRIPT [ARGS...]

``--path`` puts folders first on sys.path (AMBF's ``ambf_client/python``, the challenge's
``scripts``); ``--ambf-msgs`` adds the ambf_msgs package adfkit generates (msggen.py) for a
client that has none of its own. The script runs as ``__main__``."""

from __future__ import annotations

import argparse
import runpy
import sys


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m adfkit.ros.pyrun", description=__doc__.split("\n\n")[0])
    p.add_argument("--path", action="append", default=[], help="a folder to put first on sys.path")
    p.add_argument("--ambf-msgs", action="store_true", help="use the ambf_msgs that adfkit generates")
    p.add_argument("script")
    p.add_argument("args", nargs=argparse.REMAINDER)
    a = p.parse_args(argv)
    from ..diagnostics import AdfError
    from ..report import print_diagnostics
    from .env import import_ros

    try:
        import_ros()
        if a.ambf_msgs:
            from . import msggen

            msggen.ensure()
    except AdfError as exc:
        print_diagnostics(exc.diagnostics, sys.stderr)
        return 2
    sys.path[:0] = a.path
    sys.argv = [a.script, *a.args]
    runpy.run_path(a.script, run_name="__main__")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
