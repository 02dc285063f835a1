"""Time to read (and write back) the whole ADF corpus, and the core's import time.

Prints figures; asserts nothing. Target: core import (model + ADF I/O) < 150 ms.
"""

from __future__ import annotations

import re
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT.parent / "shared" / "corpus"


def import_time(module: str) -> float:
    """Cumulative import time of ``module`` in a fresh interpreter, from -X importtime (ms)."""
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", f"import {module}"], capture_output=True, text=True, check=True
    )
    total = 0
    for line in proc.stderr.splitlines():
        m = re.match(r"import time:\s+\d+ \|\s+(\d+) \| (\s*)(\S+)", line)
        if m and m.group(3) == module and not m.group(2):
            total = int(m.group(1))
    return total / 1000.0


def wall_import(module: str, repeat: int = 5) -> float:
    best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        subprocess.run([sys.executable, "-c", f"import {module}"], check=True)
        best = min(best, time.perf_counter() - t)
    base = min(_timed([sys.executable, "-c", "pass"]) for _ in range(repeat))
    return (best - base) * 1000.0


def _timed(cmd) -> float:
    t = time.perf_counter()
    subprocess.run(cmd, check=True)
    return time.perf_counter() - t


def main() -> None:
    from adfkit.adf import dumps, read_file
    from adfkit.diagnostics import AdfError

    for mod in ("adfkit", "adfkit.model", "adfkit.adf", "adfkit.cli"):
        print(f"import {mod:<14} {import_time(mod):7.1f} ms (-X importtime, cumulative)")
    print(f"import adfkit.adf     {wall_import('adfkit.adf'):7.1f} ms (wall, over a bare interpreter)")
    if not CORPUS.is_dir():
        print(f"corpus not found at {CORPUS}: skipping the corpus figures")
        return
    files = sorted(CORPUS.rglob("*.yaml"))
    size = sum(f.stat().st_size for f in files)
    t = time.perf_counter()
    docs = []
    for f in files:
        try:
            docs.append(read_file(f)[0])
        except AdfError:
            pass
    read_s = time.perf_counter() - t
    t = time.perf_counter()
    for d in docs:
        dumps(d)
    write_s = time.perf_counter() - t
    print(f"corpus: {len(files)} files, {size / 1e6:.2f} MB; read {len(docs)} into the model")
    print(
        f"read  whole corpus: {read_s * 1000:7.1f} ms ({len(files) / read_s:6.0f} files/s, {size / 1e6 / read_s:5.1f} MB/s)"
    )
    print(f"write whole corpus: {write_s * 1000:7.1f} ms ({len(docs) / write_s:6.0f} files/s)")


if __name__ == "__main__":
    main()
