"""Mesh export as OBJ, STL, PLY or 3DS (the add-on's export option and `blend-export
--mesh-format`): the files, the ADF keys naming them, reading them back, the validator, and
PyBullet playing what it can read and saying where it cannot. Real bpy, trimesh, PyBullet."""

from __future__ import annotations

import json

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")
from blender_fixtures import cube  # noqa: E402

trimesh = pytest.importorskip("trimesh")

from adfkit.adf import read_file  # noqa: E402
from adfkit.cli import main  # noqa: E402
from adfkit.geometry.softmesh import load_soft_mesh, read_3ds  # noqa: E402

FORMATS = ("OBJ", "STL", "PLY", "3DS")


def _red(o) -> None:
    mat = bpy.data.materials.new("Red")
    if mat.node_tree is None:  # Blender before 5.0 made node trees on request
        mat.use_nodes = True
    bsdf = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    bsdf.inputs["Base Color"].default_value = (0.9, 0.1, 0.1, 1.0)
    o.data.materials.append(mat)


def tray_and_lid(addon):
    """A 10 cm red tray on the floor, and a lid above it whose collision is two box parts."""
    a = addon.authoring
    tray = cube("Tray", 0.1, (0.0, 0.0, 0.05))
    _red(tray)
    a.mark(tray, "BODY")
    lid = cube("Lid", 0.04, (0.0, 0.0, 0.2))
    a.mark(lid, "BODY")
    for i, x in enumerate((-0.01, 0.01)):
        part = cube(f"LidPart{i}", 0.02, (x, 0.0, 0.2))
        part.parent = lid
        part.matrix_parent_inverse = lid.matrix_world.inverted()
        a.mark(part, "COLLISION_MESH")
    bpy.context.view_layer.update()
    return tray, lid


def _load(path):
    if path.suffix.upper() == ".3DS":
        v, f = read_3ds(path)
        return trimesh.Trimesh(v, f, process=False)
    return trimesh.load(path, force="mesh", process=False)


@pytest.mark.parametrize("fmt", FORMATS)
def test_export_writes_the_meshes_in_the_chosen_format(addon, scene, tmp_path, fmt):
    tray_and_lid(addon)
    out = tmp_path / "out"
    res = addon.export.export_scene(scene, out, "tray", mesh_format=fmt)
    assert res.ok, [str(d) for d in res.diagnostics]
    doc, _ = read_file(res.path)
    tray, lid = (next(b for b in doc.bodies if b.name == n) for n in ("Tray", "Lid"))
    assert tray.mesh == f"Tray.{fmt}" and tray.collision_mesh is None  # AMBF looks it up in low_res/
    visual = _load(out / "meshes/high_res" / tray.mesh)
    assert len(visual.faces) == 12 and np.allclose(visual.bounds, [[-0.05] * 3, [0.05] * 3], atol=1e-7)
    assert len(_load(out / "meshes/low_res" / tray.mesh).faces) == 12
    # the lid's two collision parts stay apart: OBJ and 3DS hold several objects, STL and PLY one
    multi = fmt in ("OBJ", "3DS")
    assert lid.collision_mesh == f"Lid_collision.{fmt if multi else 'OBJ'}"
    parts = out / "meshes/low_res" / lid.collision_mesh
    if fmt == "3DS":
        from test_geometry_mesh3ds import spec_read

        assert [o[0] for o in spec_read(parts.read_bytes())["objects"]] == ["LidPart0", "LidPart1"]
    got = _load(parts)
    assert len(got.faces) == 24 and np.allclose(got.bounds, [[-0.02, -0.01, -0.01], [0.02, 0.01, 0.01]], atol=1e-7)
    said = {d.rule: d for d in res.diagnostics}
    assert ("mesh-format-parts" in said) is not multi
    if not multi:
        assert "its 2 collision parts are written as OBJ" in said["mesh-format-parts"].message
    # the red material: an OBJ keeps it in its MTL, the other formats say they drop it
    if fmt == "OBJ":
        assert "Kd 0.9 0.1 0.1" in (out / "meshes/high_res/Tray.mtl").read_text()
    else:
        assert "mesh-format-materials" in said and "'Red'" in said["mesh-format-materials"].message
    # the validator: clean, but a PLY mesh is one AMBF does not load, said at its `mesh:` line
    from adfkit.validator import validate_file

    found = [d for d in validate_file(res.path).diagnostics]
    assert [d for d in found if d.severity >= 2] == []
    fmt_warnings = [d for d in found if d.rule == "mesh-format"]
    if fmt == "PLY":
        line = res.path.read_text().splitlines().index("  mesh: Tray.PLY") + 1
        assert any(d.location.line == line and "AMBF loads OBJ, 3DS and STL" in d.message for d in fmt_warnings)
    else:
        assert fmt_warnings == []


