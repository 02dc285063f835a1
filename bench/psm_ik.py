"""Closed-form PSM IK (adfkit.runner.psm_kinematics): microseconds per call over random
reachable poses, and how many of them reproduce the pose (one FK per candidate)."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))


def main() -> int:
    from adfkit.runner.psm_kinematics import default, pose_error

    k = default()
    rng = np.random.default_rng(0)
    lo, hi = k.lower_limits[:6], k.upper_limits[:6]
    poses = [k.fk(lo + (hi - lo) * rng.random(6)) for _ in range(2000)]
    ok = 0
    t0 = time.process_time()
    for T in poses:
        try:
            k.ik(T)
        except ValueError:
            continue
        ok += 1
    per_ik = (time.process_time() - t0) / len(poses)
    t0 = time.process_time()
    for _pose in poses[:500]:
        k.fk(np.zeros(6))
    per_fk = (time.process_time() - t0) / 500
    worst = max(pose_error(k.fk(k.ik(T, check_limits=False)), T) for T in poses[:200])
    print(
        f"ik: {per_ik * 1e6:.0f} us a call (CPU), {ok}/{len(poses)} random in-limit poses solved, "
        f"worst error {worst:.2g}; fk: {per_fk * 1e6:.0f} us a call"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
