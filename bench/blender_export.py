"""Blender add-on export time for imported corpus models (PSM, phantom with needle and thread).

Prints, per model: import time, first export (meshes copied/written), export again with
meshes unchanged (skipped by content hash), export after editing one mesh. Goal: < 2 s,
and < 1 s when meshes are unchanged.   Usage: python bench/blender_export.py [--thumbnail PNG]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT.parent / "shared" / "corpus"
MODELS = {
    "psm": CORPUS / "ambf/ambf_models/descriptions/multi-bodies/robots/blender-psm.yaml",
    "phantom": CORPUS / "src/ADF/Phantoms/Simple/phantom.yaml",
    "cloth (soft body)": CORPUS / "ambf/ambf_models/descriptions/multi-bodies/sb/cloth.yaml",
    "soft phantom (sample)": ROOT / "sample_scenes/soft_phantom/phantom.yaml",
}


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--thumbnail", help="also render a Workbench thumbnail of the exported PSM here")
    args = ap.parse_args()
    sys.path.insert(0, str(ROOT))
    from adfkit.commands.blend_import import load_addon

    bpy, addon = load_addon()
    for name, path in MODELS.items():
        if not path.is_file():
            print(f"{name}: corpus file {path} missing, skipped")
            continue
        bpy.ops.wm.read_factory_settings(use_empty=True)
        t0 = time.perf_counter()
        made, _ = addon.build.import_model(path)
        t_import = time.perf_counter() - t0
        with tempfile.TemporaryDirectory() as tmp:
            times = []
            for step in ("first", "unchanged", "one mesh edited"):
                if step == "one mesh edited":
                    o = next(
                        o for o in bpy.context.scene.objects if o.adf.kind in ("BODY", "SOFT_BODY") and o.type == "MESH"
                    )
                    o.data.vertices[0].co.x += 1e-4
                t0 = time.perf_counter()
                res = addon.export.export_scene(bpy.context.scene, tmp, name.split()[0])
                times.append((step, time.perf_counter() - t0, len(res.written), len(res.skipped), res.ok))
            print(f"{name}: {len(made)} objects, import {t_import:.2f} s")
            for step, t, w, s, ok in times:
                print(f"  export ({step}): {t:.3f} s  files written {w}, meshes kept {s}, ok={ok}")
            if args.thumbnail and name == "psm":
                bpy.ops.wm.read_factory_settings(use_empty=True)
                addon.build.import_model(res.path)
                addon.render.thumbnail(bpy.context.scene, args.thumbnail)
                print(f"  thumbnail: {args.thumbnail}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
