"""A digest of the poses `adfkit run` plays on the suturing set, to show that a speed change of the
PyBullet runner at run settings keeps the physics bit for bit: every body's position, orientation,
linear and angular velocity after every control step, under the options `adfkit run` and `adfkit
parity` use (AMBF's ghosts, springs, bodies, the file's link shapes), hashed (SHA-256) in order.

    .venv/bin/python bench/run_digest.py [--steps 2000]

The scene is the corpus suturing set (launch -l 6-11) when ``$ADFKIT_CORPUS`` (else
``../shared/corpus``) is there, else the bundled suturing scene. Prints the digest, the control
steps and this process's CPU time of the stepping; run it before and after a change: the same
digest means the same trajectory to the last bit. Asserts nothing.
"""

from __future__ import annotations

import argparse
import hashlib
import struct
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "bench")]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=2000, help="control steps (4 ms each)")
    a = ap.parse_args()

    from runner_cpu import options, run_defaults
    from speed import scene_and_label

    from adfkit.runner import open_world

    scene, label = scene_and_label()
    world = open_world(scene, options(run_defaults()), engine="pybullet")
    h = hashlib.sha256()
    cpu = 0.0
    try:
        for _ in range(a.steps):
            c0 = time.process_time()
            world.step(1)
            cpu += time.process_time() - c0
            for sb in world.bodies:
                p, q, v, w = sb.state()
                h.update(struct.pack("<13d", *p, *q, *(v or (0, 0, 0)), *(w or (0, 0, 0))))
    finally:
        world.close()
    print(f"{label}: digest {h.hexdigest()[:16]}  control steps {a.steps}  CPU of the stepping {cpu:.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
