"""Episodes per second on Ray with 1 and 2 workers : expert demonstrations of
adfkit/NeedlePick-v0 recorded as Ray tasks (adfkit.fanout, the `adfkit dataset` path), one
seed per episode, on a local Ray. Each worker builds its environment once and resets it per
episode, so the figure counts steady-state episodes: a warm-up round (one episode per worker)
runs first and is not timed.

    python bench/episodes_ray.py [--episodes 8] [--env adfkit/NeedlePick-v0] [--address A]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--episodes", type=int, default=8)
    ap.add_argument("--env", default="adfkit/NeedlePick-v0")
    ap.add_argument("--address", default=None)
    args = ap.parse_args()
    import ray

    from adfkit import fanout
    from adfkit.gym.record import record_episode

    rows = []
    for workers in (1, 2):
        fanout.start(workers, args.address)
        with tempfile.TemporaryDirectory() as tmp:
            warm = [{"env": args.env, "seed": 1000 + i, "out": tmp} for i in range(workers * 2)]
            fanout.fan_out(record_episode, warm, workers, args.address)
            jobs = [{"env": args.env, "seed": s, "out": tmp} for s in range(args.episodes)]
            t0 = time.perf_counter()
            runs = fanout.fan_out(record_episode, jobs, workers, args.address)
            wall = time.perf_counter() - t0
        ok = [r for r in runs if r["ok"]]
        steps = sum(r["result"]["steps"] for r in ok)
        pids = len({r["result"]["pid"] for r in ok})
        rows.append((workers, len(ok), wall, len(ok) / wall, steps / wall, pids))
        print(
            f"{workers} worker(s): {len(ok)} episodes in {wall:.1f} s = {len(ok) / wall:.3f} episodes/s, "
            f"{steps / wall:.1f} env steps/s ({pids} worker processes)",
            flush=True,
        )
        ray.shutdown()
    if len(rows) == 2:
        print(f"speed-up 2 vs 1 worker: {rows[1][3] / rows[0][3]:.2f}x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
