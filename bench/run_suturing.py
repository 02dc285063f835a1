"""Real-time factor of the suturing set (launch indices 6–11) headless at 1 kHz physics, side by
side with its floor: the same loaded scene stepping ``stepSimulation`` alone, measured in the
same run. Printed for wall time and for this process's CPU time (the CPU figures
hold on a shared, loaded machine; wall time does not), with the ratio loop/floor (goal ≥ 0.9)
and the cost of one control step and its parts.

Each figure is the median of ``--rounds`` alternations of (full loop, bare floor) on freshly
built worlds, so both see the same machine load.
"""

from __future__ import annotations

import argparse
import resource
import statistics
import sys
import time
import timeit
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT.parent / "shared" / "corpus"

SETTINGS = [  # (label, Options keywords)
    ("default: control every 4 steps, 10 solver iterations", {}),
    ("contact threshold 1 mm", {"contact_threshold": 0.001}),
]


def _timed(fn) -> tuple[float, float]:
    w0, c0 = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - w0, time.process_time() - c0


def measure(scene, kw: dict, seconds: float, rounds: int) -> dict:
    import pybullet as pb

    from adfkit.runner import Options, open_world

    full, bare = [], []
    for _ in range(rounds):
        for kind in ("full", "bare"):
            world = open_world(scene, Options(visuals=False, **kw))
            try:
                world.run(0.05)  # settle: the first steps wake everything up
                n = int(round(seconds / (world.dt * world.opt.control_substeps)))
                if kind == "full":
                    full.append(_timed(lambda: world.step(n)))
                    r = world.report()
                else:
                    cid = world.cid
                    bare.append(_timed(lambda: [pb.stepSimulation(physicsClientId=cid) for _ in range(n)]))
            finally:
                world.close()
    world = open_world(scene, Options(visuals=False, **kw))
    try:
        world.run(0.05)
        cdt = world.dt * world.opt.control_substeps
        parts = {
            name: timeit.timeit(fn, number=300, timer=time.process_time) / 300
            for name, fn in (
                ("springs", lambda: world.springs.apply(cdt)),
                ("hole ghosts", world._update_ghosts),
                ("control step", world.control),
            )
        }
    finally:
        world.close()
    med = lambda xs, i: statistics.median(x[i] for x in xs)  # noqa: E731
    return {
        "wall": (seconds / med(full, 0), seconds / med(bare, 0)),
        "cpu": (seconds / med(full, 1), seconds / med(bare, 1)),
        "report": r,
        "parts": parts,
    }


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    from adfkit.adf import load_scene

    launch = CORPUS / "src" / "launch.yaml"
    if not launch.is_file():
        print(f"corpus not found at {launch}", file=sys.stderr)
        return 2
    scene = load_scene(launch, [6, 7, 8, 9, 10, 11])
    for label, kw in SETTINGS:
        m = measure(scene, kw, args.seconds, args.rounds)
        r = m["report"]
        print(f"{label}:")
        for clock in ("wall", "cpu"):
            loop, floor = m[clock]
            print(
                f"  {clock:4s}: loop {loop:.2f}x real time, bare stepSimulation floor {floor:.2f}x, "
                f"loop/floor {loop / floor:.3f} (goal 0.9)"
            )
        print("  per control step (CPU): " + ", ".join(f"{k} {v * 1e6:.0f} us" for k, v in m["parts"].items()))
        print(
            f"  max constraint error {r['max_constraint_error_m'] * 1e3:.4f} mm, unstable bodies "
            f"{len(r['nan']) + len(r['exploded']) + len(r['fell_through_floor'])}"
        )
    print(f"peak memory {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
