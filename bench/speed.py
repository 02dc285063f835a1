"""Every speed figure in one run, each beside its floor or its goal, as a table.

    .venv/bin/python bench/speed.py [--seconds S] [--rounds R] [--frames N]

- PyBullet loop (suturing set, 1 kHz physics, no frames) against the bare ``stepSimulation``
  floor of the same loaded scene, alternated ``--rounds`` times (medians);
- MuJoCo engine on the same scene: the first S seconds (the thread settling, every tree
  awake) and the next S (resting trees asleep) in chunks alternated with bare ``mj_step``
  chunks from the same state (the floor);
- a stereo frame (both cameras, RGB + depth + segmentation) with each renderer of the PyBullet
  world (TinyRenderer, PyBullet's EGL plugin, MuJoCo's renderer on a mirror) and with the
  MuJoCo engine's own cameras, the last alternated with its floor (one RGB pass of camera L):
  medians of N frames after a first one;
- ``adfkit validate`` of the whole corpus (``-j`` default and ``-j 1``) alternated with its
  floor (libyaml alone), and ``adfkit --help``: fresh processes, start-up included, medians of 5.

The suturing set is the corpus's (launch indices 6-11) when ``$ADFKIT_CORPUS`` (else ``../shared/corpus``) is there, else
the project's bundled suturing scene. Asserts nothing; prints figures.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORPUS = Path(os.environ.get("ADFKIT_CORPUS", ROOT.parent / "shared" / "corpus"))


def scene_and_label():
    from adfkit.adf import load_scene

    launch = CORPUS / "src" / "launch.yaml"
    if launch.is_file():
        return load_scene(launch, [6, 7, 8, 9, 10, 11]), "corpus suturing set (launch -l 6-11)"
    return load_scene(ROOT / "sample_scenes" / "suturing" / "launch.yaml"), "bundled suturing scene"


def pybullet_loop(scene, seconds: float, rounds: int) -> dict:
    """The loop and its bare floor as real-time factors, in wall time and in this process's CPU
    time (which a loaded machine disturbs less): bench/run_suturing.py's alternated rounds."""
    sys.path.insert(0, str(ROOT / "bench"))
    from run_suturing import measure

    m = measure(scene, {}, seconds, rounds)
    return {"wall": m["wall"], "cpu": m["cpu"]}


def mujoco_loop(scene, seconds: float) -> dict:
    """The first window, the next window and the bare floor as real-time factors, in wall and
    CPU time. The next window alternates chunks of 0.1 s of the engine's loop and of bare
    ``mj_step`` from where the loop left the scene, so that both see the same machine load and
    the same sleeping trees."""
    import mujoco

    from adfkit.runner import Options
    from adfkit.runner.mujoco.world import MujocoWorld

    clocks = (time.perf_counter, time.process_time)
    world = MujocoWorld(scene, Options())
    try:
        start = [c() for c in clocks]
        world.run(seconds)
        first = [world.sim_time / (c() - s) for c, s in zip(clocks, start)]
        m, d = world.model, world.data
        sub = world.opt.control_substeps
        k = max(1, int(round(0.1 / (world.dt * sub))))  # control steps a chunk
        chunks = max(1, int(round(seconds / (k * sub * world.dt))))
        loop, bare = [0.0, 0.0], [0.0, 0.0]
        for _ in range(chunks):
            t0 = [c() for c in clocks]
            world.step(k)
            t1 = [c() for c in clocks]
            mujoco.mj_step(m, d, k * sub)
            t2 = [c() for c in clocks]
            for i in range(2):
                loop[i] += t1[i] - t0[i]
                bare[i] += t2[i] - t1[i]
        simulated = chunks * k * sub * world.dt
    finally:
        world.close()
    return {
        "wall": (first[0], simulated / loop[0], simulated / bare[0]),
        "cpu": (first[1], simulated / loop[1], simulated / bare[1]),
    }


