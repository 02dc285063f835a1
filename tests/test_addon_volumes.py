"""The Blender add-on and ADF volumes, headless with the real bpy module: importing the
drilling sample shows its bone as an iso-surface mesh object (the slices kept by reference),
and exporting it back leaves the volume exactly as it was written."""

from __future__ import annotations

import shutil

import pytest

bpy = pytest.importorskip("bpy")
pytest.importorskip("skimage", reason="scikit-image (geometry extra) is not installed")

from adfkit.adf import read_file  # noqa: E402
from adfkit.adf.writer import file_to_plain  # noqa: E402
from adfkit.diagnostics import Severity  # noqa: E402
from adfkit.scenes.drilling import write_drilling  # noqa: E402


@pytest.fixture(scope="module")
def addon():
    from adfkit.commands.blend_import import load_addon

    _, mod = load_addon()
    return mod


@pytest.fixture()
def drilling(addon, tmp_path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return write_drilling(tmp_path / "scene").parent


def test_import_shows_the_volume_as_its_iso_surface(addon, drilling):
    from adfkit.geometry.volume import iso_surface, load_volume

    made, diags = addon.build.import_model(drilling / "drill.yaml")
    assert [d for d in diags if d.severity >= Severity.WARNING] == []
    (obj,) = [o for o in bpy.context.scene.objects if o.get(addon.volumes.VOLUME_KEY) == "VOLUME Bone"]
    assert obj not in made and obj.adf.kind == "NONE"  # a picture, not an ADF object of its own
    doc, _ = read_file(drilling / "drill.yaml")
    _, faces = iso_surface(load_volume(doc, doc.volumes[0]), 0.5)
    assert len(obj.data.polygons) == len(faces) > 1000
    assert tuple(round(v, 6) for v in obj.matrix_world.translation) == (0.0, 0.0, 0.02)
    assert tuple(round(c, 3) for c in obj.color) == (0.93, 0.89, 0.78, 1.0)
    lo = min(v.co.z for v in obj.data.vertices)
    hi = max(v.co.z for v in obj.data.vertices)
    assert lo == pytest.approx(-0.012, abs=0.04 / 48) and hi == pytest.approx(0.012, abs=0.04 / 48)


def test_export_back_leaves_the_volume_as_written(addon, drilling):
    addon.build.import_model(drilling / "drill.yaml")
    res = addon.export.export_scene(bpy.context.scene, drilling, "drill_back")
    assert res.ok
    before, after = (drilling / "drill.yaml").read_text(), res.path.read_text()
    section = before[before.index("VOLUME Bone:\n") :]
    assert section in after  # byte for byte: slices by reference, every key as written
    # the whole file differs only by the mesh folders the add-on always writes
    extra = "high resolution path: meshes/high_res/\nlow resolution path: meshes/low_res/\n"
    assert after.replace(extra, "") == before
    back, _ = read_file(res.path)
    orig, _ = read_file(drilling / "drill.yaml")
    assert file_to_plain(back)["VOLUME Bone"] == file_to_plain(orig)["VOLUME Bone"]
    assert [b.identifier for b in back.bodies] == ["BODY Mount", "BODY Shaft", "BODY Burr"]  # no body for the picture


def test_a_volume_whose_slices_are_gone_is_not_shown_and_not_exported(addon, drilling):
    shutil.rmtree(drilling / "slices")
    made, diags = addon.build.import_model(drilling / "drill.yaml")
    assert [d.rule for d in diags if d.severity == Severity.WARNING] == ["file-not-found"]
    assert "the volume is kept but not shown" in diags[-1].message and "drill.yaml:" in str(diags[-1].location)
    assert not [o for o in bpy.context.scene.objects if addon.volumes.VOLUME_KEY in o]
    # the export validates what it would write, and a volume without slices is an error there
    res = addon.export.export_scene(bpy.context.scene, drilling, "drill_back")
    assert not res.ok and [d.rule for d in res.diagnostics if d.severity >= Severity.ERROR] == ["volume-slice-missing"]
    assert not (drilling / "drill_back.yaml").exists()
