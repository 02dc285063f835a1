"""A soft pad resting on a static tray whose collision is a triangle mesh (AMBF's default
`collision mesh type` for a static body). PyBullet's soft bodies cannot collide with a triangle
mesh: Bullet's sparse SDF gives every point a distance 0 to a non-convex shape, so the pad's
nodes near the tray were flung up to 10 cm and the camera drew it in fragments. In a world with
soft bodies the runner plays a static concave mesh as convex hulls (exact for the box tray), and
warns when that fills a hollow. Real PyBullet, TinyRenderer."""

from __future__ import annotations

import json
import textwrap

import numpy as np
import pytest

pytest.importorskip("pybullet")
trimesh = pytest.importorskip("trimesh")
Image = pytest.importorskip("PIL.Image")

from adfkit.cli import main  # noqa: E402
from adfkit.geometry.softmesh import load_soft_mesh  # noqa: E402

PAD_BOTTOM, PAD_TOP = 0.046, 0.05


def _scene(tmp, tray: trimesh.Trimesh) -> str:
    pad = trimesh.creation.box(extents=(0.1, 0.1, PAD_TOP - PAD_BOTTOM)).subdivide_to_size(0.0125)
    pad.apply_translation((0, 0, (PAD_TOP + PAD_BOTTOM) / 2))
    pad.export(tmp / "pad.obj")
    tray.export(tmp / "tray.obj")
    nodes = load_soft_mesh(tmp / "pad.obj").nodes
    rim = [int(i) for i in np.flatnonzero(np.abs(nodes[:, :2]).max(axis=1) > 0.05 - 1e-6)]
    (tmp / "scene.yaml").write_text(
        textwrap.dedent(f"""\
        bodies: [BODY Tray]
        soft bodies: [SOFT Pad]
        cameras: [CAMERA cam]
        BODY Tray:
          name: Tray
          mass: 0.0
          mesh: tray.obj
          color rgba: {{r: 0.3, g: 0.3, b: 0.3, a: 1.0}}
          inertial offset: {{position: {{x: 0.0, y: 0.0, z: 0.0}}}}
        SOFT Pad:
          name: Pad
          mass: 0.04
          mesh: pad.obj
          color rgba: {{r: 0.9, g: 0.2, b: 0.2, a: 1.0}}
          config:
            fixed nodes: {rim}
        CAMERA cam:
          name: cam
          location: {{x: 0.0, y: -0.12, z: 0.25}}
          look at: {{x: 0.0, y: 0.0, z: 0.048}}
          up: {{x: 0.0, y: 0.0, z: 1.0}}
          clipping plane: {{near: 0.01, far: 10.0}}
          field view angle: 0.7
          publish image resolution: {{width: 64, height: 48}}
        """)
    )
    return str(tmp / "scene.yaml")


def _box_tray() -> trimesh.Trimesh:
    tray = trimesh.creation.box(extents=(0.16, 0.16, 0.02))
    tray.apply_translation((0, 0, PAD_BOTTOM - 0.01))  # its top touches the pad's bottom face
    return tray


