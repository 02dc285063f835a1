"""Where the time of the speed figures goes (bench/speed.py measures them), by cProfile: the
PyBullet loop, the MuJoCo engine while the thread settles and after, the MuJoCo engine's stereo
frame and ``adfkit validate -j 1`` in process. For each, the share of the engine's own calls
(or libyaml's) against adfkit's Python, then the heaviest functions by their own time.

    .venv/bin/python bench/profile_speed.py [--seconds S] [--top N]

cProfile adds its own cost to every Python call (not to the engines' C calls), so the Python
shares printed here are upper bounds. Prints figures, asserts nothing.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

# the calls that are an engine's own work: a C function of pybullet or mujoco, and PyYAML's
# compose, whose own time is libyaml's C parser and composer
ENGINE_CALLS = (".stepSimulation>", ".mj_step>", ".mjr_render>", ".mjr_readPixels>")


# PyBullet's per-body queries and forces, one call per body (it has no batched form for them)
PER_BODY_CALLS = tuple(
    f"pybullet.{n}>"
    for n in (
        "getBasePositionAndOrientation",
        "getBaseVelocity",
        "getLinkStates",
        "applyExternalTorque",
        "applyExternalForce",
        "getAABB",
        "getOverlappingObjects",
        "getClosestPoints",
        "multiplyTransforms",
        "resetBasePositionAndOrientation",
    )
)


def _engine(file: str, name: str) -> bool:
    if file == "~":
        return any(name.endswith(e) for e in ENGINE_CALLS)
    return name == "compose" and file.endswith(str(Path("yaml") / "__init__.py"))


def summary(title: str, prof: cProfile.Profile, top: int) -> None:
    st = pstats.Stats(prof)
    total = sum(v[2] for v in st.stats.values())  # own time of every function
    rows = sorted(st.stats.items(), key=lambda kv: kv[1][2], reverse=True)
    engine = sum(v[2] for (file, _, name), v in st.stats.items() if _engine(file, name))
    per_body = sum(v[2] for (file, _, name), v in st.stats.items() if file == "~" and name.endswith(PER_BODY_CALLS))
    print(
        f"\n== {title}: {total:.2f} s profiled; the engine's own calls {100 * engine / total:.0f} %"
        + (f", PyBullet's per-body calls {100 * per_body / total:.0f} %" if per_body else "")
    )
    for (file, line, name), (_cc, nc, tt, _ct, _callers) in rows[:top]:
        where = name if file == "~" else f"{Path(file).name}:{line}({name})"
        print(f"  {100 * tt / total:5.1f} %  {tt * 1e3:8.1f} ms  {nc:>8} calls  {where}")


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--top", type=int, default=10)
    args = ap.parse_args()
    from speed import CORPUS, scene_and_label

    from adfkit.runner import Options, open_world
    from adfkit.runner.mujoco.world import MujocoWorld

    scene, label = scene_and_label()
    print(f"scene: {label}; {args.seconds:g} s windows")

    world = open_world(scene, Options(visuals=False))
    try:
        world.run(0.05)
        n = int(round(args.seconds / (world.dt * world.opt.control_substeps)))
        prof = cProfile.Profile()
        prof.runcall(world.step, n)
        summary("PyBullet loop (world.step)", prof, args.top)
    finally:
        world.close()

    world = MujocoWorld(scene, Options())
    try:
        prof = cProfile.Profile()
        prof.runcall(world.run, args.seconds)
        summary("MuJoCo engine, first window (the thread settling)", prof, args.top)
        prof = cProfile.Profile()
        prof.runcall(world.run, args.seconds)
        summary("MuJoCo engine, next window (resting trees asleep)", prof, args.top)
        try:
            for c in world.cameras:
                c.render(world)

            def frames():
                for _ in range(10):
                    for c in world.cameras:
                        c.render(world)

            prof = cProfile.Profile()
            prof.runcall(frames)
            summary("MuJoCo engine, 10 stereo frames (RGB + depth + segmentation)", prof, args.top)
        except Exception as exc:  # noqa: BLE001 - no headless OpenGL here: say so, go on
            print(f"\n== MuJoCo stereo frames: n/a ({type(exc).__name__}: {exc})")
    finally:
        world.close()

    if CORPUS.is_dir():
        from adfkit.validator import engine

        files, _ = engine.expand([str(CORPUS)])
        prof = cProfile.Profile()
        prof.runcall(engine.validate_files, files)
        summary("adfkit validate corpus/ -j 1, in process (no start-up)", prof, args.top)
    return 0


if __name__ == "__main__":
    sys.exit(main())
