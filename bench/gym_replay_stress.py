"""Replay one seeded episode of a Gymnasium environment many times in one process and say whether
every replay gave the same state and observations bit for bit (tests/test_gym.py's claim, stressed).

Each replay is compared with the first in double precision (every body's pose and velocity after
each step, not only the float32 observations, so a difference too small to move a float32 shows)
and in its observations. ``--churn N`` builds, steps and drops N other worlds between replays (other
memory addresses, other PyBullet client ids, as a full test run does between the gym's tests);
``--threshold M`` makes those worlds with Options(contact_threshold=M) (Bullet holds one threshold
for the process: runner/pybullet/bullet_globals.py).

    python bench/gym_replay_stress.py [--env adfkit/NeedleReach-v0] [--needle 0.004] [--obs-mode state]
        [--replays 50] [--steps 12] [--churn 0] [--threshold M]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def _state(world) -> list:
    """Every body's COM pose and velocity, as PyBullet holds them (doubles)."""
    out = []
    for sb in world.bodies:
        if sb.uid is None or sb.uid < 0:
            continue
        p, q, v, w = sb.state()
        out.append((*p, *q, *(v or ()), *(w or ())))
    return out


def _churn(model, threshold) -> None:
    from adfkit.runner import Options, open_world

    w = open_world(model, Options(visuals=False, contact_threshold=threshold))
    try:
        w.step(5)
    finally:
        w.close()


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--env", default="adfkit/NeedleReach-v0")
    ap.add_argument("--needle", type=float, default=0.004, help="randomize_needle (m)")
    ap.add_argument("--obs-mode", default="state")
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--replays", type=int, default=50)
    ap.add_argument("--steps", type=int, default=12)
    ap.add_argument("--churn", type=int, default=0, help="other worlds built, stepped and dropped between replays")
    ap.add_argument("--threshold", type=float, default=None, help="those worlds' contact threshold (m)")
    args = ap.parse_args()
    import gymnasium as gym
    import numpy as np

    import adfkit.gym  # noqa: F401

    kw = dict(randomize_needle=args.needle, obs_mode=args.obs_mode)
    if args.obs_mode != "state":
        kw.update(image_size=(32, 24), render_mode="rgb_array")
    env = gym.make(args.env, **kw)
    rng = np.random.default_rng(3)
    actions = [rng.uniform(-1, 1, env.action_space.shape).astype(np.float32) for _ in range(args.steps)]
    raw = env.unwrapped

    def play():
        obs, _ = env.reset(seed=args.seed)
        states, seen = [_state(raw.world)], [obs]
        for a in actions:
            obs, *_ = env.step(a)
            states.append(_state(raw.world))
            seen.append(obs)
        return np.array(states, dtype=float), seen

    first, first_obs = play()
    bad = 0
    for i in range(1, args.replays):
        for _ in range(args.churn):
            _churn(raw._model, args.threshold)
        again, obs = play()
        same_obs = all(np.array_equal(x[k], y[k]) for x, y in zip(first_obs, obs) for k in x)
        if not np.array_equal(first, again) or not same_obs:
            bad += 1
            diff = np.abs(first - again).max(axis=(1, 2))
            step = int(np.argmax(diff > 0)) if diff.max() > 0 else -1
            print(
                f"replay {i}: state differs from step {step} (largest {diff.max():.3e}); observations equal: {same_obs}"
            )
    env.close()
    print(
        f"{args.env} obs_mode={args.obs_mode} randomize_needle={args.needle} seed {args.seed}, {args.steps} steps: "
        f"{bad} of {args.replays - 1} replays differ (churn {args.churn}, threshold {args.threshold})"
    )
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
