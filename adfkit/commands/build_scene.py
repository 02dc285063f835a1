"""`adfkit build-scene NAME OUT_DIR`: author a sample scene from code."""

from __future__ import annotations

NAME = "build-scene"
HELP = "write one of adfkit's own sample scenes (ADF files) into a folder"


class _SceneNames:
    """The builders' names, imported only when argparse checks or lists them: `adfkit --help`
    never imports adfkit.scenes (77 ms of a 131 ms start-up, issue 17)."""

    def _names(self) -> list[str]:
        from ..scenes import BUILDERS

        return sorted(BUILDERS)

    def __contains__(self, name) -> bool:
        return name in self._names()

    def __iter__(self):
        return iter(self._names())


def add_arguments(p) -> None:
    p.add_argument("name", choices=_SceneNames(), metavar="NAME", help="which scene: %(choices)s")
    p.add_argument("out_dir", help="folder to write the scene into (created if needed)")


def run(args) -> int:
    from ..scenes import BUILDERS

    launch = BUILDERS[args.name](args.out_dir)
    print(f"wrote {args.name} to {args.out_dir} (launch file: {launch})")
    return 0
