"""Run N fuzz cases (tests/fuzzkit.py) through adfkit's commands in process; print cases/s,
the tally by exit status, and every case that broke a guarantee. Asserts nothing.

    .venv/bin/python bench/fuzz.py [N] [--no-run] [--blender] [--corpus DIR] [--seed-filter TEXT]
"""

from __future__ import annotations

import argparse
import collections
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

import fuzzkit  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("n", type=int, nargs="?", default=500)
    ap.add_argument("--no-run", action="store_true", help="leave `adfkit run` out (faster)")
    ap.add_argument("--blender", action="store_true", help="include blend-import (needs bpy)")
    ap.add_argument("--corpus", default=os.environ.get("ADFKIT_CORPUS", str(ROOT.parent / "shared" / "corpus")))
    ap.add_argument("--seed-filter", default="")
    ap.add_argument("--start", type=int, default=0)
    ap.add_argument("--explicit", action="store_true", help="also run the named-on-the-command-line cases")
    args = ap.parse_args()

    seeds = fuzzkit.builtin_seeds() + fuzzkit.sample_scene_seeds() + fuzzkit.corpus_seeds(Path(args.corpus))
    seeds = [s for s in seeds if args.seed_filter in s.name]
    cases = [
        fuzzkit.make_case(seeds[i % len(seeds)], args.start + i // len(seeds), not args.no_run, args.blender)
        for i in range(args.n)
    ]
    if args.explicit:
        cases = fuzzkit.explicit_cases() + cases
    by_status: collections.Counter = collections.Counter()
    by_command: collections.Counter = collections.Counter()
    failures = []
    work = Path(tempfile.mkdtemp(prefix="adfkit-fuzz-"))
    t0 = time.perf_counter()
    try:
        for i, case in enumerate(cases):
            d = work / str(i)
            o = fuzzkit.run_case(case, d)
            bad = fuzzkit.problems(o)
            by_status["error" if o.error else f"exit {o.rc}"] += 1
            by_command[case.command] += 1
            if bad:
                failures.append((case.id, bad))
            shutil.rmtree(d, ignore_errors=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    wall = time.perf_counter() - t0
    print(f"{len(cases)} cases in {wall:.1f} s: {len(cases) / wall:.1f} cases/s")
    print("by outcome: " + ", ".join(f"{k} {v}" for k, v in sorted(by_status.items())))
    print("by command: " + ", ".join(f"{k} {v}" for k, v in sorted(by_command.items())))
    print(f"broken guarantees: {len(failures)}")
    for cid, bad in failures[:40]:
        print(f"  {cid}: {bad[0][:600]}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
