"""Validate the whole ADF corpus and compare with check-jsonschema on the same files and
schemas, in the same run. Prints figures; asserts nothing.

    .venv/bin/python bench/validate_corpus.py [CORPUS_DIR]

Figures:
- adfkit CLI wall time (a fresh `adfkit validate DIR` process: start-up included), files/s;
- adfkit in-process time per file (reader + schema + semantic + path rules);
- check-jsonschema wall time with adfkit's shipped schema of each file's kind (one process
  per kind, as it takes one schema per run), files/s, and the ratio adfkit / check-jsonschema.
check-jsonschema only applies the JSON Schema; adfkit also runs the semantic and file rules.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BIN = Path(sys.executable).parent


def main() -> int:
    corpus = Path(
        sys.argv[1] if len(sys.argv) > 1 else os.environ.get("ADFKIT_CORPUS", ROOT.parent / "shared" / "corpus")
    )
    if not corpus.is_dir():
        print(f"corpus not found: {corpus}", file=sys.stderr)
        return 2
    from adfkit.adf_schema import schema_file
    from adfkit.validator import validate_file
    from adfkit.validator.engine import expand

    files = [f for f, _tree in expand([corpus])[0]]
    n = len(files)

    # 1. adfkit CLI, start-up included (no following of launch files: each file once).
    t0 = time.perf_counter()
    proc = subprocess.run(
        [str(BIN / "adfkit"), "validate", str(corpus), "--no-follow", "-f", "json", "--fail-on", "never"],
        capture_output=True,
        text=True,
    )
    cli_wall = time.perf_counter() - t0
    report = json.loads(proc.stdout)
    counts = defaultdict(int)
    for d in report["diagnostics"]:
        counts[d["severity"]] += 1

    # 2. adfkit in process (warm imports), and each file's kind for check-jsonschema.
    by_kind: dict[str, list[Path]] = defaultdict(list)
    t0 = time.perf_counter()
    for f in files:
        res = validate_file(f)
        by_kind[res.kind or "unparsed"].append(f)
    inproc = time.perf_counter() - t0

    # 3. check-jsonschema with the same schemas on the same files.
    t0 = time.perf_counter()
    cj_failed_files = 0
    for kind, paths in sorted(by_kind.items()):
        if kind == "unparsed":
            continue  # not YAML for PyYAML either; counted as checked by adfkit only
        p = subprocess.run(
            [str(BIN / "check-jsonschema"), "--schemafile", str(schema_file(kind)), "-o", "json", *map(str, paths)],
            capture_output=True,
            text=True,
        )
        try:
            out = json.loads(p.stdout)
            cj_failed_files += len(
                {e.get("filename") for e in out.get("errors", [])}
                | {e.get("filename") for e in out.get("parse_errors", [])}
            )
        except json.JSONDecodeError:
            pass
    cj_wall = time.perf_counter() - t0
    cj_n = sum(len(v) for k, v in by_kind.items() if k != "unparsed")

    print(
        f"corpus: {corpus} ({n} YAML files; kinds: "
        + ", ".join(f"{k} {len(v)}" for k, v in sorted(by_kind.items()))
        + ")"
    )
    print(
        f"adfkit validate (CLI, start-up included): {cli_wall:.2f} s wall, {n / cli_wall:.1f} files/s; "
        f"findings: {counts['error']} error, {counts['warning']} warning, {counts['info']} info"
    )
    print(
        f"adfkit validate_file (in process):        {inproc:.2f} s, {n / inproc:.1f} files/s, "
        f"{1000 * inproc / n:.1f} ms/file"
    )
    print(
        f"check-jsonschema (same schemas, {len([k for k in by_kind if k != 'unparsed'])} runs): "
        f"{cj_wall:.2f} s wall, {cj_n / cj_wall:.1f} files/s; files failing: {cj_failed_files}"
    )
    print(
        f"ratio adfkit CLI / check-jsonschema wall time: {cli_wall / cj_wall:.2f}x "
        f"(files/s ratio {(n / cli_wall) / (cj_n / cj_wall):.2f})"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
