"""The scripted suture on the bundled scene: pairs passed over seeds and where the time goes
(physics, observing, rendering the GIF and the MP4, planning and servoing), the per-pair
verdicts, the largest constraint error and the grasp drift. Prints figures, asserts nothing.
AMBF's published figure for the suturing scene: real time (1.0x) on a Ryzen 3600 + GTX 1080.

    python bench/suture.py --pairs 1 --seeds 0 1 2 [--engine mujoco] [--no-pictures]
    python bench/suture.py --pairs 4 --seeds 0 --engine both   # PyBullet and MuJoCo side by side

With ``--engine both`` each seed is played in both engines, one after the other in the same
process (the order alternating from seed to seed, so that neither always runs on a warmer or
quieter machine), and a table gives each engine's whole-episode wall time, its physics time and
real-time factors, and MuJoCo's speed-up over PyBullet.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
AMBF_RTF = 1.0  # AMBF's published suturing scene: real time on a Ryzen 3600 + GTX 1080


def _episode(args, seed: int, engine: str) -> dict:
    from adfkit.tasks.episode import run_episode

    with tempfile.TemporaryDirectory() as out:
        return run_episode(
            args.scene,
            args.indices,
            list(range(1, args.pairs + 1)),
            seed=seed,
            out=None if args.no_pictures else out,
            progress=False,
            engine=engine,
        )


def _report(m: dict, seed: int, engine: str) -> None:
    ok = m.get("all_passed")
    t = m.get("where_the_time_goes", {})
    print(
        f"{engine} seed {seed}: {'passed' if ok else 'FAILED ' + str(m.get('failure'))}; "
        f"{m.get('simulated_time_s', 0):.1f} s simulated in {m.get('episode_wall_time_s', 0):.1f} s "
        f"({m.get('real_time_factor') or 0:.2f}x real time); "
        + ", ".join(f"{k} {v:.1f}" for k, v in t.items())
        + (
            f"; physics {100 * t['physics_s'] / m['episode_wall_time_s']:.0f} % of the wall time"
            if t.get("physics_s") and m.get("episode_wall_time_s")
            else ""
        )
    )
    for p in m.get("pairs", []):
        print(f"  pair {p['pair']}: {p.get('verdict')}" + (f" [{p['rule']}] {p['reason']}" if p.get("rule") else ""))
    drift = m.get("grasp_drift_one_arm_by_phase_m") or {}
    err = m.get("max_constraint_error_m")
    print(
        (f"  max constraint error {1000 * err:.2f} mm" if err is not None else "  no loop-closing joint to measure")
        + "; grasp drift while one "
        "arm holds, by phase (mm): "
        + ", ".join(f"{k} {1000 * v:.2f}" for k, v in drift.items())
        + f"; thread {1000 * (m.get('thread_length_through_tissue_m') or 0):.1f} mm through the tissue"
    )


def _side_by_side(rows: list) -> None:
    """rows: (seed, PyBullet metrics, MuJoCo metrics)."""
    print()
    print(
        f"{'seed':>4} | {'PyBullet wall (physics)':>24} | {'MuJoCo wall (physics)':>22} | "
        f"{'MuJoCo faster by':>16} | {'real-time factor PyBullet / MuJoCo / AMBF':>41}"
    )
    for seed, pb, mj in rows:

        def cell(m):
            return f"{m['episode_wall_time_s']:.1f} s ({m['where_the_time_goes']['physics_s']:.1f} s)"

        ratio = pb["episode_wall_time_s"] / mj["episode_wall_time_s"]
        phys = pb["where_the_time_goes"]["physics_s"] / mj["where_the_time_goes"]["physics_s"]
        passed = "".join("p" if m["all_passed"] else "F" for m in (pb, mj))
        print(
            f"{seed:>4} | {cell(pb):>24} | {cell(mj):>22} | {ratio:>5.2f}x ({phys:.2f}x phys) | "
            f"{pb['real_time_factor']:.2f} / {mj['real_time_factor']:.2f} / {AMBF_RTF:.1f}   [{passed}]"
        )


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--pairs", type=int, default=1)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0])
    ap.add_argument("--scene", default=str(ROOT / "sample_scenes" / "suturing" / "launch.yaml"))
    ap.add_argument("-l", "--indices", default=None)
    ap.add_argument("--engine", choices=("pybullet", "mujoco", "both"), default="pybullet")
    ap.add_argument("--no-pictures", action="store_true", help="no GIF/MP4 (the physics and the verdicts only)")
    args = ap.parse_args()
    sys.path.insert(0, str(ROOT))

    engines = ("pybullet", "mujoco") if args.engine == "both" else (args.engine,)
    passed = dict.fromkeys(engines, 0)
    rows = []
    for n, seed in enumerate(args.seeds):
        order = engines if n % 2 == 0 else engines[::-1]
        got = {}
        for engine in order:
            got[engine] = m = _episode(args, seed, engine)
            passed[engine] += bool(m.get("all_passed"))
            _report(m, seed, engine)
        if len(engines) == 2:
            rows.append((seed, got["pybullet"], got["mujoco"]))
    for engine in engines:
        print(f"{engine}: {passed[engine]} of {len(args.seeds)} seeds passed all {args.pairs} pair(s)")
    if rows:
        _side_by_side(rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
