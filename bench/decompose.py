"""CoACD decomposition time and hull count for the corpus phantom and needle, and the
cache-hit time (goal < 50 ms). Prints figures; asserts nothing.

    .venv/bin/python bench/decompose.py [--max-hulls 8] [--seed 0]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORPUS = Path(os.environ.get("ADFKIT_CORPUS", ROOT.parent / "shared" / "corpus"))
MESHES = {
    "phantom": "src/ADF/Phantoms/Simple/high_res/Phantom.OBJ",
    "needle": "src/ADF/Phantoms/Simple/high_res/Needle.OBJ",
}


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--max-hulls", type=int, default=8)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    if not CORPUS.is_dir():
        print(f"corpus not found at {CORPUS}", file=sys.stderr)
        return 2
    os.environ["ADFKIT_CACHE"] = tempfile.mkdtemp(prefix="adfkit-bench-")  # a cold cache
    from adfkit.geometry import decompose as dec
    from adfkit.geometry.meshio import load_mesh
    from adfkit.geometry.repair import manifold_volume, repair_mesh

    params = dec.DecompositionParams(max_hulls=args.max_hulls, seed=args.seed)
    print(f"{'mesh':8} {'faces':>6} {'coacd s':>8} {'hulls':>5} {'union/V':>8} {'cache-hit ms':>12}")
    for name, rel in MESHES.items():
        solid, _ = repair_mesh(load_mesh(CORPUS / rel))
        cold = dec.decompose(solid, params)
        t = time.perf_counter()
        hit = dec.decompose(solid, params)
        hit_ms = (time.perf_counter() - t) * 1000
        hit_ms_text = f"{hit_ms:12.1f}" if hit.cache_hit else f"{'miss':>12}"
        ratio = manifold_volume(cold.hulls) / solid.volume
        print(f"{name:8} {len(solid.faces):6d} {cold.seconds:8.2f} {len(cold.hulls):5d} {ratio:8.3f} {hit_ms_text}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
