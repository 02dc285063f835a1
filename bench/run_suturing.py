"""Real-time factor of the suturing set (launch indices 6–11) headless at 1 kHz physics, steps
per second and peak memory, for the runner's default settings and the faster ones."""
from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT.parent / "shared" / "corpus"

SETTINGS = [  # (label, Options keywords)
    ("default: control every 4 steps, 10 solver iterations", {}),
    ("control every step", {"control_substeps": 1}),
    ("PyBullet's 50 solver iterations", {"solver_iterations": 50}),
    ("contact threshold 1 mm", {"contact_threshold": 0.001}),
    ("contact threshold 1 mm, control every 8 steps", {"contact_threshold": 0.001, "control_substeps": 8}),
]


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=5.0)
    args = ap.parse_args()
    from adfkit.adf import load_scene
    from adfkit.runner.world import Options, SimWorld
    launch = CORPUS / "src" / "launch.yaml"
    if not launch.is_file():
        print(f"corpus not found at {launch}", file=sys.stderr)
        return 2
    scene = load_scene(launch, [6, 7, 8, 9, 10, 11])
    for label, kw in SETTINGS:
        t0 = time.perf_counter()
        world = SimWorld(scene, Options(visuals=False, **kw))
        build = time.perf_counter() - t0
        world.run(args.seconds)
        r = world.report()
        print(f"{label}: build {build:.2f} s, {r['steps'] / r['wall_time_s']:.0f} physics steps/s, "
              f"real-time factor {r['real_time_factor']:.2f}x (goal 5x), "
              f"max constraint error {r['max_constraint_error_m'] * 1e3:.4f} mm, "
              f"unstable bodies {len(r['nan']) + len(r['exploded']) + len(r['fell_through_floor'])}")
        world.close()
    print(f"peak memory {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
