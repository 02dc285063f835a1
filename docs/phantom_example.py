"""A suturing phantom authored in Blender with the adfkit add-on, as docs/phantom.md does it by
hand: a slab with a ridge of tissue, a gap in the ridge at each hole pair (the needle's
channel), colliding as its boxes; the hole pairs from the add-on's hole helper; exported.

    python docs/phantom_example.py OUT_DIR [--pairs 3] [--spacing 0.012] [--pictures]

With ``--pictures`` it also renders docs/phantom-blender.png, checks the phantom with
`adfkit suture --phantom OUT_DIR/phantom.yaml --pairs all` and draws docs/phantom-hole.png,
docs/phantom-trajectory.png and docs/phantom-camera.png from the run. tests/test_addon_suture_phantom.py
authors its phantom with ``author_phantom`` below.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SLAB = (0.07, 0.09, 0.012)  # m: the slab, its top 12 mm above the floor
RIDGE = (0.021, 0.006)  # m: the ridge along the holes' line, its width and its height over the slab
GAP = 0.0055  # m: the ridge's gap at each pair, the needle's channel


def phantom_boxes(pairs: int, spacing: float) -> tuple[list, list[float]]:
    """The tissue as boxes ((min), (max)), and the y of each pair (pair 1 at +y)."""
    ys = [((pairs + 1) / 2 - k) * spacing for k in range(1, pairs + 1)]
    top = SLAB[2] + RIDGE[1]
    boxes = [((-SLAB[0] / 2, -SLAB[1] / 2, 0.0), (SLAB[0] / 2, SLAB[1] / 2, SLAB[2]))]
    edges = [-SLAB[1] / 2 + 0.01]
    for y in sorted(ys):
        edges += [y - GAP / 2, y + GAP / 2]
    edges.append(SLAB[1] / 2 - 0.01)
    boxes += [((-RIDGE[0] / 2, a, SLAB[2]), (RIDGE[0] / 2, b, top)) for a, b in zip(edges[0::2], edges[1::2])]
    return boxes, ys


def _bpy(addon):
    """Blender's module as the add-on holds it (bpy is imported only inside addon/)."""
    import importlib

    return importlib.import_module(addon.__name__ + ".headless").bpy


def _tissue(addon, boxes):
    """The slab and the ridge as one mesh body, static, colliding as its boxes (a hull of the
    whole mesh would fill the channels)."""
    from mathutils import Matrix

    bpy = _bpy(addon)

    verts, faces = [], []
    for lo, hi in boxes:
        n = len(verts)
        verts += [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
        faces += [
            tuple(n + i for i in f)
            for f in ((0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3))
        ]
    me = bpy.data.meshes.new("Phantom")
    me.from_pydata(verts, [], faces)
    me.update()
    mat = bpy.data.materials.new("tissue")
    mat.diffuse_color = (0.85, 0.55, 0.5, 1.0)
    me.materials.append(mat)
    o = bpy.data.objects.new("Phantom", me)
    bpy.context.scene.collection.objects.link(o)
    addon.authoring.mark(o, "BODY")
    o.adf.body.mass, o.adf.body.mass_typed = 0.0, True
    for lo, hi in boxes:
        centre = [(a + b) / 2 for a, b in zip(lo, hi)]
        size = [b - a for a, b in zip(lo, hi)]
        addon.elements.add_collision_primitive(o, "BOX", size=size, offset=Matrix.Translation(centre))
    return o


def author_phantom(addon, out: Path, pairs: int = 3, spacing: float = 0.012) -> Path:
    """Author the phantom in the current (empty) Blender scene and export it to ``out``;
    returns the model file."""
    import importlib

    from adfkit.diagnostics import AdfError, Severity

    bpy = _bpy(addon)

    boxes, ys = phantom_boxes(pairs, spacing)
    _tissue(addon, boxes)
    holes = importlib.import_module(addon.__name__ + ".holes")
    for k, y in enumerate(ys, start=1):
        # the pair's middle on the ridge's top, from entry to exit along +x, out of the tissue along +z
        holes.add_hole_pair(k, (0.0, y, SLAB[2] + RIDGE[1]), direction=(1.0, 0.0, 0.0))
    res = addon.export.export_scene(bpy.context.scene, out, "phantom")
    if not res.ok:
        raise AdfError(next(d for d in res.diagnostics if d.severity >= Severity.ERROR))
    return res.path


def pictures(addon, model: Path) -> None:
    """docs/phantom-*.png: the phantom in Blender, pair 2's collision shapes, the check's run."""
    import shutil
    import tempfile

    import imageio.v2 as imageio

    from adfkit.tasks import hole_figure
    from adfkit.tasks.episode import run_episode

    bpy = _bpy(addon)

    docs = ROOT / "docs"
    addon.render.thumbnail(bpy.context.scene, docs / "phantom-blender.png", size=480)
    hole_figure.draw(ROOT / "sample_scenes" / "suturing" / "launch.yaml", 2, docs / "phantom-hole.png", model)
    with tempfile.TemporaryDirectory() as tmp:
        m = run_episode(ROOT / "sample_scenes" / "suturing" / "launch.yaml", pairs=None, out=tmp, phantom=model)
        shutil.copy(Path(tmp) / "trajectory.png", docs / "phantom-trajectory.png")
        frames = imageio.mimread(Path(tmp) / "cameraL.gif")
        pull_2 = next(p["start_s"] for p in m["phases"] if p["phase"] == "pull 2")
        imageio.imwrite(docs / "phantom-camera.png", frames[min(int(pull_2) + 1, len(frames) - 1)])
        for p in m["pairs"]:
            print(f"pair {p['pair']}: {p['verdict']}" + (f" [{p['rule']}] {p['reason']}" if p["rule"] else ""))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--pairs", type=int, default=3)
    ap.add_argument("--spacing", type=float, default=0.012)
    ap.add_argument("--pictures", action="store_true")
    a = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    from adfkit.commands.blend_import import load_addon

    bpy, addon = load_addon()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    model = author_phantom(addon, Path(a.out), a.pairs, a.spacing)
    print(model)
    if a.pictures:
        pictures(addon, model)
    return 0


if __name__ == "__main__":
    sys.exit(main())
