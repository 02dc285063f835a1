"""The Blender add-on and ADF volumes, headless with the real bpy module: importing the
drilling sample shows its bone as an iso-surface mesh object (the slices kept by reference),
and exporting it back leaves the volume exactly as it was written."""

from __future__ import annotations

import shutil

import pytest

bpy = pytest.importorskip("bpy")
pytest.importorskip("skimage", reason="scikit-image (geometry extra) is not installed")

from conftest import ROOT  # noqa: E402

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
    assert [d.rule for d in diags if d.severity == Severity.WARNING] == ["volume-slice-missing"]
    assert "does not exist" in diags[-1].message
    assert "the volume is kept but not shown" in diags[-1].message and "drill.yaml:" in str(diags[-1].location)
    assert not [o for o in bpy.context.scene.objects if addon.volumes.VOLUME_KEY in o]
    # the export validates what it would write, and a volume without slices is an error there
    res = addon.export.export_scene(bpy.context.scene, drilling, "drill_back")
    assert not res.ok and [d.rule for d in res.diagnostics if d.severity >= Severity.ERROR] == ["volume-slice-missing"]
    assert not (drilling / "drill_back.yaml").exists()


# ---- a volume authored from a folder of slices ----------------------------------------------
SAMPLE = ROOT / "sample_scenes" / "drilling"


def _author(tmp_path, folder, **kw):
    """The Add volume operator, as the sidebar runs it; returns its result."""
    args = dict(
        directory=str(folder),
        volume_name="Bone",
        dimensions=(0.04, 0.04, 0.04),
        iso_value=0.5,
        use_colour=True,
        colour=(0.93, 0.89, 0.78, 1.0),
    )
    return bpy.ops.adf.add_volume(**{**args, **kw})


def test_a_volume_authored_from_slices_exports_as_the_sample_has_it(addon, tmp_path):
    """The drilling sample's slices authored into an empty scene, exported into another folder:
    `adfkit validate` accepts the file, its volume has the sample's keys and values (the slices
    copied beside it, as the folder lies outside the new file's tree)."""
    from adfkit.cli import main

    bpy.ops.wm.read_factory_settings(use_empty=True)
    assert _author(tmp_path, SAMPLE / "slices") == {"FINISHED"}
    (obj,) = [o for o in bpy.context.scene.objects if o.get(addon.volumes.VOLUME_KEY) == "VOLUME Bone"]
    obj.location = (0.0, 0.0, 0.02)  # moved where the sample has it: the export takes it from here
    bpy.context.view_layer.update()
    sample, _ = read_file(SAMPLE / "drill.yaml")
    from adfkit.geometry.volume import iso_surface, load_volume

    _, faces = iso_surface(load_volume(sample, sample.volumes[0]), 0.5)
    assert len(obj.data.polygons) == len(faces) > 1000  # the iso-surface in the viewport
    assert tuple(round(c, 3) for c in obj.color) == (0.93, 0.89, 0.78, 1.0)
    out = tmp_path / "out"
    res = addon.export.export_scene(bpy.context.scene, out, "bone")
    assert res.ok, [d.message for d in res.diagnostics]
    assert main(["validate", str(res.path)]) == 0
    back, _ = read_file(res.path)
    assert file_to_plain(back)["volumes"] == ["VOLUME Bone"]
    assert file_to_plain(back)["VOLUME Bone"] == file_to_plain(sample)["VOLUME Bone"]
    assert sorted(p.name for p in (out / "slices").iterdir()) == sorted(p.name for p in (SAMPLE / "slices").iterdir())


def test_an_authored_volume_inside_the_tree_is_written_relative_to_the_file(addon, tmp_path):
    """Slices beside the exported file are named where they are, not copied."""
    shutil.copytree(SAMPLE / "slices", tmp_path / "scan" / "ct")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    assert _author(tmp_path, tmp_path / "scan" / "ct", use_colour=False) == {"FINISHED"}
    res = addon.export.export_scene(bpy.context.scene, tmp_path / "model", "m")
    assert res.ok, [d.message for d in res.diagnostics]
    vol = read_file(res.path)[0].volumes[0]
    assert (vol.images.path, vol.images.prefix, vol.images.format, vol.images.count) == (
        "../scan/ct/",
        "bone_",
        "png",
        48,
    )
    assert vol.color_rgba is None and not (tmp_path / "model" / "ct").exists()