def stereo_ms(make_world, frames: int) -> float | str:
    try:
        world = make_world()
    except Exception as exc:  # noqa: BLE001 - a renderer that cannot start here is a table cell, not a crash
        return f"n/a ({type(exc).__name__})"
    try:
        world.run(0.1)
        cams = world.cameras
        for c in cams:
            c.render(world)
        times = []
        for _ in range(frames):
            t = time.perf_counter()
            for c in cams:
                c.render(world)
            times.append(time.perf_counter() - t)
        used = getattr(world, "renderer", "mujoco engine")
        return f"{1e3 * statistics.median(times):.1f} ms ({used}, {len(cams)} x {cams[0].width}x{cams[0].height})"
    finally:
        world.close()


def engine_frame_and_pass(scene, frames: int) -> tuple[str, float | None]:
    """The MuJoCo engine's stereo frame (both cameras, RGB + depth + segmentation) and its floor,
    one software-rendered RGB pass of camera L at its own size in the same GL context
    (``mjv_updateScene`` + ``mjr_render`` + ``mjr_readPixels`` of the colour buffer; no depth,
    no segmentation pass, no conversion), alternated frame by frame in one world so that both
    see the same load: (the frame's cell, the pass in ms or None), medians after a first one."""
    import mujoco
    import numpy as np

    from adfkit.runner.mujoco.world import MujocoWorld
    from adfkit.runner.options import Options

    try:
        world = MujocoWorld(scene, Options())
        world.run(0.1)
        r = world._renderer()
    except Exception as exc:  # noqa: BLE001 - a table cell, not a crash
        return f"n/a ({type(exc).__name__})", None
    try:
        cams = world.cameras
        cam = cams[0]
        m, d = world.model, world.data
        rect = mujoco.MjrRect(0, 0, cam.width, cam.height)
        rgb = np.empty((cam.height, cam.width, 3), dtype=np.uint8)

        def one_pass():
            r.gl.make_current()
            r.cam.fixedcamid = cam.cam_id
            mujoco.mjv_updateScene(m, d, r.opt, r.pert, r.cam, mujoco.mjtCatBit.mjCAT_ALL, r.scene)
            mujoco.mjr_render(rect, r.scene, r.ctx)
            mujoco.mjr_readPixels(rgb, None, rect, r.ctx)

        stereo, passes = [], []
        for i in range(frames + 1):
            t = time.perf_counter()
            for c in cams:
                c.render(world)
            t1 = time.perf_counter()
            one_pass()
            if i:
                stereo.append(t1 - t)
                passes.append(time.perf_counter() - t1)
        cell = f"{1e3 * statistics.median(stereo):.1f} ms (mujoco engine, {len(cams)} x {cam.width}x{cam.height})"
        return cell, 1e3 * statistics.median(passes)
    finally:
        world.close()


LIBYAML_ALONE = (
    "import sys, yaml, pathlib\n"
    "for p in sorted(pathlib.Path(sys.argv[1]).rglob('*')):\n"
    "    if p.suffix in ('.yaml', '.yml') and p.is_file():\n"
    "        try: yaml.load(p.read_text(encoding='utf-8', errors='replace'), Loader=yaml.CSafeLoader)\n"
    "        except Exception: pass\n"
)


def validate_and_floor_ms(folder: Path, runs: int = 5) -> tuple[float, float, float]:
    """(``adfkit validate folder`` with ``-j`` default, with ``-j 1``, parsing every YAML file
    under ``folder`` with libyaml alone (``yaml.load`` with ``CSafeLoader``): the floor), each in
    a fresh process, start-up included, alternated run by run so that all three see the same
    load: medians in ms."""
    commands = (
        [sys.executable, "-m", "adfkit", "validate", str(folder), "-f", "json"],
        [sys.executable, "-m", "adfkit", "validate", str(folder), "-f", "json", "-j", "1"],
        [sys.executable, "-c", LIBYAML_ALONE, str(folder)],
    )
    times: list[list[float]] = [[], [], []]
    for _ in range(runs):
        for cmd, out in zip(commands, times):
            t = time.perf_counter()
            subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            out.append(time.perf_counter() - t)
    jobs, one, floor = (1e3 * statistics.median(t) for t in times)
    return jobs, one, floor


