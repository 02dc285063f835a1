"""Run by tests/test_addon_bundled.py in a fresh Python that sees only bpy and Blender's numpy:
install the built extension zip with Blender's own installer (its wheels go to the extension
folder's site-packages), then run the geometry operators. Prints one JSON line."""

from __future__ import annotations

import json
import sys

sys.path.insert(0, sys.argv[2])  # a folder holding bpy and numpy only

import bpy  # noqa: E402

out: dict = {"before": {}}
for name in ("adfkit", "trimesh", "coacd", "scipy", "manifold3d"):
    try:
        __import__(name)
        out["before"][name] = sys.modules[name].__file__
    except ImportError:
        out["before"][name] = None
out["install"] = sorted(
    bpy.ops.extensions.package_install_files(filepath=sys.argv[1], repo="user_default", enable_on_install=True)
)
out["from"] = {}
for name in ("adfkit", "trimesh", "coacd", "scipy", "manifold3d"):
    try:
        __import__(name)
        out["from"][name] = sys.modules[name].__file__
    except ImportError:
        out["from"][name] = None


def run(op, **kw):
    try:
        return sorted(getattr(bpy.ops.adf, op)(**kw))
    except RuntimeError as exc:  # the operator's ERROR report
        return str(exc)


def active(o):
    for other in bpy.context.scene.objects:
        other.select_set(other is o)
    bpy.context.view_layer.objects.active = o


for o in list(bpy.data.objects):  # an empty scene (factory settings would disable the extension again)
    bpy.data.objects.remove(o, do_unlink=True)
ops = {}
# estimate inertia: a 10 cm cube of 1000 kg/m³
bpy.ops.mesh.primitive_cube_add(size=0.1)
cube = bpy.context.active_object
cube.name = "Cube"
active(cube)
ops["mark_cube"] = run("mark", kind="BODY")
ops["estimate_inertia"] = run("estimate_inertia")
ops["cube"] = [cube.adf.body.mass, list(cube.adf.body.inertia)]
# fit a cylinder: radius 2 cm, length 10 cm
bpy.ops.mesh.primitive_cylinder_add(radius=0.02, depth=0.1, vertices=64, location=(0.3, 0, 0))
cyl = bpy.context.active_object
cyl.name = "Cyl"
active(cyl)
ops["mark_cyl"] = run("mark", kind="BODY")
ops["fit_cylinder"] = run("fit_collision_primitive", shape="CYLINDER")
shapes = [c for c in cyl.children if c.adf.kind == "COLLISION_SHAPE"]
ops["cylinder"] = [[c.adf.shape.shape, c.adf.shape.radius, c.adf.shape.height] for c in shapes]
# convex hull (one CoACD hull) and decomposition of a ring
bpy.ops.mesh.primitive_torus_add(major_radius=0.05, minor_radius=0.015, location=(0.6, 0, 0))
ring = bpy.context.active_object
ring.name = "Ring"
active(ring)
ops["mark_ring"] = run("mark", kind="BODY")
ops["convex_hull"] = run("generate_collision", max_hulls=1)
ops["hull_parts"] = len([c for c in ring.children if c.adf.kind == "COLLISION_MESH"])
for c in list(ring.children):
    bpy.data.objects.remove(c, do_unlink=True)
active(ring)
ops["decomposition"] = run("generate_collision", max_hulls=8, threshold=0.05)
hulls = [c for c in ring.children if c.adf.kind == "COLLISION_MESH"]
ops["decomposition_parts"] = len(hulls)
pts = [tuple(c.matrix_world @ v.co) for c in hulls for v in c.data.vertices]
ops["decomposition_bounds"] = (
    [[min(p[i] for p in pts) for i in range(3)], [max(p[i] for p in pts) for i in range(3)]] if pts else None
)
out["ops"] = ops
print("RESULT " + json.dumps(out))
