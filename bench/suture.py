"""The scripted suture on the bundled scene: pairs passed over seeds and where the time goes
(physics, observing, rendering the GIF and the MP4, planning and servoing), the per-pair
verdicts, the largest constraint error and the grasp drift. Prints figures, asserts nothing.
AMBF's published figure for the suturing scene: real time (1.0x) on a Ryzen 3600 + GTX 1080.

    python bench/suture.py --pairs 1 --seeds 0 1 2 [--engine mujoco] [--no-pictures]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--pairs", type=int, default=1)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0])
    ap.add_argument("--scene", default=str(ROOT / "sample_scenes" / "suturing" / "launch.yaml"))
    ap.add_argument("-l", "--indices", default=None)
    ap.add_argument("--engine", choices=("pybullet", "mujoco"), default="pybullet")
    ap.add_argument("--no-pictures", action="store_true", help="no GIF/MP4 (the physics and the verdicts only)")
    args = ap.parse_args()
    sys.path.insert(0, str(ROOT))
    from adfkit.tasks.episode import run_episode

    passed = 0
    for seed in args.seeds:
        with tempfile.TemporaryDirectory() as out:
            m = run_episode(
                args.scene,
                args.indices,
                list(range(1, args.pairs + 1)),
                seed=seed,
                out=None if args.no_pictures else out,
                progress=False,
                engine=args.engine,
            )
        ok = m.get("all_passed")
        passed += bool(ok)
        t = m.get("where_the_time_goes", {})
        print(
            f"seed {seed}: {'passed' if ok else 'FAILED ' + str(m.get('failure'))}; "
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
            print(
                f"  pair {p['pair']}: {p.get('verdict')}" + (f" [{p['rule']}] {p['reason']}" if p.get("rule") else "")
            )
        drift = m.get("grasp_drift_one_arm_by_phase_m") or {}
        print(
            f"  max constraint error {1000 * (m.get('max_constraint_error_m') or 0):.2f} mm; grasp drift while one "
            "arm holds, by phase (mm): "
            + ", ".join(f"{k} {1000 * v:.2f}" for k, v in drift.items())
            + f"; thread through tissue {1000 * (m.get('thread_length_through_tissue_m') or 0):.1f} mm"
        )
    print(f"{passed} of {len(args.seeds)} seeds passed all {args.pairs} pair(s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
