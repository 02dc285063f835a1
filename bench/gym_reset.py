"""How long a Gymnasium reset takes, exact (a fresh world restored from the snapshot, the default)
and in place (``exact_reset=False``), and how far apart two runs of the same seed and actions end
up each way (the needle's position, m).

    python bench/gym_reset.py [--env adfkit/NeedleReach-v0] [--obs-mode state] [--resets 10] [--steps 10]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--env", default="adfkit/NeedleReach-v0")
    ap.add_argument("--obs-mode", default="state")
    ap.add_argument("--resets", type=int, default=10)
    ap.add_argument("--steps", type=int, default=10)
    args = ap.parse_args()
    import gymnasium as gym
    import numpy as np

    import adfkit.gym  # noqa: F401

    for exact in (True, False):
        env = gym.make(args.env, obs_mode=args.obs_mode, exact_reset=exact)
        rng = np.random.default_rng(0)
        actions = [rng.uniform(-1, 1, env.action_space.shape).astype(np.float32) for _ in range(args.steps)]
        times, runs = [], []
        for _ in range(args.resets):
            t = time.perf_counter()
            env.reset(seed=5)
            times.append(time.perf_counter() - t)
            needle = []
            for a in actions:
                obs, *_ = env.step(a)
                needle.append(obs["needle_pose"][:3].astype(float))
            runs.append(np.array(needle))
        spread = max(float(np.abs(r - runs[0]).max()) for r in runs)
        print(
            f"{args.env} obs_mode={args.obs_mode} exact_reset={exact}: reset median "
            f"{statistics.median(times) * 1e3:.1f} ms (min {min(times) * 1e3:.1f}, max {max(times) * 1e3:.1f}); "
            f"needle after {args.steps} steps, {args.resets} runs of seed 5: spread {spread:.2e} m"
        )
        env.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
