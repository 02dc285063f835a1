"""Real-time factor of the suturing set (launch indices 6–11) headless; prints figures."""
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
    ap.add_argument("--seconds", type=float, default=5.0)
    ap.add_argument("--control-substeps", type=int, nargs="*", default=[1, 4, 8])
    args = ap.parse_args()
    from adfkit.adf import load_scene
    from adfkit.runner.world import Options, SimWorld
    launch = CORPUS / "src" / "launch.yaml"
    if not launch.is_file():
        print(f"corpus not found at {launch}", file=sys.stderr)
        return 2
    for sub in args.control_substeps:
        t0 = time.perf_counter()
        world = SimWorld(load_scene(launch, [6, 7, 8, 9, 10, 11]), Options(control_substeps=sub, visuals=False))
        build = time.perf_counter() - t0
        world.run(args.seconds)
        r = world.report()
        print(f"control every {sub} physics step(s) at 1 kHz: build {build:.2f} s, "
              f"{r['steps'] / r['wall_time_s']:.0f} physics steps/s, real-time factor {r['real_time_factor']:.2f}x, "
              f"max constraint error {r['max_constraint_error_m'] * 1e3:.4f} mm, "
              f"unstable bodies {len(r['nan']) + len(r['exploded']) + len(r['fell_through_floor'])}")
        world.close()
    print(f"peak memory {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