def test_a_soft_pad_on_a_triangle_mesh_tray_rests_whole_and_is_drawn_whole(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", _scene(tmp_path, _box_tray()), "--seconds", "0.1", "--out", str(out)]) == 0
    said = capsys.readouterr()
    (pad,) = json.loads((out / "report.json").read_text())["soft_bodies"]
    # the pad keeps its size (it grew from 0.141 m to 0.19 m, nodes flung 8 cm, on the triangle mesh)
    assert pad["size_m"] == pytest.approx(pad["rest_size_m"], rel=0.01)
    assert PAD_BOTTOM - 0.002 < pad["lowest_z"] < PAD_BOTTOM + 0.001
    assert "runner-soft-concave" not in said.out + said.err  # a box: its hull is exact, nothing to say
    # seen from above, the middle of the picture is the pad's red top, not fragments of the tray
    rgb = np.asarray(Image.open(out / "cam_rgb.png")).astype(int)
    middle = rgb[18:30, 24:40].reshape(-1, 3)
    assert (middle[:, 0] > middle[:, 1] + 60).all(), middle[:4]


def test_a_concave_tray_beside_a_soft_body_is_played_as_hulls_and_said(tmp_path, capsys):
    floor = trimesh.creation.box(extents=(0.16, 0.16, 0.01))
    floor.apply_translation((0, 0, PAD_BOTTOM - 0.005))
    wall = trimesh.creation.box(extents=(0.16, 0.01, 0.04))
    wall.apply_translation((0, 0.075, PAD_BOTTOM + 0.015))
    tray = trimesh.util.concatenate([floor, wall])  # an L: its convex hull fills the corner
    path = _scene(tmp_path, tray)
    assert main(["run", path, "--seconds", "0.02", "--no-frames", "--out", str(tmp_path / "out")]) == 0
    printed = "".join(capsys.readouterr())
    assert "warning[runner-soft-concave]: BODY Tray: concave collision mesh tray.obj played as convex hulls" in printed
    assert "scene.yaml:7:" in printed  # the `mesh:` line that names it


def test_a_pad_authored_in_blender_on_a_mesh_tray_plays_whole(tmp_path):
    """The modeller's case: grid + Solidify soft body, border fixed, resting on a cube tray that
    exports as a mesh (a static body: a triangle mesh), through the add-on, then `adfkit run`: the
    pad whole, resting on the tray, and drawn in its material's colour."""
    bpy = pytest.importorskip("bpy")
    from adfkit.commands.blend_import import load_addon

    addon = load_addon()[1]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=12, y_subdivisions=12, size=0.1, location=(0, 0, PAD_TOP))
    pad = bpy.context.active_object
    pad.name = "Pad"
    pad.modifiers.new("Solidify", "SOLIDIFY").thickness = PAD_TOP - PAD_BOTTOM
    tissue = bpy.data.materials.new("Tissue")
    if tissue.node_tree is None:  # Blender before 5.0 made node trees on request
        tissue.use_nodes = True
    bsdf = next(n for n in tissue.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    bsdf.inputs["Base Color"].default_value = (0.9, 0.25, 0.2, 1.0)
    pad.data.materials.append(tissue)
    addon.authoring.mark(pad, "SOFT_BODY")
    for v in pad.data.vertices:
        v.select = max(abs(v.co.x), abs(v.co.y)) > 0.05 - 1e-6
    addon.authoring.fix_selected_nodes(pad)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0, 0, PAD_BOTTOM - 0.01), scale=(0.16, 0.16, 0.02))
    tray = bpy.context.active_object
    tray.name = "Tray"
    addon.authoring.mark(tray, "BODY")
    tray.adf.body.mass = 0.0
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    bpy.context.scene.collection.objects.link(cam)
    cam.location = (0.0, -0.12, 0.25)
    cam.rotation_euler = (0.45, 0.0, 0.0)
    addon.authoring.mark(cam, "CAMERA")
    cam.parent = tray
    cam.matrix_parent_inverse = tray.matrix_world.inverted()
    bpy.context.view_layer.update()
    res = addon.export.export_scene(bpy.context.scene, tmp_path / "model", "pad")
    assert res.ok, [str(d) for d in res.diagnostics]
    out = tmp_path / "out"
    assert main(["run", str(res.path), "--seconds", "0.1", "--out", str(out)]) == 0
    rep = json.loads((out / "report.json").read_text())
    (sb,) = rep["soft_bodies"]
    assert sb["nodes"] == 2 * 13 * 13 and sb["fixed_nodes"] == 2 * 48  # the shell, its rim fixed on both faces
    assert sb["size_m"] == pytest.approx(sb["rest_size_m"], rel=0.01)  # was 0.19 m against 0.141 m
    assert PAD_BOTTOM - 0.002 < sb["lowest_z"] < PAD_BOTTOM + 0.001
    seg = np.load(out / "Cam_seg.npy")
    pad_pixels = seg == 1  # the pad: label 1, after the tray
    assert pad_pixels.sum() > 0.05 * seg.size
    # drawn in its material's colour (the MTL's Kd: the file has no `color rgba`), not white on the white floor
    r, g, b = np.asarray(Image.open(out / "Cam_rgb.png"))[pad_pixels].reshape(-1, 3).astype(float).mean(axis=0)
    assert r > g + 60 and r > b + 60, (r, g, b)
