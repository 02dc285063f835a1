"""Timing this tree's adfkit against another git revision's, for the benches' ``--against REV``:
REV's ``adfkit`` exported into a temporary folder, each round a fresh process importing one
side's adfkit, the sides alternated round by round (a loaded machine's drift falls on both).
``use_tree`` is what such a process calls first: it refuses an adfkit imported from anywhere
else (an installed one shadowing the tree measured)."""

from __future__ import annotations

import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def alternated(rev: str, rounds: int, one_round: Callable[[str], dict]) -> dict[str, list[dict]]:
    """``one_round(tree)`` (a round in a fresh process importing the adfkit under ``tree``) for
    this tree and REV's, ``rounds`` times each, alternated; by side: "this tree", REV."""
    with tempfile.TemporaryDirectory(prefix="adfkit-against-") as old:
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "adfkit"], check=True, capture_output=True)
        subprocess.run(["tar", "-x", "-C", old], input=archive.stdout, check=True)
        trees = {"this tree": str(ROOT), rev: old}
        got: dict[str, list[dict]] = {name: [] for name in trees}
        for r in range(rounds):
            for name in list(trees)[:: 1 if r % 2 == 0 else -1]:
                got[name].append(one_round(trees[name]))
    return got


def use_tree(tree: str) -> None:
    """Import adfkit from ``tree`` in this process, or exit saying where it came from."""
    sys.path.insert(0, tree)
    import adfkit

    if not Path(adfkit.__file__).resolve().is_relative_to(Path(tree).resolve()):
        raise SystemExit(f"adfkit came from {adfkit.__file__}, not {tree}")
