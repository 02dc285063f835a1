"""The add-on as a modeller uses it all day (headless bpy): the geometry tools measure the mesh
export writes, computed numbers carry no float32 error, and what AMBF's own add-on offered.
One Blender session for the module; each test starts from an empty scene."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

bpy = pytest.importorskip("bpy")
from blender_fixtures import cube  # noqa: E402

from adfkit.adf import read_file  # noqa: E402
from adfkit.diagnostics import AdfError, Severity  # noqa: E402


def _export(addon, scene, out: Path, name="model"):
    res = addon.export.export_scene(scene, out, name)
    assert res.ok, [d.message for d in res.diagnostics if d.severity >= Severity.ERROR]
    return res


def _pad(thickness: float | None = 0.004):
    """A 0.2 m plane, with a Solidify modifier of ``thickness`` (none: flat)."""
    bpy.ops.mesh.primitive_plane_add(size=0.2)
    pad = bpy.context.active_object
    pad.name = pad.data.name = "Pad"
    if thickness is not None:
        pad.modifiers.new("Solidify", "SOLIDIFY").thickness = thickness
    return pad


# --- the geometry tools measure the mesh export writes --------------------------------------


def test_a_solidified_plane_gets_its_evaluated_mass_box_inertia_and_hulls(addon, scene, tmp_path):
    """A plane with a 4 mm Solidify is a 0.2 x 0.2 x 0.004 slab (what export writes): marking it
    gives density x that volume, the fitted box is the slab, the inertia is the slab's, CoACD
    makes hulls of it. With Apply modifiers off export writes the flat plane, and the same tools
    say so."""
    a = addon.authoring
    pad = _pad()
    a.mark(pad, "BODY")
    b = pad.adf.body
    assert b.mass == pytest.approx(1000 * 0.2 * 0.2 * 0.004, rel=1e-6) and b.mass_note == ""  # 0.16 kg, not 1 kg
    box = a.fit_collision_primitive(pad, "BOX")
    assert sorted(box.adf.shape.size) == pytest.approx([0.004, 0.2, 0.2], rel=1e-6)  # float32 properties
    a.estimate_body(pad)
    m = 0.16
    assert sorted(b.inertia) == pytest.approx(sorted([m * (0.04 + 0.004**2) / 12] * 2 + [m * 0.08 / 12]), rel=1e-6)
    assert tuple(b.inertial_offset[:3]) == pytest.approx((0.0, 0.0, -0.002), abs=1e-8)  # Solidify goes below
    hulls = a.generate_collision(pad, threshold=0.1, max_hulls=2)
    zs = [(c.matrix_world @ v.co).z for c in hulls for v in c.data.vertices]
    assert hulls and max(zs) - min(zs) == pytest.approx(0.004, abs=2e-4)
    res = _export(addon, scene, tmp_path / "out")
    assert "  mass: 0.16\n" in res.path.read_text()
    # export without the modifiers: the tools measure that flat plane and say why they cannot
    scene.adf.apply_modifiers = False
    flat = _pad()
    a.mark(flat, "BODY")
    assert "flat" in flat.adf.body.mass_note and "Solidify" in flat.adf.body.mass_note
    for call in (lambda: a.fit_collision_primitive(flat, "BOX"), lambda: a.estimate_body(flat)):
        with pytest.raises(AdfError) as exc:
            call()
        assert exc.value.diagnostics[0].rule in ("mesh-flat", "mesh-not-closed")


def test_the_documented_cube_exports_its_numbers_without_float32_error(addon, scene, tmp_path):
    """docs/blender.md: a 4 cm link of 1000 kg/m³ gets 64 g. Exported: mass 0.064 (not
    0.063999996), the centre of mass 0 (not 2.2e-10), no rotated principal axes; a cone fitted
    upside down is turned by pi exactly (not -3.1415926072)."""
    a = addon.authoring
    link = cube("Link", 0.04)
    a.mark(link, "BODY")
    a.estimate_body(link)
    bpy.ops.mesh.primitive_cone_add(radius1=0.02, depth=0.06, location=(0.3, 0, 0))
    cone = bpy.context.active_object
    cone.name = "Cone"
    cone.data.transform(__import__("mathutils").Matrix.Rotation(math.pi, 4, "X"))  # apex down
    a.mark(cone, "BODY")
    fitted = a.fit_collision_primitive(cone, "CONE")
    res = _export(addon, scene, tmp_path / "out")
    text = res.path.read_text()
    block = text[text.index("BODY Link:") :]
    assert "  mass: 0.064\n" in block and "  inertia: {ix: 1.706667e-05, iy: 1.706667e-05, iz: 1.706667e-05}\n" in block
    assert "    position: {x: 0.0, y: 0.0, z: 0.0}\n    orientation: {r: 0.0, p: 0.0, y: 0.0}\n" in block
    cone_block = text[text.index("BODY Cone:") :]
    assert "radius: 0.02\n" in cone_block and "height: 0.06\n" in cone_block
    assert "orientation: {r: 3.1415926536, p: 0.0, y: 0.0}" in cone_block
    # moved by the modeller, the cone is written where it now stands
    fitted.rotation_euler.x += 0.5
    bpy.context.view_layer.update()
    doc, _ = read_file(_export(addon, scene, tmp_path / "moved").path)
    (entry,) = doc.body("BODY Cone").compound_collision_shape
    assert entry.offset.rpy()[0] == pytest.approx(math.pi + 0.5 - 2 * math.pi, abs=1e-6)


# --- export refuses an empty scene, visible, the model's keys in the sidebar ----------------


def test_an_empty_export_is_refused_and_writes_nothing(addon, scene, tmp_path):
    res = addon.export.export_scene(scene, tmp_path / "out")
    assert not res.ok and [d.rule for d in res.diagnostics] == ["export-empty"]
    assert not (tmp_path / "out").exists()
    plain = cube("Plain")  # an object without an ADF kind is not a model either
    assert bpy.ops.adf.check() == {"FINISHED"} and "nothing to export" in scene.adf.findings
    body = cube("Body", location=(0.2, 0, 0))
    addon.authoring.mark(body, "BODY")
    for o in scene.objects:
        o.select_set(o is plain)
    with pytest.raises(RuntimeError, match="no selected object is an ADF object"):
        bpy.ops.adf.export_model(directory=str(tmp_path / "sel"), use_selection=True)
    assert not (tmp_path / "sel").exists()
    assert _export(addon, scene, tmp_path / "all").ok  # with its body, the scene exports


def test_visible_round_trips_and_the_sidebar_shows_every_model_key(addon, scene, tmp_path):
    """`visible: false` (the challenge's phantom has 52 visible keys) is a body and soft-body
    key: written when ticked, read back on import, written again as it came in. Every
    model-level key with a "write it" switch is in the sidebar (ignore inter-collision was not)."""
    hidden = cube("Hidden")
    addon.authoring.mark(hidden, "BODY")
    hidden.adf.body.use_visible, hidden.adf.body.visible = True, False
    first = _export(addon, scene, tmp_path / "a")
    assert "  visible: false\n" in first.path.read_text()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon.build.import_model(first.path)
    b = bpy.data.objects["Hidden"].adf.body
    assert b.use_visible and not b.visible
    again = _export(addon, bpy.context.scene, tmp_path / "b")
    assert again.path.read_text() == first.path.read_text()
    assert "visible" in {f.prop for f in addon.fields.SOFT}
    ui = __import__("importlib").import_module(addon.__name__ + ".ui")
    scene_props = bpy.context.scene.adf.bl_rna.properties.keys()
    switched = {k for k in scene_props if "use_" + k in scene_props}
    assert switched == set(ui.MODEL_KEYS) and "ignore_inter_collision" in switched


# --- joints: gains for every joint, springs that hold ---------------------------------------


def _select(active, *others):
    for o in bpy.context.scene.objects:
        o.select_set(o is active or o in others)
    bpy.context.view_layer.objects.active = active


def _base_and_arms(addon, n=2):
    base = cube("Base", 0.1)
    addon.authoring.mark(base, "BODY")
    base.adf.body.mass = 0.0
    arms = []
    for i in range(n):
        arm = cube(f"Arm{i}", 0.04, (0.2 * (i + 1), 0.0, 0.0))
        addon.authoring.mark(arm, "BODY")
        arms.append(arm)
    return base, arms


def test_gains_for_every_new_joint_and_check_names_a_joint_without_any(addon, scene):
    """Joints added one after the other through the operator (each new joint stays selected):
    Estimate joint controller gains sets every joint's controller. Before, Check says which
    hinge has none; a passive one is not driven, so it is not named."""
    base, arms = _base_and_arms(addon, 3)
    for arm in arms:
        _select(arm, base)
        assert bpy.ops.adf.add_joint(joint_type="revolute") == {"FINISHED"}
    joints = sorted((o for o in scene.objects if o.adf.kind == "JOINT"), key=lambda o: o.name)
    passive = joints[2].adf.joint
    passive.use_passive = passive.passive = True
    found = addon.export.check_scene(scene)
    named = sorted(d.message.split("'")[1] for d in found if d.rule == "joint-controller")
    assert named == [j.name for j in joints[:2]]
    assert all(d.severity == Severity.INFO for d in found if d.rule == "joint-controller")
    assert [o.name for o in bpy.context.selected_objects] == [joints[-1].name]  # the last one is selected
    assert bpy.ops.adf.estimate_gains() == {"FINISHED"}
    assert all(j.adf.joint.use_controller_p and j.adf.joint.controller_p > 0 for j in joints)
    assert [d for d in addon.export.check_scene(scene) if d.rule == "joint-controller"] == []
    # the joint panel's button: the selected joints only
    for j in joints:
        j.adf.joint.controller_p = 1.0
    _select(joints[0])
    assert bpy.ops.adf.estimate_gains(selected_only=True) == {"FINISHED"}
    assert [j.adf.joint.controller_p != 1.0 for j in joints] == [True, False, False]


@pytest.mark.parametrize("jtype", ["six dof spring", "linear spring", "torsion spring"])
def test_a_new_spring_joint_holds_its_child_and_check_says_when_it_cannot(addon, scene, tmp_path, jtype):
    """A spring added between a static base and a 64 g cube (through the operator) gets limits,
    stiffness and damping: played for 2 s the cube stays within 5 mm of where it was placed (a
    spring of 10 Hz sags g/ω² ≈ 2.5 mm). Without them a six-dof spring has AMBF's defaults
    (±1.2, stiffness 1): Check says so, and the cube sinks by centimetres."""
    pytest.importorskip("pybullet")
    from adfkit.adf import load_scene
    from adfkit.runner import open_world

    base, (arm,) = _base_and_arms(addon, 1)
    _select(arm, base)
    assert bpy.ops.adf.add_joint(joint_type=jtype) == {"FINISHED"}
    joint = next(o for o in scene.objects if o.adf.kind == "JOINT")
    assert [d.rule for d in addon.export.check_scene(scene) if d.severity >= Severity.WARNING] == []

    def drop(out: Path) -> float:
        res = _export(addon, scene, out)
        world = open_world(load_scene(res.path))
        try:
            start = world.body("Arm0").com_position()
            world.run(2.0)
            return float(math.dist(start, world.body("Arm0").com_position()))
        finally:
            world.close()

    assert drop(tmp_path / "held") < 0.005
    if jtype != "six dof spring":
        return
    p = joint.adf.joint
    for k in ("linear_low", "linear_high", "angular_low", "angular_high", "stiffness_linear", "stiffness_angular"):
        setattr(p, "use_" + k, False)
    (d,) = [d for d in addon.export.check_scene(scene) if d.rule == "spring-joint-defaults"]
    assert "no limits or stiffness" in d.message and "'Arm0'" in d.message
    assert drop(tmp_path / "defaults") > 0.02


# --- what AMBF's own add-on offered ---------------------------------------------------------


def _textured_ball(tmp: Path, name="Ball"):
    """A UV sphere (482 vertices) with a base-colour image texture."""
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.03)
    o = bpy.context.active_object
    o.name = o.data.name = name
    img = bpy.data.images.new(f"{name}_skin", 4, 4)
    img.filepath_raw = str(tmp / f"{name}_skin.png")
    img.file_format = "PNG"
    img.save()
    mat = bpy.data.materials.new(f"{name}Mat")
    mat.use_nodes = True
    bsdf = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = img
    mat.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    o.data.materials.append(mat)
    return o


def test_meshes_folder_apart_from_the_model_file(addon, scene, tmp_path):
    """A meshes folder of the scene's own: relative to the model file's folder, or absolute
    (written relative); the model names it, the meshes are there, the validator is content."""
    from adfkit.adf import visual_mesh_path
    from adfkit.validator import validate_file

    ball = cube("Link")
    addon.authoring.mark(ball, "BODY")
    for folder, want in (("../assets/meshes", "../assets/meshes/"), (str(tmp_path / "shared"), "../shared/")):
        scene.adf.meshes_path = folder
        res = _export(addon, scene, tmp_path / "model")
        doc, _ = read_file(res.path)
        assert (doc.high_resolution_path, doc.low_resolution_path) == (want + "high_res/", want + "low_res/")
        assert visual_mesh_path(doc, doc.bodies[0]).is_file()
        assert (tmp_path / "model" / want / "low_res" / "Link.OBJ").is_file()
        assert [d for d in validate_file(res.path).diagnostics if d.severity >= Severity.WARNING] == []
    assert not (tmp_path / "model" / "meshes").exists()  # nothing in the default folder


def test_switches_skip_high_res_low_res_and_textures(addon, scene, tmp_path):
    """High res / Low res / Textures off: the model still names the files, the ones already
    there are kept as they are, nothing else is written; a texture that is not there is said."""
    ball = _textured_ball(tmp_path)
    addon.authoring.mark(ball, "BODY")
    out = tmp_path / "out"
    _export(addon, scene, out)
    hi, lo = out / "meshes/high_res/Ball.OBJ", out / "meshes/low_res/Ball.OBJ"
    before = {p: p.read_bytes() for p in (hi, lo)}
    ball.data.vertices[0].co.x += 0.01  # an edit both files would take
    scene.adf.save_high_res = False
    res = _export(addon, scene, out)
    assert hi.read_bytes() == before[hi] and lo.read_bytes() != before[lo]
    assert "meshes/high_res/Ball.OBJ" not in {p.relative_to(out).as_posix() for p in res.written}
    scene.adf.save_high_res, scene.adf.save_low_res = True, False
    lo_now = lo.read_bytes()
    _export(addon, scene, out)
    assert hi.read_bytes() != before[hi] and lo.read_bytes() == lo_now
    # textures off: a fresh folder gets the meshes and the MTL, not the image, and says so
    scene.adf.save_low_res, scene.adf.save_textures = True, False
    res = _export(addon, scene, tmp_path / "fresh")
    assert (tmp_path / "fresh/meshes/high_res/Ball.mtl").is_file()
    assert not (tmp_path / "fresh/meshes/high_res/Ball_skin.png").exists()
    said = [d for d in res.diagnostics if "Ball_skin.png" in d.message]  # beside both copies of the mesh
    assert {d.rule for d in said} == {"texture-not-saved"} and any("high_res" in d.message for d in said)
    res = _export(addon, scene, out)  # where the image already is: nothing to say
    assert (out / "meshes/high_res/Ball_skin.png").is_file()
    assert [d for d in res.diagnostics if d.rule == "texture-not-saved"] == []


def test_the_constraint_axis_chosen_per_joint(addon, scene, tmp_path):
    """A hinge whose Empty's X is the axis (AMBF's add-on: Axis X): exported, the joint turns
    about that direction; with the type's own axis about the Empty's Z."""
    from mathutils import Matrix

    from adfkit.model.semantics import joint_frames

    base, (arm,) = _base_and_arms(addon, 1)
    frame = Matrix.Translation((0.1, 0.0, 0.0)) @ Matrix.Rotation(math.radians(30), 4, "Z")
    joint = addon.authoring.add_joint(base, arm, "revolute", frame, "J")
    x_axis = (math.cos(math.radians(30)), math.sin(math.radians(30)), 0.0)
    for axis, want in (("X", x_axis), ("DEFAULT", (0.0, 0.0, 1.0)), ("Y", (-x_axis[1], x_axis[0], 0.0))):
        joint.adf.joint.axis = axis
        doc, _ = read_file(_export(addon, scene, tmp_path / axis).path)
        (j,) = doc.joints
        assert tuple(j.parent_axis) == pytest.approx(want, abs=1e-6)  # the base sits at the origin
        fa, fb = joint_frames(j)
        wa, wb = doc.body("BODY Base").location * fa, doc.body("BODY Arm0").location * fb
        assert (wa.position - wb.position).norm() < 1e-7 and wa.orientation.angle_to(wb.orientation) < 1e-6


def test_show_collision_and_rename_per_object(addon, scene):
    a, b = cube("A"), cube("B", location=(0.2, 0, 0))
    for o in (a, b):
        addon.authoring.mark(o, "BODY")
        addon.authoring.add_collision_primitive(o, "BOX")
    c = cube("C", location=(0.4, 0, 0))
    addon.authoring.mark(c, "BODY")
    _select(a)
    assert bpy.ops.adf.show_collision(show=False, selected_only=True) == {"FINISHED"}
    assert [o.name for o in scene.objects if o.adf.kind == "COLLISION_SHAPE" and o.hide_get()] == ["A.box"]
    j1 = addon.authoring.add_joint(a, b, "fixed", name="first")
    j2 = addon.authoring.add_joint(b, c, "fixed", name="second")
    _select(j2)
    assert bpy.ops.adf.rename_joints(selected_only=True) == {"FINISHED"}
    assert (j1.name, j2.name) == ("first", "B-C")
    assert bpy.ops.adf.rename_joints() == {"FINISHED"} and j1.name == "A-B"


def test_fit_collision_primitives_for_all_bodies_in_one_click(addon, scene):
    """Each body's own primitive is fitted again in its shape, a body without one gets a box;
    a compound, a set of convex hulls and a flat mesh are left as they are, each with why."""
    a = addon.authoring
    ball = cube("Ball", 0.04)
    a.mark(ball, "BODY")
    a.add_collision_primitive(ball, "SPHERE", radius=0.5)  # far too big: refitted
    plain = cube("Plain", 0.06, (0.2, 0, 0))
    a.mark(plain, "BODY")
    compound = cube("Compound", 0.04, (0.4, 0, 0))
    a.mark(compound, "BODY")
    for _ in range(2):
        a.add_collision_primitive(compound, "BOX")
    hulls = cube("Hulls", 0.04, (0.6, 0, 0))
    a.mark(hulls, "BODY")
    a.generate_collision(hulls, max_hulls=1)
    flat = _pad(None)
    flat.location = (0.8, 0, 0)
    a.mark(flat, "BODY")
    assert bpy.ops.adf.fit_all_collision() == {"FINISHED"}
    shapes = {o.parent.name: o.adf.shape for o in scene.objects if o.adf.kind == "COLLISION_SHAPE"}
    assert shapes["Ball"].shape == "SPHERE" and shapes["Ball"].radius == pytest.approx(0.02 * math.sqrt(3), rel=1e-6)
    assert shapes["Plain"].shape == "BOX" and tuple(shapes["Plain"].size) == pytest.approx((0.06,) * 3, rel=1e-6)
    said = scene.adf.findings
    assert "Compound: its collision is a compound of 2 primitives" in said
    assert "Hulls: its collision is a set of collision meshes" in said and "Pad: " in said and "flat" in said
    assert bpy.ops.adf.fit_all_collision(shape="CAPSULE") == {"FINISHED"}
    assert shapes_of(scene)["Ball"] == "CAPSULE" and shapes_of(scene)["Plain"] == "CAPSULE"


def shapes_of(scene) -> dict:
    return {o.parent.name: o.adf.shape.shape for o in scene.objects if o.adf.kind == "COLLISION_SHAPE"}


def test_low_res_modifiers_make_the_collision_mesh_only(addon, scene, tmp_path):
    """Low-res modifiers (a Decimate on each body mesh over the limit) make the low-res copy of
    the visual mesh, shown or hidden in the viewport; the visual mesh and the geometry tools
    leave them out; removing them removes only them (a Solidify stays)."""
    ball = _textured_ball(tmp_path)
    addon.authoring.mark(ball, "BODY")
    mass = ball.adf.body.mass
    small = cube("Small", 0.04, (0.2, 0, 0))  # 8 vertices: under the limit, left alone
    addon.authoring.mark(small, "BODY")
    small.modifiers.new("Solidify", "SOLIDIFY")
    assert bpy.ops.adf.add_low_res_modifiers(max_vertices=100) == {"FINISHED"}
    assert [m.name for m in ball.modifiers] == ["ADF low-res"] and [m.name for m in small.modifiers] == ["Solidify"]

    def counts(out):
        _export(addon, scene, out)
        return [(out / f"meshes/{d}/Ball.OBJ").read_text().count("\nv ") for d in ("high_res", "low_res")]

    hi, lo = counts(tmp_path / "on")
    assert hi == len(ball.data.vertices) == 482 and 60 < lo <= 110
    addon.authoring.mark(ball, "BODY")
    assert ball.adf.body.mass == pytest.approx(mass, rel=1e-9)  # measured on the visual mesh
    assert bpy.ops.adf.toggle_low_res_modifiers() == {"FINISHED"}
    assert not ball.modifiers["ADF low-res"].show_viewport
    assert counts(tmp_path / "hidden") == [hi, lo]
    assert ball.modifiers["ADF low-res"].show_viewport is False  # export left the toggle as it was
    assert bpy.ops.adf.remove_low_res_modifiers() == {"FINISHED"}
    assert list(ball.modifiers) == [] and [m.name for m in small.modifiers] == ["Solidify"]
    assert counts(tmp_path / "off") == [hi, hi]


# --- scripting: docs/blender.md names every operator id and enum value ----------------------

DOCS = Path(__file__).resolve().parent.parent / "docs" / "blender.md"


def test_the_docs_name_every_operator_and_its_enum_values(addon):
    """The Scripting section's table names every registered bpy.ops.adf operator (and no
    other), and in its row every value of each of its enum arguments; the object and scene
    enums are named too."""
    import re

    text = DOCS.read_text()
    registered = set(dir(bpy.ops.adf))
    assert set(re.findall(r"bpy\.ops\.adf\.(\w+)", text)) == registered
    rows = {m.group(1): m.group(0) for m in re.finditer(r"^\| `bpy\.ops\.adf\.(\w+)\(.*$", text, re.M)}
    assert set(rows) == registered
    for name in registered:
        for p in getattr(bpy.ops.adf, name).get_rna_type().properties:
            if p.type == "ENUM":
                missing = [i.identifier for i in p.enum_items if f"`{i.identifier}`" not in rows[name]]
                assert missing == [], (name, p.identifier, missing)
    props = bpy.types.Object.bl_rna.properties["adf"].fixed_type.properties
    for enum in (
        props["kind"],
        bpy.types.Scene.bl_rna.properties["adf"].fixed_type.properties["mesh_format"],
        props["joint"].fixed_type.properties["axis"],
        props["shape"].fixed_type.properties["shape"],
    ):
        assert [i.identifier for i in enum.enum_items if f"`{i.identifier}`" not in text] == []


def test_the_docs_install_and_example_are_what_runs(addon, scene, tmp_path, monkeypatch):
    """The headless install the docs show is the call tests/bundled_child.py makes; the docs'
    example script runs as written: a 64 g link on a static base, its hinge with gains."""
    import re

    text = DOCS.read_text()
    child = (Path(__file__).resolve().parent / "bundled_child.py").read_text()
    call = re.search(r"package_install_files\((.*?)\)", text, re.S).group(1)
    assert (
        re.sub(r"filepath=[^,]*, ", "", " ".join(call.split())).strip() == 'repo="user_default", enable_on_install=True'
    )
    assert 'repo="user_default", enable_on_install=True' in child
    example = text[text.index("A link on a static base") :]
    code = example[example.index("```python\n") + 10 : example.index("```\n", example.index("```python"))]
    monkeypatch.chdir(tmp_path)
    exec(compile(code, str(DOCS), "exec"), {})
    doc, _ = read_file(tmp_path / "out" / "link.yaml")
    (joint,) = doc.joints
    assert joint.type == "revolute" and joint.controller.P > 0
    assert doc.body("BODY Cube").mass == 0.064 and doc.body("BODY Cube.001").mass == 0.0