def test_check_reads_the_slices_where_they_are(addon, tmp_path):
    """The Check operator (nothing written yet) reads an authored volume's slices from its
    folder and an imported one's beside its file: no finding; a slice taken away is one."""
    shutil.copytree(SAMPLE / "slices", tmp_path / "ct")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    assert _author(tmp_path, tmp_path / "ct") == {"FINISHED"}
    assert addon.authoring.problems(bpy.context.scene) == []
    (tmp_path / "ct" / "bone_7.png").unlink()  # AMBF stacks the others: a warning
    (found,) = addon.authoring.problems(bpy.context.scene)
    assert found.startswith("WARNING: volume 'VOLUME Bone': slice 7 of 0..47 is missing")
    (tmp_path / "ct" / "bone_8.png").write_text("no picture")
    found = addon.authoring.problems(bpy.context.scene)
    assert found[0].startswith("ERROR: volume 'VOLUME Bone': slice 7 (bone_8.png) is not an image")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon.build.import_model(SAMPLE / "drill.yaml")
    assert addon.authoring.problems(bpy.context.scene) == []


def test_a_folder_with_a_gap_is_refused_with_a_reason(addon, tmp_path):
    """(every kind of bad folder: tests/test_volume_folder.py)"""
    from PIL import Image

    from adfkit.diagnostics import AdfError

    folder = tmp_path / "slices"
    folder.mkdir()
    for i in (0, 1, 3):
        Image.new("L", (8, 8), 255).save(folder / f"ct_{i}.png")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    with pytest.raises(AdfError) as exc:
        addon.volumes.author_volume(bpy.context.scene, folder, "Bone", (0.04, 0.04, 0.04), 0.5)
    (d,) = exc.value.diagnostics
    assert d.rule == "volume-slice-gap" and "ct_2.png missing" in d.message and str(folder) in d.message, d
    # the operator says it in the UI (Blender raises it to a script as a RuntimeError), nothing added
    with pytest.raises(RuntimeError, match=r"has gaps: ct_2.png missing .* — number the slices 0, 1, 2"):
        _author(tmp_path, folder)
    assert not list(bpy.context.scene.objects)


def test_bad_settings_and_a_taken_name_are_refused(addon, tmp_path):
    from adfkit.diagnostics import AdfError

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for kw, rule in (
        (dict(dimensions=(0.04, 0.0, 0.04)), "volume-dimensions"),
        (dict(iso=1.0), "volume-iso"),
        (dict(name=" "), "volume-name"),
    ):
        args = {"folder": SAMPLE / "slices", "name": "Bone", "dimensions": (0.04, 0.04, 0.04), "iso": 0.5, **kw}
        with pytest.raises(AdfError) as exc:
            addon.volumes.author_volume(scene, **args)
        assert exc.value.diagnostics[0].rule == rule
    addon.volumes.author_volume(scene, SAMPLE / "slices", "Bone", (0.04, 0.04, 0.04), 0.5)
    with pytest.raises(AdfError) as exc:
        addon.volumes.author_volume(scene, SAMPLE / "slices", "Bone", (0.04, 0.04, 0.04), 0.5)
    assert exc.value.diagnostics[0].rule == "volume-name-taken"


def test_a_project_shaped_volume_imports_under_its_parent_and_exports_as_written(addon, tmp_path):
    """The skull-base projects' shape: RGBA slices under `count: 512`, the volume hanging from a
    body at the anatomy's origin (turned 90° about z)."""
    import numpy as np
    from volume_shapes import skull_base

    from adfkit.geometry.volume import iso_surface, load_volume

    bpy.ops.wm.read_factory_settings(use_empty=True)
    skull_base(tmp_path)
    made, diags = addon.build.import_model(tmp_path / "skull.yaml")
    assert [d for d in diags if d.severity >= Severity.WARNING] == []
    (obj,) = [o for o in bpy.context.scene.objects if o.get(addon.volumes.VOLUME_KEY) == "VOLUME skull"]
    assert obj.parent is not None and obj.parent.name == "volume_Anatomical_Origin"
    assert np.allclose(obj.matrix_world.translation, (0.1, 0.21, 0.3), atol=1e-6)  # as AMBF places it
    doc, _ = read_file(tmp_path / "skull.yaml")
    data = load_volume(doc, doc.volumes[0])
    assert data.voxels.shape == (12, 16, 16)  # the 12 slices found under count 512
    assert len(obj.data.polygons) == len(iso_surface(data, 0.5)[1]) > 100
    res = addon.export.export_scene(bpy.context.scene, tmp_path, "skull_back")
    assert res.ok, [str(d) for d in res.diagnostics]
    back, _ = read_file(res.path)
    assert file_to_plain(back)["VOLUME skull"] == file_to_plain(doc)["VOLUME skull"]
