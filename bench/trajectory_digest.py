"""A digest of the suture's whole trajectory, to show that a speed change keeps the physics
bit for bit: every body's pose and velocity and every PSM joint's position after every control
step of a scripted suture, hashed (SHA-256) in order, with the observer, the video frames and
the planner running as in `adfkit suture`.

    .venv/bin/python bench/trajectory_digest.py [--pairs 1] [--seed 0] [--steps N] [--engine pybullet]

Prints the digest, the number of control steps and the wall time; two runs of the same code
print the same digest. Run it before and after a change: the same digest means the same
trajectory to the last bit. Asserts nothing.
"""

from __future__ import annotations

import argparse
import hashlib
import struct
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default=str(ROOT / "sample_scenes" / "suturing" / "launch.yaml"))
    ap.add_argument("-l", "--indices", default=None)
    ap.add_argument("--pairs", type=int, default=1)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--steps", type=int, default=0, help="stop after N control steps (0: the whole episode, with its video)"
    )
    ap.add_argument("--engine", default="pybullet", choices=["pybullet", "mujoco"])
    a = ap.parse_args()

    from adfkit.tasks import episode
    from adfkit.tasks.episode import run_episode

    h = hashlib.sha256()
    count = {"steps": 0}
    real_play = episode.play_task

    def play(world, task, *args, **kw):
        # every control step's state goes into the hash right after the step, before anything
        # else reads it; the episode is otherwise played exactly as `adfkit suture` plays it
        real_step = world.step

        def step(n=1):
            real_step(n)
            for sb in world.bodies:
                p, q, v, w = sb.state()
                h.update(struct.pack("<13d", *p, *q, *(v or (0, 0, 0)), *(w or (0, 0, 0))))
            for psm in getattr(task, "psms", {}).values():
                h.update(struct.pack(f"<{len(psm.measured_jp())}d", *psm.measured_jp()))
            count["steps"] += 1
            if a.steps and count["steps"] >= a.steps:
                raise ValueError("the steps asked for are done")  # ends the episode as a failure would

        world.step = step
        return real_play(world, task, *args, **kw)

    episode.play_task = play
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as out:
        m = run_episode(
            a.scene,
            a.indices,
            list(range(1, a.pairs + 1)),
            seed=a.seed,
            out=None if a.steps else out,  # a cut-short episode has no pictures to write
            progress=False,
            engine=a.engine,
        )
    wall = time.perf_counter() - t0
    passed = [p.get("passed") for p in m.get("pairs", [])]
    print(f"digest {h.hexdigest()}  control steps {count['steps']}  wall {wall:.1f} s  pairs passed {passed}")
    spent = m.get("where_the_time_goes")
    if spent:
        total = m["episode_wall_time_s"]
        print("  where the time goes: " + ", ".join(f"{k[:-2]} {v:.1f} s ({v / total:.0%})" for k, v in spent.items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
