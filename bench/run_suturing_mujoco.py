"""The suturing set (launch indices 6-11) in the MuJoCo engine, headless at 1 kHz physics:
real-time factor of MujocoWorld.run, the bare mj_step floor of the same compiled model from the
same state, where the time goes (MuJoCo's own timers), and the stereo frame time (cameraL +
cameraR, each RGB + depth + segmentation) with MuJoCo's renderer. Figures only, no asserts."""

from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT.parent / "shared" / "corpus"


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--frames", type=int, default=10, help="stereo frames to time")
    args = ap.parse_args()
    import mujoco
    import numpy as np

    from adfkit.adf import load_scene
    from adfkit.runner import Options
    from adfkit.runner.mujoco.render import CameraUnavailable
    from adfkit.runner.mujoco.world import MujocoWorld

    launch = CORPUS / "src" / "launch.yaml"
    if not launch.is_file():
        print(f"corpus not found at {launch}", file=sys.stderr)
        return 2
    scene = load_scene(launch, [6, 7, 8, 9, 10, 11])
    t0 = time.perf_counter()
    world = MujocoWorld(scene, Options())
    build = time.perf_counter() - t0
    m, d = world.model, world.data
    print(
        f"model: {m.nbody} bodies, {m.nv} dofs, {m.ngeom} geoms, {m.nu} servos, {m.neq} equalities; build {build:.2f} s"
    )
    world.run(args.seconds)  # the thread settles onto the phantom
    r = world.report()
    first = world.sim_time / world.wall_time
    w0, s0 = world.wall_time, world.sim_time
    world.run(args.seconds)
    r = world.report()
    rtf = (world.sim_time - s0) / (world.wall_time - w0)
    print(
        f"MujocoWorld.run: {first:.2f}x real time over the first {args.seconds:g} s (the thread settling, "
        f"awake), {rtf:.2f}x over the next {args.seconds:g} s ({r['awake_trees']} of {r['trees']} trees awake); "
        f"unstable bodies {len(r['nan']) + len(r['exploded']) + len(r['fell_through_floor'])}"
    )
    # the floor: the same model and state, mj_step only
    for t in d.timer:
        t.duration, t.number = 0.0, 0
    n = int(round(args.seconds * world.opt.physics_hz))
    t1 = time.perf_counter()
    mujoco.mj_step(m, d, n)
    floor = args.seconds / (time.perf_counter() - t1)
    print(
        f"bare mj_step floor from there {floor:.2f}x (ratio {rtf / floor:.2f}); contacts {d.ncon}, "
        f"constraint rows {d.nefc}"
    )
    asleep = MujocoWorld(scene, Options(), sleep=False)
    asleep.run(args.seconds)
    w1, s1 = asleep.wall_time, asleep.sim_time
    asleep.run(args.seconds)
    print(f"without island sleeping: {(asleep.sim_time - s1) / (asleep.wall_time - w1):.2f}x over the same window")
    asleep.close()
    step = d.timer[mujoco.mjtTimer.mjTIMER_STEP]
    per = step.duration / max(step.number, 1)
    parts = []
    for name in ("POS_KINEMATICS", "POS_INERTIA", "POS_COLLISION", "POS_MAKE", "CONSTRAINT", "ADVANCE"):
        t = d.timer[getattr(mujoco.mjtTimer, "mjTIMER_" + name)]
        parts.append(f"{name.lower()} {100 * t.duration / max(t.number, 1) / per:.0f} %")
    print(f"mj_step {per * 1e3:.3f} ms: " + ", ".join(parts))
    t2 = time.perf_counter()
    for _ in range(200):
        world.control()
    print(
        f"control step (hole ghosts' friction) {(time.perf_counter() - t2) / 200 * 1e3:.3f} ms "
        f"per {world.opt.control_substeps} physics steps"
    )
    cams = world.cameras
    try:
        for c in cams:
            c.render(world)  # first frame: context and shaders
        times = []
        for _ in range(args.frames):
            t3 = time.perf_counter()
            for c in cams:
                c.render(world)
            times.append(time.perf_counter() - t3)
        w, h = cams[0].width, cams[0].height
        print(
            f"stereo frame ({len(cams)} cameras {w}x{h}, RGB + depth + segmentation): median "
            f"{np.median(times) * 1e3:.1f} ms, best {min(times) * 1e3:.1f} ms (goal 15 ms)"
        )
    except CameraUnavailable as e:
        print(f"cameras unavailable: {e}")
    world.close()
    print(f"peak memory {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
