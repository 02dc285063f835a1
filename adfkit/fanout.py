"""Many episodes (or files) at once on Ray: each one a Ray task over the same function one
process would call, one seed per episode, results merged by the caller into one index. A task
that fails (an exception, or its worker process killed) is retried once on a fresh worker and
reported; none is lost: the index lists every seed with its outcome.

Local Ray by default (``num_cpus=workers``); ``address="ray://host:10001"`` or ``"auto"`` joins
a cluster (README: "Gymnasium and Ray").
"""
from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Callable

RETRIES = 1


def _ray():
    try:
        import ray
    except ImportError as exc:
        raise ImportError("fan-out needs Ray: pip install 'adfkit[ray]'") from exc
    return ray


def start(workers: int, address: str | None = None):
    """Connect to Ray (start a local instance with ``workers`` CPUs unless ``address`` names a
    cluster); returns the ray module. A running connection is reused."""
    ray = _ray()
    if not ray.is_initialized():
        kw = dict(include_dashboard=False, log_to_driver=False, configure_logging=False)
        if address:
            ray.init(address=address, **kw)
        else:
            ray.init(num_cpus=max(1, int(workers)), **kw)
    return ray


def fan_out(fn: Callable, jobs: list, workers: int = 2, address: str | None = None,
            progress: Callable | None = None) -> list[dict]:
    """Run ``fn(job)`` for every job as Ray tasks (at most ``workers`` at a time on a local
    Ray). Returns, in the jobs' order, {"job", "ok", "attempts", "result" | "error"}; a job
    that failed is run once more before it is reported failed."""
    ray = start(workers, address)
    remote = ray.remote(num_cpus=1, max_retries=0)(fn)
    pending = {remote.remote(job): (i, 1) for i, job in enumerate(jobs)}
    out: list[dict | None] = [None] * len(jobs)
    while pending:
        done, _ = ray.wait(list(pending), num_returns=1)
        ref = done[0]
        i, attempt = pending.pop(ref)
        try:
            out[i] = {"job": jobs[i], "ok": True, "attempts": attempt, "result": ray.get(ref)}
        except Exception as exc:   # a raised error, or a worker that died (ray.exceptions.*)
            if attempt <= RETRIES:
                pending[remote.remote(jobs[i])] = (i, attempt + 1)
                continue
            out[i] = {"job": jobs[i], "ok": False, "attempts": attempt,
                      "error": f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"}
        if progress is not None:
            progress(out[i])
    return out


def write_index(out_dir: Path, runs: list[dict], meta: dict) -> Path:
    """One index.json over every episode: its seed, folder, outcome and metrics."""
    from .adf import atomic_write_text
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    episodes = []
    for r in runs:
        e = {"seed": r["job"]["seed"], "ok": r["ok"], "attempts": r["attempts"]}
        if r["ok"]:
            e.update(r["result"])
        else:
            e["error"] = r["error"]
        episodes.append(e)
    index = {**meta, "episodes": episodes, "failed": [e["seed"] for e in episodes if not e["ok"]],
             "retried": [e["seed"] for e in episodes if e["attempts"] > 1]}
    path = out_dir / "index.json"
    atomic_write_text(path, json.dumps(index, indent=2, allow_nan=False))
    return path


def worker_pid() -> int:
    return os.getpid()
