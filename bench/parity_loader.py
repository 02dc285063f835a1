"""Loader parity over the whole ADF corpus: every file through AMBF's own loader (headless,
adfkit's AMBF plugin writing what it created) and through adfkit's (`validate` and the runner).
Prints a markdown table (docs/parity.md) and the totals; asserts nothing.

    .venv/bin/python bench/parity_loader.py [CORPUS_DIR] [--json OUT]

Per file: what AMBF does with it (loads / refuses / not loaded by a launch), the error rules
`adfkit validate` gives, the bodies, joints, ghosts, sensors and actuators AMBF created against
adfkit's (`=` when the same), what differs, and how far apart a multibody's links start.
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def main(argv: list[str]) -> int:
    from adfkit.parity import ambf, loader

    args = [a for a in argv if not a.startswith("--")]
    out_json = argv[argv.index("--json") + 1] if "--json" in argv else None
    if out_json in args:
        args.remove(out_json)
    corpus = Path(args[0] if args else os.environ.get("ADFKIT_CORPUS", ROOT.parent / "shared" / "corpus"))
    build, why = ambf.available()
    if build is None or not corpus.is_dir():
        print(f"skipped: {why or f'no corpus at {corpus}'}")
        return 0
    files = sorted(p for p in corpus.rglob("*.yaml") if p.is_file())
    rows, results = [], []
    t0 = time.perf_counter()
    for f in files:
        r = loader.check_file(f, build)
        results.append(r)
        counts = "—"
        if r.ambf == "loads":
            a, b = r.ambf_counts, r.adfkit_counts
            counts = " ".join(f"{k[0].upper()}{a[k]}" + ("" if a[k] == b.get(k) else f"≠{b.get(k)}") for k in a if a[k])
            counts = counts or "nothing"
        diff = "; ".join(
            [f"only in AMBF: {d['kind']} {d['name']}" for d in r.only_in_ambf]
            + [f"only in adfkit: {d['kind']} {d['name']}" for d in r.only_in_adfkit]
            + r.differences
        )
        start = f"{r.start_gap_m * 1e3:.2f} mm, {r.start_gap_deg:.2f}°" if r.start_gap_m or r.start_gap_deg else ""
        rows.append(
            f"| `{f.relative_to(corpus)}` | {r.ambf} | {', '.join(r.validate_errors) or 'no error'} | {counts} "
            f"| {diff or ('agree' if r.agree else 'differ')} | {start} |"
        )
    wall = time.perf_counter() - t0
    print("| file | AMBF | adfkit validate | created (AMBF; ≠ adfkit) | differences | links start apart |")
    print("|---|---|---|---|---|---|")
    print("\n".join(rows))
    n_agree = sum(r.agree for r in results)
    by = {k: sum(r.ambf == k for r in results) for k in ("loads", "refuses", "not loaded")}
    print(
        f"\n{len(results)} files: AMBF loads {by['loads']}, refuses {by['refuses']}, {by['not loaded']} not loaded "
        f"by a launch; adfkit agrees on {n_agree} ({100 * n_agree / max(1, len(results)):.0f} %); {wall:.0f} s"
    )
    if out_json:
        Path(out_json).write_text(json.dumps([r.as_json() for r in results], indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
