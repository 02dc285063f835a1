"""Issue 16 (add-on half) and issue 14's add-on items, in the real bpy: soft bodies, pass-through
of what the add-on does not edit, fitted collision primitives, mass from density, export
options, joint tools, sensors. One Blender session for the module; each test starts empty."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from conftest import CORPUS, ROOT, corpus_files, corpus_id, require_corpus

bpy = pytest.importorskip("bpy")
from blender_fixtures import cube  # noqa: E402

from adfkit.adf import read_file  # noqa: E402
from adfkit.adf.writer import file_to_plain  # noqa: E402
from adfkit.diagnostics import AdfError, Severity  # noqa: E402

SB = CORPUS / "ambf/ambf_models/descriptions/multi-bodies/sb"
SAMPLES = sorted(
    p for p in (ROOT / "sample_scenes").glob("*/*.yaml") if p.stem not in ("launch", "world", "colors", "input_devices")
)


def _export(addon, scene, out: Path, name="model"):
    res = addon.export.export_scene(scene, out, name)
    assert res.ok, [d.message for d in res.diagnostics if d.severity >= Severity.ERROR]
    return res


def _cube(name, size=0.04, location=(0, 0, 0)):
    return cube(name, size, location)


def _key_paths(plain, prefix=()) -> set[tuple]:
    out = set()
    if isinstance(plain, dict):
        for k, v in plain.items():
            out.add(prefix + (str(k),))
            out |= _key_paths(v, prefix + (str(k),))
    return out


MESH_FOLDERS = ("high resolution path", "low resolution path")


def _lost(orig_path: Path, back_path: Path) -> list[str]:
    """Keys (and scalar values) the original file has and the exported one lost. Mesh folders
    are normalised by the exporter (into the output folder), so they are not compared."""
    orig, _ = read_file(orig_path, kind="model")
    back, _ = read_file(back_path, kind="model")
    a, b = file_to_plain(orig), file_to_plain(back)
    lost = []
    for key, value in a.items():
        if key in MESH_FOLDERS:
            continue
        if key not in b:
            lost.append(f"{key}: section lost")
            continue
        if isinstance(value, list) and all(isinstance(v, str) for v in value):
            missing = [v for v in value if v not in b[key]]
            lost += [f"{key}: {v} not listed" for v in missing]
        elif isinstance(value, dict):
            for path in _key_paths(value) - _key_paths(b[key]):
                if path[-1] not in MESH_FOLDERS:
                    lost.append(f"{key}: {' / '.join(path)} lost")
        elif not isinstance(value, list) and value != b[key]:
            lost.append(f"{key}: {value!r} became {b[key]!r}")
    return lost


# --- soft bodies ---------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["cloth.yaml", "cloth2.yaml"])
def test_corpus_cloth_import_export_keeps_every_soft_body_key(addon, scene, tmp_path, name):
    require_corpus()
    made, _ = addon.build.import_model(SB / name)
    cloth = next(o for o in made if o.adf.kind == "SOFT_BODY")
    orig, _ = read_file(SB / name)
    (sb,) = orig.soft_bodies
    from adfkit.geometry.softmesh import load_soft_mesh

    nodes = load_soft_mesh(SB / "low_res/cloth.3DS").nodes
    assert cloth.type == "MESH" and len(cloth.data.vertices) == len(nodes)  # vertex i is node i
    assert [c for v in cloth.data.vertices[:3] for c in v.co] == pytest.approx(nodes[:3].ravel().tolist(), abs=1e-6)
    grp = cloth.vertex_groups[cloth.adf.soft.fixed_group]
    assert [v.index for v in cloth.data.vertices if any(g.group == grp.index for g in v.groups)] == sorted(
        sb.config.fixed_nodes
    )
    assert cloth.adf.soft.use_config_klst and cloth.adf.soft.config_klst == pytest.approx(sb.config.kLST)
    res = _export(addon, scene, tmp_path, Path(name).stem)
    back, _ = read_file(res.path)
    (sb2,) = back.soft_bodies
    from adfkit.adf.writer import node_to_plain

    p1, p2 = node_to_plain(sb), node_to_plain(sb2)
    for k in MESH_FOLDERS:
        p1.pop(k, None), p2.pop(k, None)
    assert p1 == p2  # every soft-body key and value, config included
    assert (tmp_path / back.low_resolution_path / sb2.mesh).is_file()
    assert _lost(SB / name, res.path) == []


def _grid(name: str, n: int = 5, size: float = 0.1):
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=n, y_subdivisions=n, size=size)
    o = bpy.context.active_object
    o.name = o.data.name = name
    return o


def test_soft_body_authored_with_fixed_nodes_from_a_vertex_group(addon, scene, tmp_path):
    from adfkit.geometry.softmesh import load_soft_mesh

    pad = _grid("Pad")
    addon.authoring.mark(pad, "SOFT_BODY")
    s = pad.adf.soft
    assert s.use_mass and s.mass == 1.0  # a flat sheet: no volume, AMBF's 1 kg stays
    s.mass = 0.05
    for prop, value in (
        ("config_klst", 0.4),
        ("config_kdp", 0.02),
        ("config_piterations", 8),
        ("config_bending_constraint", 2),
        ("randomize_constraints", True),
    ):
        setattr(s, "use_" + prop, True)
        setattr(s, prop, value)
    corners = [v.index for v in pad.data.vertices if v.co.y > 0.049 and abs(v.co.x) > 0.049]
    assert len(corners) == 2
    for v in pad.data.vertices:
        v.select = v.index in corners
    assert addon.authoring.fix_selected_nodes(pad) == corners
    res = _export(addon, scene, tmp_path)
    doc, _ = read_file(res.path)
    (sb,) = doc.soft_bodies
    assert sb.identifier == "SOFT Pad" and sb.mass == 0.05 and sb.randomize_constraints is True
    assert (sb.config.kLST, sb.config.kDP, sb.config.piterations, sb.config.bending_constraint) == (0.4, 0.02, 8, 2)
    # the written node numbering (AMBF's) puts the fixed nodes where the group's vertices are
    nodes = load_soft_mesh(tmp_path / doc.low_resolution_path / sb.mesh).nodes
    fixed = nodes[sb.config.fixed_nodes]
    assert len(fixed) == 2 and (fixed[:, 1] > 0.049).all() and (abs(fixed[:, 0]) > 0.049).all()
    from adfkit.validator import validate_file

    assert [d for d in validate_file(res.path).diagnostics if d.severity >= Severity.ERROR] == []
    bpy.ops.wm.read_factory_settings(use_empty=True)
    (obj,), _ = addon.build.import_model(res.path)
    grp = obj.vertex_groups[obj.adf.soft.fixed_group]
    back = sorted(v.index for v in obj.data.vertices if any(g.group == grp.index for g in v.groups))
    assert back == sb.config.fixed_nodes


@pytest.mark.parametrize("path", SAMPLES, ids=[p.parent.name + "/" + p.name for p in SAMPLES])
def test_bundled_sample_scenes_lose_nothing_on_import_export(addon, scene, tmp_path, path):
    addon.build.import_model(path)
    res = _export(addon, scene, tmp_path, path.stem)
    assert _lost(path, res.path) == []


CORPUS_MODELS = [
    p
    for p in corpus_files()
    if "bodies" in p.read_text(errors="replace")[:4000]
    and not p.name.startswith(("world", "launch", "input_devices", "color"))
]


@pytest.mark.slow
@pytest.mark.parametrize("path", CORPUS_MODELS, ids=[corpus_id(p) for p in CORPUS_MODELS])
def test_every_corpus_model_loses_nothing_on_import_export(addon, scene, tmp_path, path):
    try:
        _, diags = read_file(path, kind="model")
    except AdfError as exc:
        pytest.skip(f"not a model file the reader accepts: {exc.diagnostics[0].message}")
    from adfkit.validator.engine import SEVERITY_OVERRIDES

    bad = [d for d in diags if SEVERITY_OVERRIDES.get(d.rule, d.severity) >= Severity.ERROR]
    if bad:
        pytest.skip(f"AMBF rejects this file too ({bad[0].rule}: {bad[0].message})")
    addon.build.import_model(path)
    res = addon.export.export_scene(scene, tmp_path, path.stem)
    assert res.ok, [d.format() for d in res.diagnostics if d.severity >= Severity.ERROR]
    assert _lost(path, res.path) == []


def test_vehicles_and_unknown_sections_pass_through(addon, scene, tmp_path):
    src = tmp_path / "src.yaml"
    src.write_text("""bodies: [BODY chassis]