@pytest.mark.parametrize("fmt", FORMATS)
def test_pybullet_plays_stl_and_obj_and_says_where_it_cannot_read_ply_and_3ds(addon, scene, tmp_path, fmt, capsys):
    pytest.importorskip("pybullet")
    tray_and_lid(addon)
    res = addon.export.export_scene(scene, tmp_path / "out", "tray", mesh_format=fmt)
    assert res.ok
    run = tmp_path / "run"
    assert main(["run", str(res.path), "--seconds", "0.2", "--no-frames", "--out", str(run)]) == 0
    rep = json.loads((run / "report.json").read_text())
    said = capsys.readouterr()
    printed = said.out + said.err
    assert rep["bodies"] == 2 and rep["nan"] == rep["exploded"] == rep["fell_through_floor"] == []
    if fmt in ("OBJ", "STL"):
        assert rep["without_collision_shape"] == [] and "runner-mesh-format" not in printed
    else:  # the tray's mesh: no collision and no picture, each said at its line; the lid's parts are 3DS too
        assert "BODY Tray" in rep["without_collision_shape"]
        assert f"visual mesh Tray.{fmt}: PyBullet reads OBJ and STL meshes, not .{fmt}" in printed
        assert f"tray.yaml:{res.path.read_text().splitlines().index(f'  mesh: Tray.{fmt}') + 1}:" in printed
        pytest.importorskip("mujoco")  # MuJoCo plays it through the MJCF writer's STL copy, and says so
        mj = ["run", str(res.path), "--engine", "mujoco", "--seconds", "0.2", "--no-frames", "--out", str(run)]
        assert main(mj) == 0
        said = capsys.readouterr()
        assert f"Tray.{fmt}: .{fmt} is not read by the engine: converted to" in said.out + said.err


@pytest.mark.parametrize("fmt", ("STL", "PLY", "3DS"))
def test_a_soft_bodys_fixed_nodes_follow_the_numbering_of_the_format_written(addon, scene, tmp_path, fmt):
    """STL keeps three corners per triangle, so its nodes come in another order than the
    vertex list: the fixed nodes are numbered as AMBF will number that file."""
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=5, y_subdivisions=5, size=0.1)
    pad = bpy.context.active_object
    pad.name = "Pad"
    addon.authoring.mark(pad, "SOFT_BODY")
    corners = [v.index for v in pad.data.vertices if v.co.y > 0.049 and abs(v.co.x) > 0.049]
    for v in pad.data.vertices:
        v.select = v.index in corners
    addon.authoring.fix_selected_nodes(pad)
    res = addon.export.export_scene(scene, tmp_path / "out", mesh_format=fmt)
    assert res.ok, [str(d) for d in res.diagnostics]
    doc, _ = read_file(res.path)
    (sb,) = doc.soft_bodies
    assert sb.mesh == f"Pad.{fmt}"
    nodes = load_soft_mesh(tmp_path / "out" / doc.low_resolution_path / sb.mesh).nodes
    assert len(nodes) == len(pad.data.vertices) == 36
    fixed = nodes[sb.config.fixed_nodes]
    assert len(fixed) == 2 and (fixed[:, 1] > 0.049).all() and (abs(fixed[:, 0]) > 0.049).all()
    if fmt == "STL":  # not the vertex list's numbers: the test would pass by luck otherwise
        assert sorted(sb.config.fixed_nodes) != sorted(corners)


def test_blend_export_takes_the_mesh_format(addon, scene, tmp_path, capsys):
    tray_and_lid(addon)
    blend = tmp_path / "tray.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    assert main(["blend-export", str(blend), str(tmp_path / "out"), "--mesh-format", "stl"]) == 0
    doc, _ = read_file(tmp_path / "out/tray.yaml")
    assert sorted(b.mesh for b in doc.bodies) == ["Lid.STL", "Tray.STL"]
    assert (tmp_path / "out/meshes/high_res/Tray.STL").stat().st_size == 84 + 50 * 12  # binary STL, 12 triangles
    with pytest.raises(SystemExit) as exc:  # argparse's usage error, exit status 2, nothing written
        main(["blend-export", str(blend), str(tmp_path / "x"), "--mesh-format", "fbx"])
    assert exc.value.code == 2 and not (tmp_path / "x").exists()
    assert "invalid choice: 'FBX'" in capsys.readouterr().err


