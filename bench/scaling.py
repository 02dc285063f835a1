"""How cost grows as the work grows: each figure at three or more sizes, with the fitted
exponent of cost against size (log-log least squares; 1.0 is linear).

    .venv/bin/python bench/scaling.py [--quick] [--only validate,run,convert,suture,record] [--plot FILE]

- ``validate``: ``adfkit validate`` (CLI, fresh process, start-up included) over 1x, 4x and 16x
  copies of the corpus's ADF files (the bundled sample scenes without the corpus);
- ``run``: a chain of 10, 100 and 1,000 boxes joined by each joint type, played in PyBullet and
  in MuJoCo: wall seconds per simulated second, the world's build timed apart;
- ``convert``: the same chains ADF -> URDF and ADF -> MJCF (in process);
- ``suture``: ``adfkit suture --episodes N --workers W`` for W = 1, 2 (one pair, short), and
  the figure per core; skipped with ``--quick``;
- ``record``: dataset frames per second, stereo RGB + depth + segmentation at 640x480, at
  10, 20 and 40 frames.

Prints a table: size, cost, cost per unit, exponent. ``--plot`` writes the log-log plot.
Asserts nothing.
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT.parent / "shared" / "corpus"
JOINTS = ["revolute", "prismatic", "fixed", "p2p", "six dof spring"]
BUDGET_S = 60.0  # a chain size whose run would take longer than this (by the growth seen) is not run


def exponent(sizes, costs) -> float:
    """Slope of log(cost) against log(size)."""
    return float(np.polyfit(np.log(sizes), np.log(costs), 1)[0])


def chain_model(n: int, joint: str) -> str:
    """ADF text of a chain of ``n`` 2 cm boxes along x, the first welded to the world (mass 0),
    each joined to the one before by ``joint``, axes along y. Each
    box has a collision group of its own, so no two collide: the cost measured is the joints'."""
    names = [f"L{i}" for i in range(n)]
    out = ["bodies:"] + [f"- BODY {b}" for b in names] + ["joints:"]
    out += [f"- JOINT J{i}" for i in range(1, n)]
    for i, b in enumerate(names):
        out += [
            f"BODY {b}:",
            f"  name: {b}",
            "  mass: " + ("0.0" if i == 0 else "0.01"),
            "  inertia: {ix: 1.0e-6, iy: 1.0e-6, iz: 1.0e-6}",
            "  collision shape: Box",
            "  collision geometry: {x: 0.02, y: 0.01, z: 0.01}",
            f"  collision groups: [{i % 1000}]",  # a group of its own: no self-contact, joints alone
            "  shape: Box",
            "  geometry: {x: 0.02, y: 0.01, z: 0.01}",
            "  location:",
            f"    position: {{x: {0.02 * i:.4f}, y: 0.0, z: 1.0}}",
            "    orientation: {r: 0.0, p: 0.0, y: 0.0}",
        ]
    for i in range(1, n):
        out += [
            f"JOINT J{i}:",
            f"  name: J{i}",
            f"  parent: BODY L{i - 1}",
            f"  child: BODY L{i}",
            f"  type: {joint}",
            "  parent pivot: {x: 0.01, y: 0.0, z: 0.0}",
            "  child pivot: {x: -0.01, y: 0.0, z: 0.0}",
            "  parent axis: {x: 0.0, y: 1.0, z: 0.0}",
            "  child axis: {x: 0.0, y: 1.0, z: 0.0}",
        ]
        if joint == "six dof spring":
            out += ["  stiffness: 10.0", "  damping: 0.1"]
    return "\n".join(out) + "\n"


def _table(title: str, unit: str, rows: list[tuple[str, list[int], list[float]]]) -> list[dict]:
    print(f"\n{title}")
    width = max(len(r[1]) for r in rows)
    print(f"  {'case':34s} " + "  ".join(f"{'size':>6s} {'cost':>9s}" for _ in range(width)) + "   exponent")
    found = []
    for label, sizes, costs in rows:
        cells = "  ".join(f"{s:6d} {c:9.4f}" for s, c in zip(sizes, costs)) + " " * 18 * (width - len(sizes))
        k = exponent(sizes, costs)
        flag = "" if k <= 1.1 else "  <- above 1.1"
        print(f"  {label:34s} {cells}   {k:5.2f}{flag}")
        found.append({"figure": title, "case": label, "sizes": sizes, "costs": costs, "exponent": k, "unit": unit})
    return found


