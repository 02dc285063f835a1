"""The MuJoCo runner under the options `adfkit run` and `adfkit parity` play with (AMBF's
ghost rule, springs, link shapes and bodies; a 4 ms control step): the CPU time of S seconds of
the suturing set, and where it goes.

    .venv/bin/python bench/mujoco_run_speed.py [--seconds S] [--rounds R] [--digest] [--against REV]

Each round builds the world anew and plays S seconds (default 10, the issue's figure) one
control step at a time, as `adfkit parity` does; it prints this process's CPU time (user +
system, which a shared machine disturbs less than the wall clock) and wall time, and splits
the CPU time into MuJoCo's own step (mj_step, timed call by call), the per-control-step Python
(ghosts, damping, sensors: world.control) and the rest of world.step. Medians of R rounds.
``--digest`` also prints the largest distance of any body from where the first round left it
(0 when the rounds agree) and a digest of every body's pose at the end.

``--against REV`` measures this tree and the adfkit of git revision REV (exported into a
temporary directory) in the same minutes: each round plays both, each in a fresh process, the
order alternating, and prints both trees' medians, their ratio and whether their poses' digests
agree (the same poses to the last bit), with the ratio of the least rounds (load only ever adds).

The suturing set is the corpus's (launch indices 6-11) when ``$ADFKIT_CORPUS`` (else ``../shared/corpus``) is there, else
the project's bundled suturing scene. Asserts nothing; prints figures.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(1, str(ROOT))  # this tree's adfkit, whichever the environment installed


def run_options():
    """The Options `adfkit parity` builds for a scene without joint commands (session.run)."""
    from adfkit.parity.session import Request
    from adfkit.runner import Options

    req = Request(Path("."), None, None)  # type: ignore[arg-type]
    opt = Options(control_substeps=4, ground=True, visuals=False, renderer="tiny")
    opt.ghosts, opt.springs, opt.link_shapes, opt.bodies = req.ghosts, req.springs, req.link_shapes, req.bodies
    return opt


def one_round(scene, seconds: float) -> dict:
    import mujoco

    from adfkit.runner import open_world

    world = open_world(scene, run_options(), engine="mujoco")
    clock = time.process_time
    engine = [0.0]
    control = [0.0]
    real_step, real_control = mujoco.mj_step, world.control

    def timed_step(m, d, n=1):
        t = clock()
        real_step(m, d, n)
        engine[0] += clock() - t

    def timed_control():
        t = clock()
        real_control()
        control[0] += clock() - t

    mujoco.mj_step = timed_step  # world.step looks it up on each call
    world.control = timed_control
    try:
        n = int(round(seconds / (world.dt * world.opt.control_substeps)))
        c0, w0 = clock(), time.perf_counter()
        for _ in range(n):
            world.step(1)
        cpu, wall = clock() - c0, time.perf_counter() - w0
        d = world.data
        poses = np.hstack([d.xpos, d.xquat])
    finally:
        mujoco.mj_step = real_step
        world.close()
    return {"cpu": cpu, "wall": wall, "mj_step": engine[0], "control": control[0], "poses": poses}


def digest(poses: np.ndarray) -> str:
    return hashlib.sha1(poses.tobytes()).hexdigest()[:12]


def report(rounds: list[dict], seconds: float, indent: str = "  ") -> None:
    def med(k: str) -> float:
        return statistics.median(r[k] for r in rounds)

    cpu = med("cpu")
    low, high = min(r["cpu"] for r in rounds), max(r["cpu"] for r in rounds)
    print(
        f"{indent}CPU {cpu:.3f} s ({low:.3f}-{high:.3f}; wall {med('wall'):.3f} s); real-time factor {seconds / cpu:.1f}"
    )
    for name, key in (("mj_step (MuJoCo)", "mj_step"), ("control (ghosts, damping, sensors)", "control")):
        print(f"{indent}{name:<36} {med(key):7.3f} s  {100 * med(key) / cpu:4.0f} %")
    rest = cpu - med("mj_step") - med("control")
    print(f"{indent}{'the rest of world.step':<36} {rest:7.3f} s  {100 * rest / cpu:4.0f} %")


def in_process(tree: str, seconds: float) -> dict:
    """One round played by the adfkit of ``tree`` in a fresh process (its figures as JSON)."""
    out = subprocess.run(
        [sys.executable, __file__, "--tree", tree, "--seconds", str(seconds), "--json"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return json.loads(out.strip().splitlines()[-1])


def against(rev: str, seconds: float, rounds: int) -> int:
    from against import alternated

    got = alternated(rev, rounds, lambda tree: in_process(tree, seconds))
    from speed import scene_and_label

    print(f"scene: {scene_and_label()[1]}; adfkit run/parity options, MuJoCo, {seconds:g} s, median of {rounds}")
    for name, rows in got.items():
        print(f"{name}: poses' digest {rows[0]['digest']}")
        report(rows, seconds, "    ")
    cpu = {k: statistics.median(r["cpu"] for r in v) for k, v in got.items()}
    # the least CPU of each tree's rounds: another process's load only ever adds to a round
    least = {k: min(r["cpu"] for r in v) for k, v in got.items()}
    same = {r["digest"] for v in got.values() for r in v}
    print(
        f"this tree / {rev}: CPU {cpu['this tree'] / cpu[rev]:.3f} (medians), "
        f"{least['this tree'] / least[rev]:.3f} (least of each); poses {'the same' if len(same) == 1 else 'differ'}"
    )
    return 0


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--digest", action="store_true")
    ap.add_argument("--against", metavar="REV", help="also measure the adfkit of this git revision, alternately")
    ap.add_argument("--tree", help=argparse.SUPPRESS)  # (--against's rounds: the adfkit to import)
    ap.add_argument("--json", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.against:
        return against(args.against, args.seconds, args.rounds)
    if args.tree:
        from against import use_tree

        use_tree(args.tree)
    from speed import scene_and_label

    scene, label = scene_and_label()
    if args.json:
        r = one_round(scene, args.seconds)
        print(json.dumps({k: r[k] for k in ("cpu", "wall", "mj_step", "control")} | {"digest": digest(r["poses"])}))
        return 0
    rounds = [one_round(scene, args.seconds) for _ in range(args.rounds)]
    print(f"scene: {label}; adfkit run/parity options, MuJoCo, {args.seconds:g} s, median of {args.rounds}")
    report(rounds, args.seconds)
    if args.digest:
        first = rounds[0]["poses"]
        spread = max(float(np.max(np.abs(r["poses"][:, :3] - first[:, :3]))) for r in rounds)
        print(f"  poses: digest {digest(first)}, rounds apart by {spread * 1e3:.6f} mm")
    return 0


if __name__ == "__main__":
    sys.exit(main())