def test_a_mesh_over_the_3ds_object_limits_is_split_but_a_soft_bodys_is_refused(addon, scene, tmp_path):
    from test_geometry_mesh3ds import spec_read

    bpy.ops.mesh.primitive_grid_add(x_subdivisions=256, y_subdivisions=256, size=0.2)
    sheet = bpy.context.active_object
    sheet.name = "Sheet"
    assert len(sheet.data.vertices) == 66049  # over 65535
    addon.authoring.mark(sheet, "SOFT_BODY")
    res = addon.export.export_scene(scene, tmp_path / "soft", mesh_format="3DS")
    assert not res.ok and not (tmp_path / "soft").exists()
    (d,) = [d for d in res.diagnostics if d.rule == "mesh-format-limit"]
    assert d.message == (
        "soft body 'Sheet' has 66049 vertices and 131072 triangles; a 3DS object holds at most 65535 of each, "
        "and a soft body's mesh cannot be split (its node numbers)"
    )
    sheet.adf.kind = "BODY"
    sheet.adf.body.use_mass, sheet.adf.body.mass = True, 0.0
    res = addon.export.export_scene(scene, tmp_path / "rigid", mesh_format="3DS")
    assert res.ok, [str(d) for d in res.diagnostics]
    objects = spec_read((tmp_path / "rigid/meshes/high_res/Sheet.3DS").read_bytes())["objects"]
    assert [o[0] for o in objects] == ["Sheet_0", "Sheet_1", "Sheet_2"]
    assert sum(len(o[2]) for o in objects) == 131072 and max(len(o[1]) for o in objects) <= 65535


def test_mesh_file_names_take_the_formats_suffix(addon):
    import importlib

    with_format = importlib.import_module(addon.__name__ + ".meshes").with_format
    assert with_format("Tray.001", "STL") == "Tray.001.STL"  # Blender's numbered copy is not a suffix
    assert with_format("Tray.STL", "OBJ") == "Tray.OBJ"
    assert with_format("sub/Tray.OBJ", "OBJ") == "sub/Tray.OBJ"  # as the file names it
    assert with_format("/ambf/env/base", "3DS") == "base.3DS"  # a namespace is no folder


@pytest.mark.parametrize("fmt", FORMATS)
def test_meshes_in_each_format_import_back_into_blender(addon, scene, tmp_path, fmt):
    tray_and_lid(addon)
    res = addon.export.export_scene(scene, tmp_path / "out", "tray", mesh_format=fmt)
    assert res.ok
    bpy.ops.wm.read_factory_settings(use_empty=True)
    made, diags = addon.build.import_model(res.path)
    assert [d for d in diags if d.rule == "mesh-unreadable"] == []
    tray = bpy.data.objects["Tray"]
    assert tray.type == "MESH" and len(tray.data.polygons) == (6 if fmt == "OBJ" else 12)  # OBJ keeps quads
    co = np.array([tray.matrix_world @ v.co for v in tray.data.vertices])
    assert np.allclose([co.min(0), co.max(0)], [[-0.05, -0.05, 0.0], [0.05, 0.05, 0.1]], atol=1e-6)
    lid_parts = [o for o in bpy.data.objects if o.parent is bpy.data.objects["Lid"] and o.type == "MESH"]
    # two cubes: quads in OBJ (the STL and PLY exports keep the lid's parts as OBJ), triangles in 3DS
    assert sum(len(o.data.polygons) for o in lid_parts) == (24 if fmt == "3DS" else 12)


def test_a_broken_3ds_mesh_imports_without_it_and_says_so(addon, scene, tmp_path):
    tray_and_lid(addon)
    res = addon.export.export_scene(scene, tmp_path / "out", "tray", mesh_format="3DS")
    mesh = tmp_path / "out/meshes/high_res/Tray.3DS"
    mesh.write_bytes(mesh.read_bytes()[:40])
    bpy.ops.wm.read_factory_settings(use_empty=True)
    _, diags = addon.build.import_model(res.path)
    (d,) = [d for d in diags if d.rule == "mesh-unreadable" and "Tray.3DS" in d.message]
    assert "Blender could not import the mesh Tray.3DS: corrupt 3DS chunk 0x4d4d at byte 0" in d.message
    assert bpy.data.objects["Tray"].type == "EMPTY"
