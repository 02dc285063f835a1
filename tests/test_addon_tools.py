"""A modeller's naming and placement tools that AMBF's own add-on had: strip namespaces from
object names, move a collision mesh to its body's origin or keep its current location. Real bpy;
the checks are on the exported ADF and mesh numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")
from blender_fixtures import cube  # noqa: E402

trimesh = pytest.importorskip("trimesh")

from adfkit.adf import read_file  # noqa: E402
from adfkit.diagnostics import Severity  # noqa: E402


def _namespaces(addon):
    import importlib

    return importlib.import_module(addon.__name__ + ".namespaces")


def _select(*objs):
    for o in bpy.context.scene.objects:
        o.select_set(o in objs)
    bpy.context.view_layer.objects.active = objs[0]


# --- strip namespaces ---------------------------------------------------------------------------


def test_strip_namespaces_moves_the_shared_namespace_to_the_model(addon, scene, tmp_path):
    a = addon.authoring
    base = cube("/ambf/env/psm/base", 0.1)
    link = cube("/ambf/env/psm/link1", 0.05, (0.0, 0.0, 0.1))
    for o in (base, link):
        a.mark(o, "BODY")
    a.add_joint(base, link, "revolute", name="/ambf/env/psm/base-link1")
    plain = cube("Table", 0.2, (0.5, 0.0, 0.0))
    a.mark(plain, "BODY")
    # before: export says what AMBF would make of such a name
    before = [d for d in addon.export.check_scene(scene) if d.rule == "namespace-in-name"]
    assert [d.message for d in before][0] == (
        "'/ambf/env/psm/base': the name carries the namespace '/ambf/env/psm/'; "
        "AMBF puts the model's namespace in front of it"
    )
    assert len(before) == 3 and "Strip namespaces" in before[0].hint
    assert bpy.ops.adf.strip_namespaces() == {"FINISHED"}
    assert sorted(o.name for o in scene.objects) == ["Table", "base", "base-link1", "link1"]
    assert (scene.adf.use_namespace, scene.adf.namespace) == (True, "/ambf/env/psm/")
    assert scene.adf.findings.splitlines()[-1] == "INFO: model namespace set to '/ambf/env/psm/'"
    res = addon.export.export_scene(scene, tmp_path / "out")
    assert res.ok, [str(d) for d in res.diagnostics]
    doc, _ = read_file(res.path)
    assert doc.namespace == "/ambf/env/psm/"
    assert [b.identifier for b in doc.bodies] == ["BODY Table", "BODY base", "BODY link1"]
    assert sorted(b.mesh for b in doc.bodies) == ["Table.OBJ", "base.OBJ", "link1.OBJ"]
    (j,) = doc.joints
    assert (j.identifier, j.parent, j.child) == ("JOINT base-link1", "BODY base", "BODY link1")
    from adfkit.validator import validate_file

    assert [str(d) for d in validate_file(res.path).diagnostics if d.severity >= Severity.WARNING] == []


def test_strip_namespaces_says_which_namespaces_it_dropped_when_they_differ(addon, scene):
    for name in ("/left/arm", "/right/arm"):
        addon.authoring.mark(cube(name), "BODY")
    said = _namespaces(addon).strip_namespaces(scene)
    # both are 'arm' now: Blender gives the second one a number, and that is said too
    assert said == [
        "renamed '/left/arm' to 'arm'",
        "renamed '/right/arm' to 'arm.001' ('arm' was taken)",
        "namespaces removed from names: '/left/', '/right/'; the model's namespace is none",
    ]
    assert scene.adf.use_namespace is False
    assert _namespaces(addon).strip_namespaces(scene) == []  # nothing left to strip


def test_split_name_follows_ambfs_rule(addon):
    ns = _namespaces(addon)
    assert ns.split_name("/ambf/env/BODY base") == ("/ambf/env/", "BODY base")
    assert ns.split_name("base") == ("", "base")
    assert ns.split_name("/ambf/env/") == ("", "/ambf/env/")  # no name after the namespace: left whole


# --- collision mesh placement -------------------------------------------------------------------


def _body_with_offset_part(addon):
    """A body turned 90° about Z at z = 0.5, and a 2 cm collision cube 10 cm from it along world
    X, which is the body's -Y."""
    body = cube("Body", 0.1, (0.0, 0.0, 0.5))
    body.rotation_euler = (0.0, 0.0, math.pi / 2)
    bpy.context.view_layer.update()
    addon.authoring.mark(body, "BODY")
    part = cube("Part", 0.02, (0.1, 0.0, 0.5))
    part.parent = body
    part.matrix_parent_inverse = body.matrix_world.inverted()
    addon.authoring.mark(part, "COLLISION_MESH")
    bpy.context.view_layer.update()
    return body, part


def _collision_bounds(addon, scene, out):
    res = addon.export.export_scene(scene, out)
    assert res.ok, [str(d) for d in res.diagnostics]
    doc, _ = read_file(res.path)
    (b,) = doc.bodies
    mesh = trimesh.load(out / "meshes/low_res" / b.collision_mesh, force="mesh", process=False)
    return np.round(mesh.bounds, 6).tolist()


OFFSET = [[-0.01, -0.11, -0.01], [0.01, -0.09, 0.01]]  # the part seen from the body: 10 cm along its -Y
AT_ORIGIN = [[-0.01, -0.01, -0.01], [0.01, 0.01, 0.01]]


def test_use_current_location_keeps_the_collision_mesh_where_it_is_seen(addon, scene, tmp_path):
    body, part = _body_with_offset_part(addon)
    assert _collision_bounds(addon, scene, tmp_path / "before") == OFFSET
    _select(part)
    assert bpy.ops.adf.collision_use_current_location() == {"FINISHED"}
    bpy.context.view_layer.update()
    assert np.allclose(np.array(part.matrix_world), np.array(body.matrix_world), atol=1e-6)
    # the offset now lives in the mesh's own vertices (the body's frame): the same numbers are written
    co = np.array([v.co[:] for v in part.data.vertices])
    assert np.allclose([co.min(0), co.max(0)], OFFSET, atol=1e-6)
    assert _collision_bounds(addon, scene, tmp_path / "after") == OFFSET


def test_move_to_body_origin_puts_the_collision_mesh_where_ambf_reads_it(addon, scene, tmp_path):
    body, part = _body_with_offset_part(addon)
    _select(body)  # the body selected: its collision meshes move, as AMBF's add-on did it from the body
    assert bpy.ops.adf.collision_to_body_origin() == {"FINISHED"}
    bpy.context.view_layer.update()
    assert np.allclose(part.matrix_world.translation[:], (0.0, 0.0, 0.5), atol=1e-6)
    assert _collision_bounds(addon, scene, tmp_path / "out") == AT_ORIGIN


def test_collision_placement_without_a_body_says_why(addon, scene):
    stray = cube("Stray", 0.02)
    addon.authoring.mark(stray, "COLLISION_MESH")
    _select(stray)
    with pytest.raises(RuntimeError) as exc:
        bpy.ops.adf.collision_to_body_origin()
    assert "collision mesh 'Stray' is not under a body — parent it to the body it belongs to" in str(exc.value)
    assert "Traceback" not in str(exc.value)
