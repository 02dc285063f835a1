"""How far AMBF stands from itself: a scene played twice in AMBF and in adfkit, the second time
with one body's `location` moved along x (or y, z) by a distance nobody could measure (0.1 µm
unless asked), and each side's largest gap to its own unmoved run beside the gap between the two sides.
Where AMBF's own spread is as large as its gap to adfkit, that gap says nothing about adfkit
(docs/parity.md, "The bundled scene at rest").

    .venv/bin/python bench/ambf_nudged.py LAUNCH [-l N ...] --body NAME [--by 1e-7] [--axis x|y|z]
        [--seconds 2] [--engine pybullet|mujoco]

Prints a markdown table; asserts nothing; skips, with the reason, without an AMBF build.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def nudged_copy(launch: Path, indices: list[int] | None, body: str, by: float, out: Path, axis: str = "x") -> Path:
    """A copy of the scene in ``out`` whose ``BODY body`` (in the model files the launch loads
    with ``indices``) stands ``by`` metres further along ``axis`` of its `location`'s position
    (adfkit.parity.spread.nudged_copy). The copy's launch file. ValueError where none of those
    files, or more than one, places that body."""
    from adfkit.adf import load_scene
    from adfkit.parity.spread import nudged_copy as copy_moving

    models = load_scene(launch, indices, []).all_models()
    found = [Path(m.path).resolve() for m in models if m.path and m.body(f"BODY {body}")]
    if len(found) != 1:
        raise ValueError(f"{len(found)} model files of {launch} place BODY {body}")
    d = tuple(by if a == axis else 0.0 for a in "xyz")
    copy, why = copy_moving(launch, indices, {(found[0], body): d}, out)
    if why:
        raise ValueError(f"BODY {body}: {why[body]}")
    return copy


def _row(label: str, c) -> str:
    pos, ang = c.worst
    if pos is None or ang is None:
        return f"| {label} | no body matched | | 0 of 0 |"
    past = sum(1 for g in c.bodies if g.max_position > c.tolerance_m or g.max_angle > c.tolerance_deg)
    short = lambda g: g.name.rsplit("/", 1)[-1]  # noqa: E731
    return (
        f"| {label} | **{pos.max_position * 1e3:.3f} mm** (`{short(pos)}`) | **{ang.max_angle:.2f}°** (`{short(ang)}`) "
        f"| {past} of {len(c.bodies)} |"
    )


def main(argv: list[str]) -> int:
    from adfkit import inputs
    from adfkit.parity import ambf, session
    from adfkit.parity.compare import compare

    ap = argparse.ArgumentParser(prog="bench/ambf_nudged.py", description=__doc__.split("\n\n")[0])
    ap.add_argument("launch", type=Path)
    ap.add_argument("-l", "--indices", type=int, nargs="+", default=None, help="the launch file's models")
    ap.add_argument("--body", required=True, help="the body moved (its ADF name, e.g. Needle)")
    ap.add_argument("--by", type=float, default=1e-7, help="m along the axis (default 1e-7)")
    ap.add_argument("--axis", choices=("x", "y", "z"), default="x", help="the body's move (default x)")
    ap.add_argument("--seconds", type=float, default=2.0)
    ap.add_argument("--engine", choices=("pybullet", "mujoco"), default="pybullet")
    args = ap.parse_args(argv)
    build, why = ambf.available()
    if build is None:
        print(f"skipped: {why}")
        return 0
    root_env = os.environ.get(inputs.ROOT_ENV)
    with tempfile.TemporaryDirectory(prefix="adfkit-nudged-") as tmp:
        try:
            copy = nudged_copy(args.launch, args.indices, args.body, args.by, Path(tmp), args.axis)
        except ValueError as e:
            print(f"bench/ambf_nudged.py: {e}", file=sys.stderr)
            return 2
        runs = []
        for path in (args.launch, copy):
            req = session.Request(path, args.indices, build, seconds=args.seconds, engines=(args.engine,))
            runs.append(session.run(req, progress=False).comparisons[0])
            # the copy's meshes are links into the original's folders, which adfkit's scene tree
            # (adfkit.inputs) refuses as outside the copy: its runner made no body of a scene whose
            # meshes lie beside the copied files' folders (the corpus puzzles); the tree is the
            # folder both share while the copy plays
            os.environ[inputs.ROOT_ENV] = os.path.commonpath(
                [os.path.realpath(tmp), str(inputs.tree_of(args.launch).root)]
            )
        if root_env is None:
            os.environ.pop(inputs.ROOT_ENV, None)
        else:
            os.environ[inputs.ROOT_ENV] = root_env
    a, b = runs
    print(
        f"{args.launch}, {args.seconds:g} s, BODY {args.body} moved {args.by:g} m along {args.axis} in the second run"
    )
    print("\n| runs compared | largest position gap | largest angle gap | bodies past 1 mm / 1° |\n|---|---|---|---|")
    print(_row("AMBF against adfkit", a))
    print(_row("AMBF against adfkit, nudged", b))
    print(_row("AMBF against AMBF nudged", compare(a.ambf, b.ambf)))
    print(_row(f"adfkit {args.engine} against itself nudged", compare(a.adfkit, b.adfkit)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
