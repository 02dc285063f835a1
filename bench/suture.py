"""The scripted suture on the bundled scene: pairs passed over seeds and where the time goes
(physics, observing, rendering the GIF, planning and servoing). Prints figures, asserts nothing.

    python bench/suture.py --pairs 1 --seeds 0 1 2
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
    args = ap.parse_args()
    sys.path.insert(0, str(ROOT))
    from adfkit.tasks.episode import run_episode
    passed = 0
    for seed in args.seeds:
        with tempfile.TemporaryDirectory() as out:
            m = run_episode(args.scene, args.indices, list(range(1, args.pairs + 1)), seed=seed, out=out,
                            progress=False)
        ok = m.get("all_passed")
        passed += bool(ok)
        t = m.get("where_the_time_goes", {})
        print(f"seed {seed}: {'passed' if ok else 'FAILED ' + str(m.get('failure'))}; "
              f"{m.get('simulated_time_s', 0):.1f} s simulated in {m.get('episode_wall_time_s', 0):.1f} s "
              f"({m.get('real_time_factor') or 0:.2f}x real time); "
              + ", ".join(f"{k} {v:.1f}" for k, v in t.items()))
    print(f"{passed} of {len(args.seeds)} seeds passed all {args.pairs} pair(s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
