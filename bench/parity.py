"""The parity table: each scene played in AMBF itself (headless, adfkit's AMBF plugin) and in
adfkit, the largest gap of any body over the run and at its end, and each side's stepping time
beside the other's. Prints a markdown table (docs/parity.md); with --plots DIR, draws each scene's
gaps over time there. Asserts nothing; skips, with the reason, without an AMBF build.

    .venv/bin/python bench/parity.py [--plots DIR] [--suture] [--corpus-at-rest] [--json OUT] [--only NAME ...]

Scenes: the project's own (`adfkit build-scene parity`: a dropped box, an arm under position,
velocity and effort commands, a stack of boxes, a cube into a ghost, the thread falling from a
held needle, a slider on its limits, pendulums, primitives dropped tilted on the floor, a ramp,
two boxes on a fixed joint, the arm with a turned inertial frame), the bundled sample scenes at rest and, where the corpus is beside the checkout, the suturing set, the puzzle on AMBF's
own floor (from the AMBF tree), and the KUKA, a PSM, the ECM and the MTM under joint programs (parity.programs);
with --corpus-at-rest, more corpus files AMBF loads (AT_REST), at rest for 1 s in both engines.
With --suture, only the suture replayed in AMBF (``adfkit parity --suture --follow both --pace
both``, 4 pairs, seed 0) on the bundled scene and the corpus set, a row per pair: each side's
verdict (AMBF following adfkit's measured joints, its set-points unpaced and paced), the tip
paths' largest gap in each replay, and the whole episode's stepping time on each side (tens of
minutes on a shared box).
Timings are of a shared 2-core box: noisy; compare AMBF's and adfkit's of one row.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORPUS = Path(os.environ.get("ADFKIT_CORPUS", ROOT.parent / "shared" / "corpus"))


@dataclass
class Scene:
    name: str
    path: Path
    indices: list[int] | None
    seconds: float
    engines: tuple[str, ...] = ("pybullet",)
    commands: Path | None = None
    ghosts: str = "ambf"  # adfkit parity's default
    note: str = ""
    rows: list = field(default_factory=list)
    # each engine in a run of its own, AMBF given that engine's floor (a model played alone: the
    # engines put the floor 1 mm under their own lowest point, MuJoCo under a mesh's lowest vertex);
    # otherwise every side on the first engine's floor
    apart: bool = False


def own_scenes(folder: Path) -> list[Scene]:
    from adfkit.scenes.parity import write_parity

    launch = write_parity(folder)
    both = ("pybullet", "mujoco")
    out = [Scene("box dropped on a slab", launch, [0], 0.5, both)]
    for kind in ("position", "velocity", "effort"):
        out.append(Scene(f"arm, {kind} commands", launch, [1], 1.0, both, commands=folder / f"arm_{kind}.txt"))
    out.append(Scene("three boxes settling in a stack", launch, [2], 1.0, both))
    out.append(Scene("cube into a ghost (AMBF's rule, the default)", launch, [3], 0.6, both))
    out.append(Scene("cube into a ghost (--ghosts hole-friction)", launch, [3], 0.6, ghosts="hole-friction"))
    out.append(Scene("thread falling from a held needle", launch, [4], 2.0, both))
    out.append(Scene("thread falling, its elements at the challenge phantom's inertia", launch, [11], 2.0, both))
    out.append(
        Scene("slider pushed onto its limits by efforts", launch, [5], 1.0, both, commands=folder / "slider_effort.txt")
    )
    out.append(Scene("pendulums on p2p, cone-twist, six-dof and six-dof-spring joints", launch, [6], 1.0, both))
    out.append(Scene("ball, cylinder, capsule and cone dropped tilted on the floor", launch, [7], 1.0, both))
    out.append(Scene("balls and a cylinder sliding down a 25° ramp", launch, [8], 1.0, both))
    out.append(Scene("two boxes on a fixed joint dropped onto an edge", launch, [9], 1.0, both))
    out.append(Scene("a rod, a slider and two links falling into their stops", launch, [10], 1.5, both))
    out.append(
        Scene(
            "arm with a turned inertial frame, position commands",
            folder / "turned_arm.yaml",
            None,
            1.0,
            both,
            commands=folder / "turned_arm_position.txt",
        )
    )
    return out


def sample_scenes() -> list[Scene]:
    """adfkit's bundled sample scenes (sample_scenes/, written by `adfkit build-scene`), left
    alone: they must stand still in AMBF as in adfkit."""
    both = ("pybullet", "mujoco")
    root = ROOT / "sample_scenes"
    return [
        Scene(f"sample scene {name} at rest", root / name / "launch.yaml", None, 1.0, both)
        for name in ("suturing", "suturing_pad", "soft_phantom", "drilling")
        if (root / name / "launch.yaml").is_file()
    ]


def corpus_scenes(build, folder: Path) -> list[Scene]:
    from adfkit.parity import ambf, programs

    if not CORPUS.is_dir():
        return []
    out = [
        Scene(
            "suturing set (src/launch.yaml -l 6-11)",
            CORPUS / "src" / "launch.yaml",
            [6, 7, 8, 9, 10, 11],
            2.0,
            ("pybullet", "mujoco"),
        )
    ]
    puzzle = CORPUS / "ambf/ambf_models/descriptions/multi-bodies/puzzles/puzzle1.yaml"
    launch = ambf.on_ambfs_floor(build, puzzle, folder)
    if launch is not None:
        out.append(Scene("puzzle 1 on AMBF's checkered floor", launch, [0], 3.0, ("pybullet", "mujoco")))
    both = ("pybullet", "mujoco")
    robots = (
        ("KUKA", CORPUS / "ambf/ambf_models/descriptions/multi-bodies/robots/blender-kuka.yaml", both),
        ("PSM (LND 400006)", CORPUS / "src/ADF/PSMs/LND_400006_SIMPLE/psm1.yaml", both),
        ("ECM (loops)", CORPUS / "ambf/ambf_models/descriptions/multi-bodies/robots/blender-ecm.yaml", both),
        ("MTM (loop)", CORPUS / "ambf/ambf_models/descriptions/multi-bodies/robots/blender-mtm.yaml", both),
    )
    for label, model, engines in robots:
        for kind in ("position", "velocity", "effort"):
            cmd = programs.write_program(model, None, kind, 1.0, folder / f"{model.stem}_{kind}.txt")
            out.append(Scene(f"{label}, {kind} program", model, None, 1.0, engines, commands=cmd))
    return out


def suture_rows(build) -> list[str]:
    """The suture replayed in AMBF (following the measured joints; the set-points unpaced and
    paced) on the bundled scene and the corpus set."""
    from adfkit.commands.suture import parse_pairs
    from adfkit.parity import ambf
    from adfkit.parity.suture import PACE, compare_suture

    scenes = [("bundled", ROOT / "sample_scenes" / "suturing" / "launch.yaml", None)]
    if CORPUS.is_dir():
        scenes.append(("corpus set", CORPUS / "src" / "launch.yaml", [6, 7, 8, 9, 10, 11]))
    rows = []
    for label, launch, indices in scenes:
        count, how = ambf.iterations_for(None, suture=True)  # as `adfkit parity --suture` replays
        with ambf.iterations_set(count) as n:
            out = compare_suture(launch, indices, parse_pairs("1,2,3,4"), build, 0, paces=(None, PACE), follow="both")
        print(f"  ({label}: AMBF's solver iterations {n} a step, {how})", file=sys.stderr)
        measured, plain, paced = out["replays"]
        walls = (
            f"{out['wall_s']['adfkit']:.0f} s | {measured['wall_s']:.0f} s | {plain['wall_s']:.0f} s | "
            f"{paced['wall_s']:.0f} s ({paced['pace']['ambf_simulated_s']:.1f} s played)"
        )
        for p in out["pairs"]:
            rows.append(
                f"| {label} | {p['pair']} | {p['adfkit']} | {p['ambf']}{_rule(p['ambf_rule'])} | "
                f"{p['ambf_unpaced']}{_rule(p['ambf_unpaced_rule'])} | {p['ambf_paced']}{_rule(p['ambf_paced_rule'])} | "
                f"{_mm(p['tip_path_gap_m'])} | {_mm(p['tip_path_gap_unpaced_m'])} | {_mm(p['tip_path_gap_paced_m'])} | "
                f"{walls} |"
            )
        print(f"  ({label}: {out['seconds']:.1f} s episode, {out['commands']} commands)", file=sys.stderr)
    return rows


def _rule(rule) -> str:
    return f" (`{rule}`)" if rule else ""


def _mm(m) -> str:
    return "-" if m is None or m != m else f"{m * 1e3:.1f} mm"


#: corpus files AMBF loads, played at rest for 1 s in both engines (--corpus-at-rest: about two
#: minutes of adfkit stepping on a quiet 2-core box); paths under the corpus's `ambf/`
AT_REST = (
    "ambf_models/descriptions/multi-bodies/robots/blender-ecm.yaml",
    "ambf_models/descriptions/multi-bodies/robots/blender-ecm-springy.yaml",
    "ambf_models/descriptions/multi-bodies/robots/blender-mtm.yaml",
    "ambf_models/descriptions/multi-bodies/robots/blender-mtm-springy.yaml",
    "ambf_models/descriptions/multi-bodies/robots/blender-psm.yaml",
    "ambf_models/descriptions/multi-bodies/robots/blender-psm-springy.yaml",
    "ambf_models/descriptions/multi-bodies/robots/blender-kuka-springy.yaml",
    "ambf_models/descriptions/multi-bodies/grippers/resistive/gripper1/gripperA.yaml",
    "ambf_models/descriptions/multi-bodies/grippers/resistive/gripper1/gripperB.yaml",
    "ambf_models/descriptions/multi-bodies/grippers/resistive/gripper3/gripper.yaml",
    "ambf_models/descriptions/multi-bodies/puzzles/puzzle2.yaml",
    "ambf_models/descriptions/multi-bodies/puzzles/puzzle4.yaml",
    "ambf_models/descriptions/multi-bodies/puzzles/puzzle5.yaml",
    "ambf_models/descriptions/multi-bodies/puzzles/puzzle6.yaml",
    "ambf_models/descriptions/multi-bodies/puzzles/parallel_structure.yaml",
    "ambf_controller/raven2/launch.yaml",
)


def corpus_at_rest() -> list[Scene]:
    both = ("pybullet", "mujoco")
    return [
        Scene(
            f"corpus {Path(rel).parent.name}/{Path(rel).name} at rest",
            CORPUS / "ambf" / rel,
            None,
            1.0,
            both,
            apart=True,
        )
        for rel in AT_REST
        if (CORPUS / "ambf" / rel).is_file()
    ]


def main(argv: list[str]) -> int:
    import argparse

    from adfkit.parity import ambf, session

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], prog="bench/parity.py")
    ap.add_argument("--plots", type=Path, metavar="DIR", help="draw each scene's gaps over time there")
    ap.add_argument("--json", type=Path, metavar="OUT", help="write the rows as JSON there too")
    ap.add_argument("--only", nargs="+", default=[], metavar="NAME", help="the scenes whose names hold one of these")
    ap.add_argument("--suture", action="store_true", help="only the suture replayed in AMBF (tens of minutes)")
    ap.add_argument("--corpus-at-rest", action="store_true", help="more corpus files AMBF loads, at rest for 1 s")
    args = ap.parse_args(argv)
    build, why = ambf.available()
    if build is None:
        print(f"skipped: {why}")
        return 0
    plots, out_json, only = args.plots, args.json, args.only
    if args.suture:
        print(
            "| scene | pair | adfkit | AMBF following | AMBF set-points | AMBF paced | tip gap following "
            "| tip gap set-points | tip gap paced | adfkit stepping (episode) | AMBF following | AMBF | AMBF paced |"
        )
        print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        print("\n".join(suture_rows(build)))
        return 0
    os.environ.setdefault("ADFKIT_INPUT_ROOT", "/")  # the puzzle's launch names AMBF's floor and the corpus
    rows, results, tip_rows = [], [], []
    with tempfile.TemporaryDirectory(prefix="adfkit-parity-bench-") as tmp:
        folder = Path(tmp)
        scenes = own_scenes(folder / "own") + sample_scenes() + corpus_scenes(build, folder)
        if args.corpus_at_rest:
            scenes += corpus_at_rest()
        for sc in scenes:
            if only and not any(o.lower() in sc.name.lower() for o in only):
                continue
            t0 = time.perf_counter()
            comparisons = []
            for engines in [(e,) for e in sc.engines] if sc.apart else [sc.engines]:
                req = session.Request(
                    sc.path, sc.indices, build, seconds=sc.seconds, every=0.02, engines=engines,
                    commands=sc.commands, ghosts=sc.ghosts,
                )  # fmt: skip
                out = session.run(req, progress=False)
                comparisons += out.comparisons
            wall = time.perf_counter() - t0
            if plots is not None:
                from adfkit.parity.plot import plot_gaps

                plots.mkdir(parents=True, exist_ok=True)
                slug = "".join(c if c.isalnum() else "-" for c in sc.name.lower()).strip("-")
                while "--" in slug:
                    slug = slug.replace("--", "-")
                plot_gaps(comparisons, plots / f"parity-{slug}.png", sc.name, top=5)
            for c in comparisons:
                pos, ang = c.worst
                end = max(c.bodies, key=lambda g: g.position[-1]) if c.bodies else None
                row = {
                    "scene": sc.name,
                    "engine": c.adfkit.side,
                    "seconds": sc.seconds,
                    "control_ms": out.request.control_substeps,
                    "max_mm": pos.max_position * 1e3 if pos else 0.0,
                    "max_body": pos.name if pos else "",
                    "max_deg": ang.max_angle if ang else 0.0,
                    "end_mm": end.position[-1] * 1e3 if end else 0.0,
                    "end_deg": max((g.angle[-1] for g in c.bodies), default=0.0),
                    "ambf_s": c.ambf.wall_s,
                    "adfkit_s": c.adfkit.wall_s,
                    "agree": not c.failures(),
                    "made_alike": not (c.only_in_ambf or c.only_in_adfkit),
                }
                tips = c.tip_gaps
                if tips:  # a driven scene's tool tips (the issue's 0.5 mm for a driven tool tip)
                    tip = max(tips, key=lambda g: g.max_position)
                    row["tip_mm"], row["tip_body"] = tip.max_position * 1e3, tip.name
                    names = ", ".join("`" + g.name.rsplit("/", 1)[-1] + "`" for g in tips)
                    tip_rows.append(
                        f"| {sc.name} | {row['engine']} | {names} | "
                        f"**{row['tip_mm']:.2f} mm** (`{tip.name.rsplit('/', 1)[-1]}`) | "
                        f"{'within' if row['tip_mm'] <= 0.5 else 'past'} |"
                    )
                results.append(row)
                rows.append(
                    f"| {sc.name} | {row['engine']} | {sc.seconds:g} s | **{row['max_mm']:.2f} mm** "
                    f"(`{row['max_body'].rsplit('/', 1)[-1]}`), {row['max_deg']:.2f}° | {row['end_mm']:.2f} mm, "
                    f"{row['end_deg']:.2f}° | {row['ambf_s']:.2f} s | {row['adfkit_s']:.2f} s | "
                    f"{'agree' if row['agree'] else 'differ'} |"
                )
            print(f"  ({sc.name}: {wall:.0f} s in all)", file=sys.stderr)
    print(
        "| scene | adfkit | played | largest gap over the run | at the end | AMBF stepping | adfkit stepping | 1 mm / 1° |"
    )
    print("|---|---|---|---|---|---|---|---|")
    print("\n".join(rows))
    if tip_rows:
        print("\n| scene | adfkit | tool tips | largest tip gap over the run | 0.5 mm |")
        print("|---|---|---|---|---|")
        print("\n".join(tip_rows))
    if out_json is not None:
        out_json.write_text(json.dumps(results, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
