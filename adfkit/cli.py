"""`adfkit` command line. Each subcommand is a module in ``adfkit.commands`` defining
``NAME``, ``HELP``, ``add_arguments(parser)`` and ``run(args) -> int``; heavy imports
happen inside ``run`` so ``adfkit --help`` stays fast.

Exit status: 0 success, 1 findings/failure the user asked to fail on, 2 usage or input error.
"""

from __future__ import annotations

import argparse
import functools
import importlib
import pkgutil
import sys

from . import __version__
from .diagnostics import AdfError
from .report import print_diagnostics


@functools.lru_cache(maxsize=1)
def build_parser() -> argparse.ArgumentParser:
    """The parser, built once per process (parse_args leaves it unchanged; in-process callers
    such as the fuzz suite and the Gymnasium fan-out call main() many times)."""
    from . import commands

    parser = argparse.ArgumentParser(prog="adfkit", description="Author, validate, convert and play AMBF ADF scenes.")
    parser.add_argument("--version", action="version", version=f"adfkit {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for info in sorted(pkgutil.iter_modules(commands.__path__), key=lambda m: m.name):
        if info.name.startswith("_"):
            continue
        mod = importlib.import_module(f"{commands.__name__}.{info.name}")
        p = sub.add_parser(mod.NAME, help=mod.HELP, description=getattr(mod, "DESCRIPTION", mod.HELP))
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "_run", None):
        parser.print_help()
        return 2
    from . import scratch

    scratch.sweep()  # what a killed command left in $TMPDIR
    try:
        return int(args._run(args) or 0)
    except AdfError as exc:
        print_diagnostics(exc.diagnostics, sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0
    finally:
        scratch.cleanup()  # the command's temporary files


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
