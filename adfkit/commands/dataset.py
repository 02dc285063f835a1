"""`adfkit dataset`: record scripted-expert demonstrations of a Gymnasium environment, one
episode per seed, as Ray tasks (local Ray by default, --address for a cluster), merged into
DIR/index.json. A failed episode is retried once and reported."""

from __future__ import annotations

from pathlib import Path

NAME = "dataset"
HELP = "record expert demonstrations of an adfkit Gymnasium environment on Ray (episodes + index)"


def add_arguments(p) -> None:
    p.add_argument(
        "--env",
        default="adfkit/NeedlePick-v0",
        help="environment id (adfkit/NeedleReach-v0, adfkit/NeedlePick-v0, adfkit/SutureOnePair-v0)",
    )
    p.add_argument("--episodes", type=int, default=4, help="number of episodes (seeds SEED..SEED+N-1)")
    p.add_argument("--seed", type=int, default=0, help="first seed (default 0)")
    p.add_argument("--workers", type=int, default=2, help="Ray workers on a local Ray (default 2)")
    p.add_argument("--address", help="Ray cluster address (e.g. auto or ray://head:10001); default: local Ray")
    p.add_argument("--obs-mode", default="state", choices=("state", "rgb", "rgbd"), help="observations to record")
    p.add_argument("--scene", help="launch file (default: the project's suturing scene)")
    p.add_argument("-l", "--indices", help="launch indices with --scene, e.g. 6-11")
    p.add_argument("--out", required=True, help="folder for episode_<seed>.npz and index.json")


def run(args) -> int:
    from ..diagnostics import AdfError, error

    if args.episodes < 1 or args.workers < 1:
        raise AdfError(
            error("bad-option", "--episodes and --workers must be at least 1", None, "e.g. --episodes 4 --workers 2")
        )
    try:
        from .. import fanout  # noqa: F401 - Ray installed? (the ray extra)
        from ..gym import ENVS
        from ..gym.experts import EXPERTS
    except ImportError as exc:
        raise AdfError(error("missing-extra", str(exc), None, "pip install 'adfkit[gym,ray]'")) from None
    if args.env not in ENVS or ENVS[args.env][0] not in EXPERTS:
        have = [e for e, (c, _) in ENVS.items() if c in EXPERTS]
        raise AdfError(
            error("bad-option", f"--env {args.env!r} has no scripted expert", None, "choose one of " + ", ".join(have))
        )
    if args.scene and not Path(args.scene).is_file():
        raise AdfError(error("no-file", f"{args.scene} does not exist", None, "give a launch file"))
    return record(
        args.env,
        args.episodes,
        args.seed,
        args.workers,
        args.address,
        Path(args.out),
        {
            "obs_mode": args.obs_mode,
            **({"scene": str(Path(args.scene).resolve()), "indices": args.indices} if args.scene else {}),
        },
    )


def record(
    env_id: str, episodes: int, seed: int, workers: int, address, out: Path, kwargs: dict, kill_once: str | None = None
) -> int:
    import time

    from .. import fanout
    from ..gym.record import record_episode
    from ..report import Progress

    out = out.resolve()
    jobs = [{"env": env_id, "seed": s, "out": str(out), "kwargs": kwargs} for s in range(seed, seed + episodes)]
    if kill_once:
        jobs[0]["kill_once"] = kill_once
    t0 = time.perf_counter()
    with Progress(len(jobs), "episodes") as bar:
        runs = fanout.fan_out(record_episode, jobs, workers, address, progress=lambda r: bar.update(1))
    wall = time.perf_counter() - t0
    index = fanout.write_index(
        out, runs, {"env": env_id, "kwargs": kwargs, "workers": workers, "address": address, "wall_s": wall}
    )
    ok = [r for r in runs if r["ok"]]
    solved = sum(1 for r in ok if r["result"]["success"])
    print(f"{len(ok)}/{len(runs)} episodes written ({solved} solved by the expert) in {wall:.1f} s; index: {index}")
    for r in runs:
        if r["attempts"] > 1:
            print(f"seed {r['job']['seed']}: retried ({'ok' if r['ok'] else r['error']})")
    return 0 if len(ok) == len(runs) else 1