def bench_validate(quick: bool) -> list[dict]:
    src = CORPUS if CORPUS.is_dir() else ROOT / "sample_scenes"
    files = [p for p in src.rglob("*.yaml")] + [p for p in src.rglob("*.yml")]
    sizes, costs = [], []
    for copies in (1, 4) if quick else (1, 4, 16):
        with tempfile.TemporaryDirectory() as tmp:
            for c in range(copies):
                for p in files:
                    dest = Path(tmp) / f"copy{c}" / p.relative_to(src)
                    dest.parent.mkdir(parents=True, exist_ok=True)
                    shutil.copyfile(p, dest)
            best = math.inf
            for _ in range(3):
                t = time.perf_counter()
                subprocess.run(
                    [sys.executable, "-m", "adfkit", "validate", tmp, "-f", "json"],
                    stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL,
                )
                best = min(best, time.perf_counter() - t)
        sizes.append(copies * len(files))
        costs.append(best)
    return _table(
        f"adfkit validate ({'corpus' if src == CORPUS else 'sample scenes'}; files -> s, CLI, best of 3)",
        "s",
        [("validate -f json", sizes, costs)],
    )


def _world(engine: str, path: Path):
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    scene = load_scene(path)
    # no gravity and no sleeping: the chain holds still, so every size does the same work per
    # body (a falling chain whips, and its cost would follow the motion, not the size)
    opt = Options(ground=False, gravity=(0.0, 0.0, 0.0))
    if engine == "mujoco":
        from adfkit.runner.mujoco.world import MujocoWorld

        return MujocoWorld(scene, opt, sleep=False)
    return open_world(scene, opt)


def bench_run(quick: bool, tmp: Path) -> list[dict]:
    from adfkit.diagnostics import AdfError

    sizes = [10, 100] if quick else [10, 100, 1000]
    found, notes = [], []
    for engine in ("pybullet", "mujoco"):
        warm = tmp / "warm.yaml"
        warm.write_text(chain_model(3, "revolute"))
        _world(engine, warm).close()  # imports and first-build caches apart
        rows, builds = [], []
        for joint in JOINTS:
            costs, build_costs, done = [], [], []
            for n in sizes:
                if costs and costs[-1] * (n / done[-1]) ** 3 * 0.1 > BUDGET_S:
                    notes.append(
                        f"  {joint:16s} N={n:5d}: not run (at the cubic growth seen, 0.1 s would take "
                        f"{costs[-1] * (n / done[-1]) ** 3 * 0.1:,.0f} s)"
                    )
                    continue
                path = tmp / f"chain_{joint.replace(' ', '_')}_{n}.yaml"
                path.write_text(chain_model(n, joint))
                t = time.perf_counter()
                try:
                    world = _world(engine, path)
                except AdfError as exc:
                    notes.append(f"  {joint:16s} N={n:5d}: cannot be built: {exc.diagnostics[0].message}")
                    continue
                done.append(n)
                build_costs.append(time.perf_counter() - t)
                try:
                    sim = 0.1 if n >= 1000 else 0.5
                    world.run(0.05)  # first steps (caches, contact pairs) apart
                    t = time.perf_counter()
                    world.run(sim)
                    costs.append((time.perf_counter() - t) / sim)
                    floor, facts = engine_floor(engine, world, sim)
                    notes.append(
                        f"  {joint:16s} N={n:5d}: loop {costs[-1]:9.4f} s/s, bare engine step "
                        f"{floor:9.4f} s/s ({floor / costs[-1]:.0%} of the loop){facts}"
                    )
                finally:
                    world.close()
            rows.append((joint, done, costs))
            builds.append((joint, done, build_costs))
        found += _table(f"adfkit run, {engine}: chain of N bodies (wall s per simulated s)", "s/s", rows)
        print("  where the time goes (the engine's own step on the same loaded world, called bare):")
        print("\n".join(notes))
        notes.clear()
        found += _table(f"world build, {engine}: chain of N bodies (s)", "s", builds)
    return found


