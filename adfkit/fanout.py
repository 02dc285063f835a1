"""Many episodes (or files) at once on Ray: each one a Ray task over the same function one
process would call, one seed per episode, results merged by the caller into one index. A task
that fails (an exception, or its worker process killed) is retried once on a fresh worker and
reported; none is lost: the index lists every seed with its outcome.

Local Ray by default (``num_cpus=workers``); ``address="ray://host:10001"`` or ``"auto"`` joins
a cluster (docs/gym-ray.md).
"""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Callable
from pathlib import Path

RETRIES = 1


def _ray():
    try:
        import ray
    except ImportError:
        from .diagnostics import AdfError, error

        raise AdfError(
            error(
                "missing-extra",
                "--workers/--episodes/--address run on Ray, which is not installed",
                None,
                "pip install 'adfkit[ray]'",
            )
        ) from None
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


def fan_out(
    fn: Callable, jobs: list, workers: int = 2, address: str | None = None, progress: Callable | None = None
) -> list[dict]:
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
        except Exception as exc:  # a raised error, or a worker that died (ray.exceptions.*)
            if attempt <= RETRIES:
                pending[remote.remote(jobs[i])] = (i, attempt + 1)
                continue
            cause = getattr(exc, "cause", None) or exc  # a RayTaskError wraps the task's own error
            text = str(cause).strip().splitlines()
            out[i] = {
                "job": jobs[i],
                "ok": False,
                "attempts": attempt,
                "error": f"{type(cause).__name__}: {text[-1] if text else ''}",
            }
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
    index = {
        **meta,
        "episodes": episodes,
        "failed": [e["seed"] for e in episodes if not e["ok"]],
        "retried": [e["seed"] for e in episodes if e["attempts"] > 1],
    }
    path = out_dir / "index.json"
    atomic_write_text(path, json.dumps(index, indent=2, allow_nan=False))
    return path


def _die_once(job: dict) -> None:
    """The first worker to run a job with "kill_once" (a marker path) kills itself: the
    fault-tolerance test's worker lost mid-run."""
    import signal

    kill = job.get("kill_once")
    if kill and not Path(kill).exists():
        Path(kill).write_text(str(os.getpid()))
        os.kill(os.getpid(), signal.SIGKILL)


def suture_job(job: dict) -> dict:
    """One scripted suture (adfkit.tasks.episode.run_episode) in OUT/episode_<seed>."""
    import time

    from .tasks.episode import run_episode

    _die_once(job)
    t0 = time.perf_counter()
    name = f"episode_{int(job['seed']):05d}"
    m = run_episode(
        job["launch"],
        job["indices"],
        job["pairs"],
        int(job["seed"]),
        Path(job["out"]) / name,
        job.get("record", False),
        False,
        progress=False,
        every=job.get("every", 10),
        engine=job.get("engine", "pybullet"),
        phantom=job.get("phantom"),
        not_tissue=tuple(job.get("not_tissue", ())),
    )
    return {
        "dir": name,
        "all_passed": bool(m.get("all_passed")),
        "pairs_passed": [p["pair"] for p in m.get("pairs", []) if p.get("passed")],
        "pairs_failed": [
            {"pair": p["pair"], "rule": p.get("rule"), "reason": p.get("reason")}
            for p in m.get("pairs", [])
            if not p.get("passed")
        ],
        "failure": m.get("failure"),
        "simulated_time_s": m.get("simulated_time_s"),
        "wall_s": time.perf_counter() - t0,
        "pid": os.getpid(),
    }


def suture_episodes(
    launch,
    indices,
    pairs,
    seed: int,
    episodes: int,
    workers: int,
    address,
    out: Path,
    record: bool = False,
    every: int = 10,
    kill_once: str | None = None,
    engine: str = "pybullet",
    phantom=None,
    not_tissue=(),
) -> int:
    """`adfkit suture --episodes N --workers W`: exit 0 when every episode ran and passed every
    pair, 1 otherwise (the index says which)."""
    import time

    from .report import Progress

    out = Path(out).resolve()
    jobs = [
        {
            "launch": str(Path(launch).resolve()),
            "indices": indices,
            "pairs": list(pairs) if pairs is not None else None,
            "seed": s,
            "out": str(out),
            "record": record,
            "every": every,
            "engine": engine,
            "phantom": str(Path(phantom).resolve()) if phantom else None,
            "not_tissue": list(not_tissue),
        }
        for s in range(seed, seed + episodes)
    ]
    if kill_once:
        jobs[0]["kill_once"] = kill_once
    t0 = time.perf_counter()
    with Progress(len(jobs), "episodes") as bar:
        runs = fan_out(suture_job, jobs, workers, address, progress=lambda r: bar.update(1))
    wall = time.perf_counter() - t0
    index = write_index(
        out,
        runs,
        {
            "command": "suture",
            "launch": jobs[0]["launch"],
            "indices": indices,
            "pairs": list(pairs) if pairs is not None else None,
            "workers": workers,
            "address": address,
            "wall_s": wall,
        },
    )
    done = [r for r in runs if r["ok"]]
    passed = sum(1 for r in done if r["result"]["all_passed"])
    print(
        f"{len(done)}/{len(runs)} episodes ran, {passed} passed every pair, in {wall:.1f} s "
        f"({len(done) / wall:.3f} episodes/s); index: {index}"
    )
    for r in done:
        for f in r["result"].get("pairs_failed", []):
            print(f"seed {r['job']['seed']}: pair {f['pair']} NOT passed [{f['rule']}]: {f['reason']}")
    for r in runs:
        if r["attempts"] > 1 or not r["ok"]:
            print(
                f"seed {r['job']['seed']}: {'retried, ' if r['attempts'] > 1 else ''}"
                f"{'ok' if r['ok'] else 'FAILED: ' + r['error']}",
                file=sys.stderr,
            )
    return 0 if len(done) == len(runs) and passed == len(runs) else 1


def _validate_chunk(args) -> list:
    from .validator.engine import validate_files

    files, kind, follow = args
    return validate_files(files, kind, follow=follow)


def validate_parallel(paths, kind, follow: bool, workers: int, address=None) -> tuple[list, list]:
    """validate_files over a big tree as Ray tasks, same results in the same order: the files
    in the engine's order (launch files first) cut into contiguous chunks, each chunk checked by
    validate_files (following launch files as it does), the chunks' results joined and a file
    reached twice kept where it first appears, as the serial run keeps it."""
    from .validator.engine import chunked, expand, merge_chunks

    files, problems = expand(paths)
    runs = fan_out(_validate_chunk, [(c, kind, follow) for c in chunked(files, 4 * workers)], workers, address)
    for r in runs:
        if not r["ok"]:
            raise RuntimeError(f"a validation task failed twice: {r['error']}")
    results = merge_chunks(r["result"] for r in runs)
    return results, problems
