"""The MuJoCo runner under the options `adfkit run` and `adfkit parity` play with (AMBF's
ghost rule, springs, link shapes and bodies; a 4 ms control step): the CPU time of S seconds of
the suturing set, and where it goes.

    .venv/bin/python bench/mujoco_run_speed.py [--seconds S] [--rounds R] [--digest]

Each round builds the world anew and plays S seconds (default 10, the issue's figure) one
control step at a time, as `adfkit parity` does; it prints this process's CPU time (user +
system, which a shared machine disturbs less than the wall clock) and wall time, and splits
the CPU time into MuJoCo's own step (mj_step, timed call by call), the per-control-step Python
(ghosts, damping, sensors: world.control) and the rest of world.step. Medians of R rounds.
``--digest`` also prints the largest distance of any body from where the first round left it
(0 when the rounds agree) and a digest of every body's pose at the end.

The suturing set is the corpus's (launch indices 6-11) when ``../shared/corpus`` is there, else
the project's bundled suturing scene. Asserts nothing; prints figures.
"""

from __future__ import annotations

import argparse
import hashlib
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(1, str(ROOT))  # this tree's adfkit, whichever the environment installed


def run_options():
    """The Options `adfkit parity` builds for a scene without joint commands (session.run)."""
    from adfkit.parity.session import Request
    from adfkit.runner import Options

    req = Request(Path("."), None, None)  # type: ignore[arg-type]
    opt = Options(control_substeps=4, ground=True, visuals=False, renderer="tiny")
    opt.ghosts, opt.springs, opt.link_shapes, opt.bodies = req.ghosts, req.springs, req.link_shapes, req.bodies
    return opt


def one_round(scene, seconds: float) -> dict:
    import mujoco

    from adfkit.runner import open_world

    world = open_world(scene, run_options(), engine="mujoco")
    clock = time.process_time
    engine = [0.0]
    control = [0.0]
    real_step, real_control = mujoco.mj_step, world.control

    def timed_step(m, d, n=1):
        t = clock()
        real_step(m, d, n)
        engine[0] += clock() - t

    def timed_control():
        t = clock()
        real_control()
        control[0] += clock() - t

    mujoco.mj_step = timed_step  # world.step looks it up on each call
    world.control = timed_control
    try:
        n = int(round(seconds / (world.dt * world.opt.control_substeps)))
        c0, w0 = clock(), time.perf_counter()
        for _ in range(n):
            world.step(1)
        cpu, wall = clock() - c0, time.perf_counter() - w0
        d = world.data
        poses = np.hstack([d.xpos, d.xquat])
    finally:
        mujoco.mj_step = real_step
        world.close()
    return {"cpu": cpu, "wall": wall, "mj_step": engine[0], "control": control[0], "poses": poses}


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--digest", action="store_true")
    args = ap.parse_args()
    from speed import scene_and_label

    scene, label = scene_and_label()
    rounds = [one_round(scene, args.seconds) for _ in range(args.rounds)]

    def med(k: str) -> float:
        return statistics.median(r[k] for r in rounds)

    cpu = med("cpu")
    print(f"scene: {label}; adfkit run/parity options, MuJoCo, {args.seconds:g} s, median of {args.rounds}")
    print(f"  CPU {cpu:.3f} s (wall {med('wall'):.3f} s); real-time factor {args.seconds / cpu:.1f}")
    for name, key in (("mj_step (MuJoCo)", "mj_step"), ("control (ghosts, damping, sensors)", "control")):
        print(f"  {name:<36} {med(key):7.3f} s  {100 * med(key) / cpu:4.0f} %")
    rest = cpu - med("mj_step") - med("control")
    print(f"  {'the rest of world.step':<36} {rest:7.3f} s  {100 * rest / cpu:4.0f} %")
    if args.digest:
        first = rounds[0]["poses"]
        spread = max(float(np.max(np.abs(r["poses"][:, :3] - first[:, :3]))) for r in rounds)
        print(
            f"  poses: digest {hashlib.sha1(first.tobytes()).hexdigest()[:12]}, rounds apart by {spread * 1e3:.6f} mm"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