def engine_floor(engine: str, world, sim: float) -> tuple[float, str]:
    """Wall seconds per simulated second of the engine's bare step on ``world`` as loaded, and
    what makes it grow: for MuJoCo the DOFs, the depth of the kinematic tree and the filled
    share of the joint-space inertia matrix (a serial chain fills it: its factorisation is then
    dense, which MuJoCo's tree-sparse solver cannot avoid)."""
    steps = max(1, int(round(sim / world.dt)))
    if engine == "mujoco":
        import mujoco

        m, d = world.model, world.data
        t = time.perf_counter()
        mujoco.mj_step(m, d, steps)
        floor = (time.perf_counter() - t) / sim
        depth = 0
        for j in range(m.nv):
            k, n = j, 0
            while k >= 0:
                k, n = m.dof_parentid[k], n + 1
            depth = max(depth, n)
        filled = m.nM / max(1, m.nv * (m.nv + 1) // 2)
        return floor, f"; nv {m.nv}, tree depth {depth}, inertia matrix {filled:.0%} filled, constraints {d.nefc}"
    import pybullet as pb

    steps = max(1, steps // world.opt.control_substeps)  # each call advances control_substeps physics steps
    t = time.perf_counter()
    for _ in range(steps):
        pb.stepSimulation(physicsClientId=world.cid)
    floor = (time.perf_counter() - t) / sim
    return floor, ""


def bench_convert(quick: bool, tmp: Path) -> list[dict]:
    from adfkit.converters import read, write

    sizes = [10, 100] if quick else [10, 100, 1000]
    rows = []
    for fmt in ("urdf", "mjcf"):
        for joint in JOINTS:
            costs = []
            for n in sizes:
                path = tmp / f"conv_{joint.replace(' ', '_')}_{n}.yaml"
                path.write_text(chain_model(n, joint))
                model, _ = read(path)
                t = time.perf_counter()
                write(model, tmp / f"out_{n}.{'urdf' if fmt == 'urdf' else 'xml'}", fmt)
                costs.append(time.perf_counter() - t)
            rows.append((f"ADF -> {fmt.upper()}, {joint}", sizes, costs))
    return _table("adfkit convert of the chains (s, in process)", "s", rows)


def bench_suture(tmp: Path) -> list[dict]:
    rows = []
    for workers in (1, 2):
        out = tmp / f"suture_w{workers}"
        sizes, costs = [], []
        for episodes in (2, 4):
            t = time.perf_counter()
            subprocess.run(
                [
                    sys.executable,
                    "-m",
                    "adfkit",
                    "suture",
                    "--pairs",
                    "1",
                    "--episodes",
                    str(episodes),
                    "--workers",
                    str(workers),
                    "--out",
                    str(out / str(episodes)),
                ],
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
            sizes.append(episodes)
            costs.append(time.perf_counter() - t)
        rows.append((f"suture --episodes N --workers {workers}", sizes, costs))
    found = _table("adfkit suture --episodes N (s, CLI; Ray start-up included)", "s", rows)
    w1, w2 = rows[0][2][-1], rows[1][2][-1]
    print(f"  per core at N = {rows[0][1][-1]}: {w1 / (2 * w2):.2f} of linear speed-up with 2 workers")
    return found


def bench_record(quick: bool) -> list[dict]:
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    scene = load_scene(ROOT / "sample_scenes" / "suturing" / "launch.yaml")
    world = open_world(scene, Options(renderer="auto"))
    try:
        cams = list(world.cameras)
        for cam in cams:  # the renderer's start-up (GL context, mirror) apart
            cam.render(world)
        sizes, costs = [], []
        for frames in (5, 10) if quick else (10, 20, 40):
            t = time.perf_counter()
            for _ in range(frames):
                world.run(1 / 30)
                for cam in cams:
                    cam.render(world)
            sizes.append(frames)
            costs.append(time.perf_counter() - t)
    finally:
        world.close()
    found = _table(
        f"recording: stereo RGB + depth + segmentation, {len(cams)} cameras at their own size, "
        "1/30 s of physics between frames (s)",
        "s",
        [("frames", sizes, costs)],
    )
    print(f"  {sizes[-1] / costs[-1]:.1f} frames per second")
    return found


def plot(found: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    groups = {}
    for f in found:
        groups.setdefault(f["figure"], []).append(f)
    ncols = min(3, len(groups))
    nrows = -(-len(groups) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.6 * ncols, 3.8 * nrows), squeeze=False)
    for ax in axes.flat[len(groups) :]:
        ax.set_visible(False)
    for ax, (title, rows) in zip(axes.flat, groups.items()):
        for r in rows:
            ax.loglog(r["sizes"], r["costs"], "o-", label=f"{r['case']} ({r['exponent']:.2f})")
        s = np.array(rows[0]["sizes"], dtype=float)
        c0 = rows[0]["costs"][0]
        ax.loglog(s, c0 * s / s[0], "k:", label="linear")
        ax.set_title(title.split("(")[0].split(":")[0].strip(), fontsize=9)
        ax.set_xlabel("size")
        ax.set_ylabel(rows[0]["unit"])
        ax.legend(fontsize=5)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    print(f"\nplot: {path}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="smaller sizes; no suture episodes")
    ap.add_argument("--only", default="validate,run,convert,suture,record")
    ap.add_argument("--plot", type=Path, help="write the log-log plot here (PNG)")
    ap.add_argument("--save", type=Path, help="write the figures here (JSON), for --replot")
    ap.add_argument("--replot", type=Path, help="plot figures saved with --save; measure nothing")
    args = ap.parse_args()
    if args.replot:
        plot(json.loads(args.replot.read_text()), args.plot or args.replot.with_suffix(".png"))
        return
    only = set(args.only.split(","))
    found: list[dict] = []
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        if "validate" in only:
            found += bench_validate(args.quick)
        if "run" in only:
            found += bench_run(args.quick, tmp)
        if "convert" in only:
            found += bench_convert(args.quick, tmp)
        if "suture" in only and not args.quick:
            found += bench_suture(tmp)
        if "record" in only:
            found += bench_record(args.quick)
    over = [f for f in found if f["exponent"] > 1.1]
    print(
        f"\n{len(found)} curves; {len(over)} with an exponent above 1.1"
        + "".join(f"\n  {f['figure']}: {f['case']} {f['exponent']:.2f}" for f in over)
    )
    if args.save:
        args.save.write_text(json.dumps(found, indent=1))
    if args.plot:
        plot(found, args.plot)


if __name__ == "__main__":
    main()
