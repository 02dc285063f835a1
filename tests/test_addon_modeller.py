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