vehicles: [VEHICLE car]
my tool section: {keep: [1, 2, 3]}
BODY chassis:
  name: chassis
  mass: 2.0
  collision shape: BOX
  collision geometry: {x: 0.4, y: 0.2, z: 0.1}
  location: {position: {x: 0.0, y: 0.0, z: 0.1}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  a key adfkit does not know: 42
VEHICLE car:
  name: car
  chassis: BODY chassis
  wheels: []
""")
    addon.build.import_model(src)
    res = _export(addon, scene, tmp_path / "out", "src")
    assert _lost(src, res.path) == []
    doc, _ = read_file(res.path)
    assert [v.identifier for v in doc.vehicles] == ["VEHICLE car"]
    assert doc.extras["my tool section"] == {"keep": [1, 2, 3]}
    assert doc.bodies[0].extras["a key adfkit does not know"] == 42


# --- sensors (issue 14) --------------------------------------------------------------------


def test_sensor_with_full_name_parent_and_unknown_type_is_attached_and_carried(addon, scene, tmp_path):
    src = tmp_path / "exo.yaml"
    src.write_text("""bodies: [BODY ExoRightFoot]
sensors: [SENSOR toe, SENSOR heel]
namespace: /ambf/env/
BODY ExoRightFoot:
  name: ExoRightFoot
  mass: 0.5
  collision shape: BOX
  collision geometry: {x: 0.2, y: 0.1, z: 0.05}
  location: {position: {x: 0.0, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
SENSOR toe:
  name: toe
  type: CONTACT
  parent: /ambf/env/BODY ExoRightFoot
  location: {position: {x: 0.1, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  range: 0.01
  array: [{offset: {x: 0.0, y: 0.0, z: 0.0}, direction: {x: 0.0, y: 0.0, z: -1.0}}]
SENSOR heel:
  name: heel
  type: Resistance
  parent: BODY ExoRightFoot
  location: {position: {x: -0.1, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  range: 0.01
  array: [{offset: {x: 0.0, y: 0.0, z: 0.0}, direction: {x: 0.0, y: 0.0, z: -1.0}}]
  friction: {static: 0.5, dynamic: 0.2, damping: 0.3, variable: true}
  contact area: 0.002
  contact stiffness: 800.0
  contact damping: 5.0
""")
    made, _ = addon.build.import_model(src)
    foot = bpy.data.objects["ExoRightFoot"]
    toe, heel = bpy.data.objects["toe"], bpy.data.objects["heel"]
    assert toe.parent == foot and heel.parent == foot
    assert tuple(toe.matrix_world.translation) == pytest.approx((0.1, 0.0, 0.5), abs=1e-6)
    h = heel.adf.sensor
    assert (h.use_contact_stiffness, h.contact_stiffness, h.use_friction_variable) == (True, 800.0, True)
    h.contact_stiffness = 900.0  # edited in the panel
    res = _export(addon, scene, tmp_path / "out", "exo")
    assert any(
        d.rule == "sensor-type" and "AMBF 2.0" in d.message and d.severity == Severity.WARNING for d in res.diagnostics
    )
    doc, _ = read_file(res.path)
    t, hh = doc.sensors
    assert (t.type, t.parent) == ("CONTACT", "/ambf/env/BODY ExoRightFoot")
    assert hh.contact_stiffness == 900.0 and hh.friction.dynamic == 0.2 and hh.contact_area == 0.002


# --- collision primitives ------------------------------------------------------------------


def _tilted_cylinder(radius=0.02, depth=0.12):
    bpy.ops.mesh.primitive_cylinder_add(vertices=64, radius=radius, depth=depth)
    o = bpy.context.active_object
    o.name = o.data.name = "Rod"
    from mathutils import Matrix

    o.data.transform(Matrix.Rotation(math.radians(35), 4, "X") @ Matrix.Translation((0.01, 0.0, 0.0)))
    return o


def test_fit_primitive_on_a_cylinder_mesh_is_within_two_percent(addon, scene, tmp_path):
    rod = _tilted_cylinder()
    addon.authoring.mark(rod, "BODY")
    cyl = addon.authoring.fit_collision_primitive(rod, "CYLINDER")
    s = cyl.adf.shape
    assert s.radius == pytest.approx(0.02, rel=0.02) and s.height == pytest.approx(0.12, rel=0.02)
    axis = cyl.matrix_world.to_3x3() @ __import__("mathutils").Vector(
        (0, 0, 1) if s.axis == "z" else (1, 0, 0) if s.axis == "x" else (0, 1, 0)
    )
    tilt = math.degrees(
        math.acos(min(1.0, abs(axis.dot((0.0, -math.sin(math.radians(35)), math.cos(math.radians(35)))))))
    )
    assert tilt < 1.0
    # the outline is the fitted cylinder: its bounding radius and length
    loc = [cyl.matrix_world @ v.co for v in cyl.data.vertices]
    assert max((p - cyl.matrix_world.translation).length for p in loc) == pytest.approx(
        math.hypot(0.02, 0.06), rel=0.02
    )
    cap = addon.authoring.fit_collision_primitive(rod, "CAPSULE")
    assert [c.name for c in rod.children] == [cap.name]  # replaced, not stacked
    assert cap.adf.shape.radius >= 0.0199 and cap.adf.shape.height >= 0.12
    for shape in ("BOX", "SPHERE", "CONE"):
        addon.authoring.fit_collision_primitive(rod, shape)
    res = _export(addon, scene, tmp_path)
    doc, _ = read_file(res.path)
    (cone,) = doc.bodies[0].compound_collision_shape
    assert cone.shape.lower() == "cone" and cone.geometry.radius == pytest.approx(0.02, rel=0.02)


def test_primitive_outline_follows_edited_size(addon, scene):
    body = _cube("Box")
    addon.authoring.mark(body, "BODY")
    prim = addon.authoring.add_collision_primitive(body, "BOX", size=(0.1, 0.1, 0.1))
    assert tuple(prim.dimensions) == pytest.approx((0.1, 0.1, 0.1))
    prim.adf.shape.size = (0.3, 0.2, 0.05)
    assert tuple(prim.dimensions) == pytest.approx((0.3, 0.2, 0.05), abs=1e-6)
    prim.adf.shape.shape = "CAPSULE"
    prim.adf.shape.radius, prim.adf.shape.height, prim.adf.shape.axis = 0.01, 0.08, "x"
    assert tuple(prim.dimensions) == pytest.approx((0.08, 0.02, 0.02), abs=1e-4)


def test_missing_geometry_package_is_a_readable_error(addon):
    with pytest.raises(AdfError) as exc:
        addon.authoring.geometry("no_such_geometry_module")
    d = exc.value.diagnostics[0]
    assert d.rule == "geometry-unavailable" and "not installed in Blender's Python" in d.message
    assert "trimesh, manifold3d, coacd, scipy" in d.hint


# --- mass, inertia -------------------------------------------------------------------------


def test_mass_follows_density_unless_typed(addon, scene, tmp_path):
    link = _cube("Link", 0.04)
    addon.authoring.mark(link, "BODY")
    b = link.adf.body
    assert b.mass == pytest.approx(1000 * 0.04**3, rel=1e-4) and not b.mass_typed  # 64 g, not 1 kg
    link.adf.density = 2700.0
    assert b.mass == pytest.approx(2700 * 0.04**3, rel=1e-4)
    addon.authoring.estimate_body(link)
    assert b.mass == pytest.approx(2700 * 0.04**3, rel=1e-4)
    assert b.inertia[0] == pytest.approx(b.mass * 0.04**2 / 6, rel=1e-3)
    heavy = _cube("Heavy", 0.04, (0.2, 0, 0))
    addon.authoring.mark(heavy, "BODY")
    heavy.adf.body.mass = 0.5  # typed by hand
    assert heavy.adf.body.mass_typed
    heavy.adf.density = 100.0
    plane = bpy.data.objects.new("Floor", None)
    bpy.context.scene.collection.objects.link(plane)
    addon.authoring.mark(plane, "BODY")
    done, skipped = addon.authoring.estimate_all(bpy.context.scene)
    assert sorted(o.name for o in done) == ["Heavy", "Link"]
    assert heavy.adf.body.mass == 0.5 and heavy.adf.body.inertia[0] == pytest.approx(0.5 * 0.04**2 / 6, rel=1e-3)


# --- export options ------------------------------------------------------------------------


def test_precision_modifiers_and_decimated_low_res(addon, scene, tmp_path):
    o = _cube("Skin", 0.05, (0.1, 0.2, 0.3))
    addon.authoring.mark(o, "BODY")
    o.adf.body.mass = 0.005
    o.modifiers.new("sub", "SUBSURF").levels = 2
    sc = scene.adf
    sc.low_res_ratio = 0.25
    res = _export(addon, scene, tmp_path / "a")
    text = res.path.read_text()
    assert "mass: 0.005\n" in text and "{x: 0.1, y: 0.2, z: 0.3}" in text and "0.0049999" not in text
    hi = (tmp_path / "a/meshes/high_res/Skin.OBJ").read_text()
    lo = (tmp_path / "a/meshes/low_res/Skin.OBJ").read_text()
    assert hi.count("\nv ") == 98  # a cube subdivided twice: 98 vertices, 96 quads
    assert 0 < lo.count("\nf ") < hi.count("\nf ") // 2
    sc.apply_modifiers, sc.low_res_ratio = False, 1.0
    res = _export(addon, scene, tmp_path / "b")
    assert (tmp_path / "b/meshes/high_res/Skin.OBJ").read_text().count("\nv ") == 8


# --- joints, lights, findings --------------------------------------------------------------


def _two_bodies(addon, jtype="revolute"):
    base = _cube("Base", 0.1)
    arm = _cube("Arm", 0.04, (0.0, 0.0, 0.2))
    for o in (base, arm):
        addon.authoring.mark(o, "BODY")
    base.adf.body.mass = 0.0
    return base, arm, addon.authoring.add_joint(base, arm, jtype, name="J")


def test_joint_limits_typed_in_the_panel_are_mirrored_on_the_constraint(addon, scene):
    _, _, j = _two_bodies(addon)
    p, rbc = j.adf.joint, j.rigid_body_constraint
    p.use_limit_low = p.use_limit_high = True
    p.limit_low, p.limit_high = -0.5, 1.25
    assert rbc.use_limit_ang_z and (rbc.limit_ang_z_lower, rbc.limit_ang_z_upper) == pytest.approx((-0.5, 1.25))
    p.use_limit_high = False
    assert not rbc.use_limit_ang_z
    _, _, s = _two_bodies(addon, "prismatic")
    q = s.adf.joint
    q.use_limit_low = q.use_limit_high = True
    q.limit_low, q.limit_high = -0.02, 0.03
    rs = s.rigid_body_constraint
    assert rs.use_limit_lin_x and (rs.limit_lin_x_lower, rs.limit_lin_x_upper) == pytest.approx((-0.02, 0.03))


def test_gains_hide_show_and_cleanup(addon, scene):
    import importlib

    from mathutils import Matrix

    tuning = importlib.import_module(addon.__name__ + ".tuning")
    base, arm = _cube("Base", 0.1), _cube("Arm", 0.04, (0.0, 0.0, 0.2))
    for o in (base, arm):
        addon.authoring.mark(o, "BODY")
    arm.adf.body.use_inertia, arm.adf.body.inertia = True, (1e-4, 1e-4, 1e-4)
    # hinge about world X through (0, 0, 0.1): the arm's centre is 0.1 m off the axis
    j = addon.authoring.add_joint(
        base, arm, "revolute", Matrix.Translation((0, 0, 0.1)) @ Matrix.Rotation(math.pi / 2, 4, "Y"), "J"
    )
    m = 1000 * 0.04**3
    load = m * 0.1**2 + 1e-4
    done = tuning.estimate_gains(scene, [j], frequency_hz=2.0, damping_ratio=1.0)
    w = 2 * math.pi * 2.0
    assert done["J"] == pytest.approx((load * w * w, 2 * load * w), rel=1e-4)
    assert j.adf.joint.use_controller_p and j.adf.joint.controller_p == pytest.approx(load * w * w, rel=1e-4)
    assert tuning.show_joints(scene, False) == 1 and j.hide_get()
    tuning.show_joints(scene, True)
    assert not j.hide_get()
    stray = addon.authoring.add_collision_primitive(arm, "SPHERE", radius=0.01)
    stray.parent = None
    lost = _cube("Gone", 0.02, (1, 0, 0))
    addon.authoring.mark(lost, "BODY")
    addon.authoring.add_joint(arm, lost, "fixed", name="K")
    bpy.data.objects.remove(lost, do_unlink=True)
    said = tuning.cleanup(scene)
    assert sorted(said) == [
        f"removed collision {stray.name if False else 'Arm.sphere'} (not under a body)",
        "removed joint K (no parent or child body)",
    ]
    assert "K" not in bpy.data.objects and "J" in bpy.data.objects


def test_new_light_has_shadow_quality_and_findings_are_said_once(addon, scene, tmp_path):
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "SPOT"))
    scene.collection.objects.link(lamp)
    addon.authoring.mark(lamp, "LIGHT")
    assert lamp.adf.light.use_shadow_quality and lamp.adf.light.shadow_quality == 5
    lamp.adf.light.use_shadow_quality = False
    found = addon.authoring.problems(scene)
    assert len([f for f in found if "shadow quality" in f]) == 1, found
    res = addon.export.export_scene(scene, tmp_path)
    assert len([d for d in res.diagnostics if d.rule == "light-shadow"]) == 1


def test_panels_offer_gravity_publish_and_resistance_keys(addon, scene, tmp_path):
    body = _cube("Link")
    addon.authoring.mark(body, "BODY")
    b = body.adf.body
    b.use_gravity, b.gravity = True, (0.0, 0.0, -1.62)
    b.use_publish_joint_positions = b.publish_joint_positions = True
    b.use_publish_frequency_low, b.publish_frequency_low = True, 20
    b.use_publish_frequency_high, b.publish_frequency_high = True, 200
    res = _export(addon, scene, tmp_path)
    doc, _ = read_file(res.path)
    link = doc.bodies[0]
    assert tuple(link.gravity) == pytest.approx((0.0, 0.0, -1.62)) and link.publish_joint_positions is True
    assert link.publish_frequency.low == 20
    ui = __import__("importlib").import_module(addon.__name__ + ".ui")
    fields = addon.fields
    sensor = bpy.data.objects.new("S", None)
    scene.collection.objects.link(sensor)
    sensor.adf.kind = "SENSOR"
    s = sensor.adf.sensor
    shown = lambda: {f.prop for f in fields.SENSOR if ui._visible("SENSOR", s, f)}  # noqa: E731
    assert "contact_stiffness" not in shown()
    s.use_type, s.type = True, "Resistance"
    assert fields.RESISTANCE_ONLY <= shown()


def test_operators_run_from_blender(addon, scene, tmp_path):
    """The buttons, through bpy.ops as the UI calls them (poll included)."""
    rod = _tilted_cylinder()
    bpy.context.view_layer.objects.active = rod
    assert bpy.ops.adf.mark(kind="BODY") == {"FINISHED"}
    assert bpy.ops.adf.fit_collision_primitive(shape="CYLINDER") == {"FINISHED"}
    assert [c.adf.shape.shape for c in rod.children] == ["CYLINDER"]
    assert bpy.ops.adf.estimate_all() == {"FINISHED"}
    assert rod.adf.body.inertia[0] > 0 and not rod.adf.body.mass_typed
    assert bpy.ops.adf.estimate_gains() == {"FINISHED"}
    assert bpy.ops.adf.show_joints(show=False) == {"FINISHED"}
    assert bpy.ops.adf.check() == {"FINISHED"}
    assert bpy.ops.adf.cleanup() == {"FINISHED"}
    pad = _grid("Pad")
    bpy.context.view_layer.objects.active = pad
    pad.select_set(True)
    rod.select_set(False)
    assert bpy.ops.adf.mark(kind="SOFT_BODY") == {"FINISHED"}
    assert bpy.ops.adf.fix_selected_nodes() == {"FINISHED"}
    assert bpy.ops.adf.export_model(directory=str(tmp_path), model_name="ops") == {"FINISHED"}
    doc, _ = read_file(tmp_path / "ops.yaml")
    assert [b.identifier for b in doc.bodies] == ["BODY Rod"] and len(doc.soft_bodies) == 1
    assert len(doc.soft_bodies[0].config.fixed_nodes) == len(pad.data.vertices)  # all were selected


def test_a_tissue_pad_with_thickness_exports_its_shell_and_its_mass(addon, scene, tmp_path):
    """Grid + Solidify as a soft body, border nodes fixed, through the operators: the exported
    mesh is the solid shell (both faces), the mass is density × its volume, the estimate acts on
    the soft body (not on rigid-body settings), and a flat sheet says why it has no mass."""
    import numpy as np

    from adfkit.geometry.softmesh import load_soft_mesh

    n, size, thick = 9, 0.1, 0.004
    pad = _grid("Pad", n, size)
    solid = pad.modifiers.new("Solidify", "SOLIDIFY")
    solid.thickness = thick
    pad.adf.density = 1000.0
    bpy.context.view_layer.objects.active = pad
    pad.select_set(True)
    assert bpy.ops.adf.mark(kind="SOFT_BODY") == {"FINISHED"}
    s = pad.adf.soft
    assert s.use_mass and s.mass == pytest.approx(1000.0 * size * size * thick, rel=1e-4) and s.mass_note == ""
    border = [v.index for v in pad.data.vertices if max(abs(v.co.x), abs(v.co.y)) > size / 2 - 1e-6]
    for v in pad.data.vertices:
        v.select = v.index in border
    assert bpy.ops.adf.fix_selected_nodes() == {"FINISHED"}
    assert bpy.ops.adf.estimate_inertia() == {"FINISHED"}  # acts on the soft body's mass
    assert pad.adf.body.use_inertia is False
    res = _export(addon, scene, tmp_path / "out")
    doc, _ = read_file(res.path)
    (sb,) = doc.soft_bodies
    nodes = load_soft_mesh(tmp_path / "out" / doc.low_resolution_path / sb.mesh).nodes
    assert len(nodes) == 2 * len(pad.data.vertices)  # both faces of the shell
    assert np.ptp(nodes[:, 2]) == pytest.approx(thick, rel=1e-3)
    assert len(sb.config.fixed_nodes) == 2 * len(border)  # the rim fixed on both faces
    assert sb.mass == pytest.approx(1000.0 * size * size * thick, rel=1e-4)
    # a flat sheet says why it has no mass from density, and the estimate says so too
    pad.modifiers.remove(solid)
    addon.authoring.mass_from_density(pad)
    assert "not closed" in s.mass_note
    with pytest.raises(RuntimeError, match="Solidify"):
        bpy.ops.adf.estimate_inertia()