def _ms(cell) -> float | None:
    """The milliseconds at the start of a stereo_ms cell, None for 'n/a'."""
    try:
        return float(str(cell).split(" ")[0])
    except ValueError:
        return None


def cli_ms(args: list[str], runs: int = 5) -> float:
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        subprocess.run([sys.executable, "-m", "adfkit", *args], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        times.append(time.perf_counter() - t)
    return 1e3 * statistics.median(times)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--frames", type=int, default=10)
    args = ap.parse_args()
    from adfkit.runner import Options, open_world

    scene, label = scene_and_label()
    print(f"scene: {label}; {args.seconds:g} s windows, {args.rounds} rounds, {args.frames} frames")
    rows = []
    pb_loop = pybullet_loop(scene, args.seconds, args.rounds)
    loop, floor = pb_loop["wall"]
    loop_cpu, floor_cpu = pb_loop["cpu"]
    rows.append(
        (
            "PyBullet loop / bare stepSimulation floor",
            f"{loop:.2f}x / {floor:.2f}x real time, ratio {loop / floor:.3f} (CPU {loop_cpu / floor_cpu:.3f})",
            ">= 2.2x, ratio >= 0.93",
        )
    )
    mj = mujoco_loop(scene, args.seconds)
    first, settled, mfloor = mj["wall"]
    first_cpu, settled_cpu, mfloor_cpu = mj["cpu"]
    rows.append(("MuJoCo engine, first window (thread settling)", f"{first:.2f}x real time", ">= 10x"))
    rows.append(
        ("MuJoCo first window / PyBullet loop", f"{first / loop:.2f}x (CPU {first_cpu / loop_cpu:.2f}x)", ">= 5x")
    )
    rows.append(
        (
            "MuJoCo engine, next window / bare mj_step floor",
            f"{settled:.2f}x / {mfloor:.2f}x, ratio {settled / mfloor:.3f} (CPU {settled_cpu / mfloor_cpu:.3f})",
            ">= 10x, ratio >= 0.95",
        )
    )
    for renderer in ("tiny", "egl", "mujoco"):
        rows.append(
            (
                f"stereo frame, PyBullet world, renderer={renderer}",
                stereo_ms(lambda: open_world(scene, Options(renderer=renderer)), args.frames),
                "<= 60 ms",
            )
        )
    engine_frame, one = engine_frame_and_pass(scene, args.frames)
    rows.append(("stereo frame (RGB + depth + seg), MuJoCo engine", engine_frame, "<= 15 ms"))
    if one is not None and _ms(engine_frame) is not None:
        rows.append(
            (
                "  / one software RGB pass of camera L (bare mjr_render)",
                f"{_ms(engine_frame) / one:.2f}x ({one:.1f} ms a pass)",
                "<= 2x",
            )
        )
    if CORPUS.is_dir():
        val, one_proc, floor_ms = validate_and_floor_ms(CORPUS)
        rows.append(("adfkit validate corpus/ (CLI, start-up included)", f"{val:.0f} ms", "< 1000 ms"))
        rows.append(("adfkit validate corpus/ -j 1 (one process)", f"{one_proc:.0f} ms", ""))
        rows.append(
            (
                "  / parsing the same files with libyaml alone (fresh process)",
                f"{val / floor_ms:.2f}x, -j 1 {one_proc / floor_ms:.2f}x ({floor_ms:.0f} ms)",
                "<= 1.6x",
            )
        )
    rows.append(("adfkit --help", f"{cli_ms(['--help'], 9):.0f} ms", "< 80 ms"))
    width = max(len(r[0]) for r in rows)
    for name, value, goal in rows:
        print(f"{name:<{width}}  {value:<58}  {goal}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
