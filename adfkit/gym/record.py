"""Demonstrations: one scripted-expert episode of an environment, written as one .npz file
(every observation key stacked over time, actions, rewards, success flags). The function a
Ray task runs (adfkit.fanout) and the one a single process calls are the same.

Layout of DIR/episode_<seed>.npz: obs/<key> (T+1, ...), action (T, A), reward (T,),
is_success (T,); DIR/index.json (written by the caller) lists every episode.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

_ENVS: dict = {}  # one environment per worker process and configuration (built once, reset per episode)


def _env(env_id: str, kwargs: dict):
    import gymnasium as gym

    from . import ENVS  # noqa: F401  (registers the environments)

    key = (env_id, tuple(sorted(kwargs.items())))
    if key not in _ENVS:
        _ENVS[key] = gym.make(env_id, **kwargs)
    return _ENVS[key]


def record_episode(job: dict) -> dict:
    """job: {"env", "seed", "out", "kwargs" (env keywords), "kill_once" (a marker path: the
    first worker to run this job kills itself, for the fault-tolerance test)}."""
    from ..fanout import _die_once

    _die_once(job)
    from .experts import expert_for

    t0 = time.perf_counter()
    env = _env(job["env"], dict(job.get("kwargs", {})))
    expert = expert_for(env)
    obs, _ = env.reset(seed=int(job["seed"]))
    expert.reset()
    frames, actions, rewards, success = [obs], [], [], []
    while True:
        a = expert(obs)
        obs, r, term, trunc, info = env.step(a)
        frames.append(obs)
        actions.append(a)
        rewards.append(r)
        success.append(info["is_success"])
        if term or trunc:
            break
    out = Path(job["out"])
    out.mkdir(parents=True, exist_ok=True)
    name = f"episode_{int(job['seed']):05d}.npz"
    arrays = {f"obs/{k}": np.stack([f[k] for f in frames]) for k in frames[0]}
    tmp = out / f".{name}.{os.getpid()}.tmp.npz"
    np.savez_compressed(
        tmp,
        action=np.array(actions, np.float32),
        reward=np.array(rewards, np.float64),
        is_success=np.array(success, bool),
        **arrays,
    )
    os.replace(tmp, out / name)
    return {
        "file": name,
        "steps": len(actions),
        "success": bool(success[-1]) if success else False,
        "return": float(np.sum(rewards)),
        "wall_s": time.perf_counter() - t0,
        "pid": os.getpid(),
    }


def load_episode(path) -> dict:
    """An episode file back as {"obs": {key: array}, "action", "reward", "is_success"}."""
    with np.load(path) as z:
        obs = {k[4:]: z[k] for k in z.files if k.startswith("obs/")}
        return {"obs": obs, **{k: z[k] for k in z.files if not k.startswith("obs/")}}
