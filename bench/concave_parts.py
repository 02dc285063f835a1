"""What the moving-concave-mesh rule (adfkit/geometry/concave.py) decomposes in the corpus and
how long the first run takes: every moving body whose collision mesh AMBF keeps concave, each
mesh file once, with a cold CoACD cache of its own (a temporary folder), then the same again
from that cache. Prints one line a mesh and the totals; asserts nothing.

    .venv/bin/python bench/concave_parts.py [--only WORD ...]

Timings are of a shared 2-core box: noisy.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORPUS = Path(os.environ.get("ADFKIT_CORPUS", ROOT.parent / "shared" / "corpus"))


def moving_concave_meshes(only: list[str]) -> list[tuple[str, Path, object]]:
    """(model file name, mesh path, the model's tree) of each moving concave mesh, once a file."""
    from adfkit.adf.paths import collision_mesh_path
    from adfkit.adf.reader import load
    from adfkit.model import ModelFile
    from adfkit.model.semantics import concave_mesh, effective_mass

    seen: set[Path] = set()
    out = []
    for f in sorted(CORPUS.rglob("*.yaml")):
        if only and not any(w.lower() in str(f).lower() for w in only):
            continue
        try:
            doc = load(f)
        except Exception:  # noqa: BLE001 - the corpus holds files that are not ADF models
            continue
        model = getattr(doc, "document", doc)
        if not isinstance(model, ModelFile):
            continue
        for b in model.bodies:
            if effective_mass(b) <= 0 or not concave_mesh(b):
                continue
            p = collision_mesh_path(model, b)
            if p is None or not p.is_file() or p in seen:
                continue
            seen.add(p)
            out.append((f.name, p, getattr(model, "tree", None)))
    return out


def main(argv: list[str]) -> int:
    if not CORPUS.is_dir():
        print(f"corpus not found at {CORPUS}: nothing to measure", file=sys.stderr)
        return 0
    warnings.filterwarnings("ignore")
    only = argv[argv.index("--only") + 1 :] if "--only" in argv else []
    with tempfile.TemporaryDirectory() as cache:
        os.environ["ADFKIT_CACHE"] = cache
        from adfkit.geometry import concave

        meshes = moving_concave_meshes(only)
        cold = warm = 0.0
        parts = 0
        for name, path, tree in meshes:
            t = time.perf_counter()
            got = concave.convex_parts(path, tree, progress=False)
            dt = time.perf_counter() - t
            cold += dt
            concave._DONE.clear()
            t = time.perf_counter()
            concave.convex_parts(path, tree, progress=False)
            warm += time.perf_counter() - t
            parts += got is not None
            print(f"{dt:6.1f} s  {name[:28]:28s} {path.name[:26]:26s} {'its hull' if got is None else got.describe()}")
        print(
            f"{len(meshes)} moving concave meshes, {parts} played as convex parts: "
            f"{cold:.1f} s with a cold cache, {warm:.1f} s from the cache"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
