"""A volume's slices read as AMBF 2.0 reads them (checked in AMBF itself, headless, with a probe
plugin, and in CHAI3D's cMultiImage::loadFromFiles): ``count`` is the most it searches for,
indices 0..count in every width up to count's digits, the slices found stacked in order (a gap
closes up), a voxel's value the alpha of an RGBA slice and the grey of a grey one, the picture's
bottom row at -y. Volumes built in the shape the public drilling projects ship them."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("skimage", reason="scikit-image (geometry extra) is not installed")

from volume_shapes import project, skull_rgba, write_slices  # noqa: E402

from adfkit.adf import load_scene  # noqa: E402
from adfkit.cli import main  # noqa: E402
from adfkit.diagnostics import AdfError, Severity  # noqa: E402
from adfkit.geometry.volume import iso_surface, load_volume  # noqa: E402
from adfkit.geometry.volume_slices import find_slice_files  # noqa: E402
from adfkit.validator.engine import validate_file  # noqa: E402


def _load(path):
    model = load_scene(path).models[0]
    return load_volume(model, model.volumes[0])


def _rules(path):
    return [(d.severity, d.rule) for d in validate_file(path).diagnostics]


def test_count_is_the_most_ambf_searches_for_and_the_slices_found_are_the_volume(tmp_path, capsys):
    adf = project(tmp_path, slices=20, side=24, count=512)
    f = adf / "volume_a.yaml"
    data = _load(f)
    assert data.voxels.shape == (20, 24, 24) and data.count == 512
    # the RGBA slices' alpha is the value: bone 1, air 0 (their colour's luminance is not)
    alpha = skull_rgba(20, 24)[..., 3][:, ::-1] / 255.0
    assert np.array_equal(data.voxels, alpha.astype(np.float32))
    assert _rules(f) == [(Severity.INFO, "volume-slice-count")]
    assert main(["validate", str(f)]) == 0
    assert "20 slices are found" in capsys.readouterr().out
    # and it plays, 20 slices high, filling its dimensions
    out = tmp_path / "run"
    assert main(["run", str(f), "--seconds", "0.01", "--no-frames", "--out", str(out)]) == 0
    rep = json.loads((out / "report.json").read_text())
    (played,) = rep["volumes"]
    assert played["voxels"] == [24, 24, 20] and played["slices_found"] == 20 and played["triangles"] > 500


def test_a_count_below_the_slices_reads_indices_up_to_count(tmp_path):
    adf = project(tmp_path, slices=20, count=9)
    data = _load(adf / "volume_a.yaml")
    assert data.voxels.shape[0] == 10  # 0..9: AMBF tries count itself too
    assert [d.rule for d in data.findings] == ["volume-slice-count"] and "slice 9" in data.findings[0].message


def test_zero_padded_indices_are_read_up_to_the_width_of_count(tmp_path):
    from PIL import Image

    for i in range(10):
        Image.fromarray(np.full((4, 4), 200, np.uint8)).save(tmp_path / f"s_{i:03d}.png")
    # count 100 has three digits: s_000 .. s_009 are indices 0..9 (AMBF loaded all ten)
    assert find_slice_files(tmp_path, "s_", "png", 100).indices == list(range(10))
    # count 50 has two: none of them is tried (AMBF: FAILED TO LOAD VOLUME)
    assert find_slice_files(tmp_path, "s_", "png", 50).files == []


def test_a_gap_closes_up_as_in_ambf_and_is_a_warning(tmp_path):
    rgba = skull_rgba(10, 12)
    write_slices(tmp_path / "s", rgba, indices=range(10))
    (tmp_path / "s" / "plane004.png").unlink()
    (tmp_path / "m.yaml").write_text(
        "volumes: [VOLUME v]\nVOLUME v:\n  name: v\n  dimensions: {x: 0.01, y: 0.01, z: 0.01}\n"
        "  images: {path: s/, prefix: plane00, format: png, count: 10}\n"
    )
    data = _load(tmp_path / "m.yaml")
    assert data.voxels.shape[0] == 9
    assert np.array_equal(data.voxels[4], rgba[5, ::-1, :, 3] / 255.0)  # file 5 is the fifth slice
    assert [(d.severity, d.rule) for d in data.findings] == [(Severity.WARNING, "volume-slice-gap")]
    assert "slice 4 of 0..9 is missing" in data.findings[0].message


def test_the_pictures_top_row_is_the_volumes_plus_y_side_and_its_first_column_minus_x(tmp_path):
    from PIL import Image

    (tmp_path / "s").mkdir()
    for i in range(4):
        a = np.zeros((6, 8), np.uint8)
        a[0:2, 0:3] = 255  # the picture's top left corner
        Image.fromarray(a).save(tmp_path / "s" / f"g{i}.png")
    (tmp_path / "m.yaml").write_text(
        "volumes: [VOLUME v]\nVOLUME v:\n  name: v\n  dimensions: {x: 0.08, y: 0.06, z: 0.04}\n"
        "  images: {path: s/, prefix: g, format: png, count: 3}\n"
    )
    data = _load(tmp_path / "m.yaml")
    assert data.voxels.shape == (4, 6, 8) and data.findings[0].rule == "volume-slice-count"  # g3 is index count
    verts, _ = iso_surface(data, 0.5)
    assert verts[:, 1].mean() > 0.015 and verts[:, 0].mean() < -0.02  # +y, -x (AMBF's probe: row 5 of 6, column 0)


def test_colour_slices_without_alpha_are_solid_as_in_ambf_and_a_warning(tmp_path):
    from PIL import Image

    (tmp_path / "s").mkdir()
    for i in range(3):
        a = np.zeros((6, 8, 3), np.uint8)
        a[2, 2] = (200, 10, 10)
        Image.fromarray(a, "RGB").save(tmp_path / "s" / f"r{i}.png")
    grey = np.zeros((6, 8), np.uint8)
    grey[1, 1] = 200
    Image.fromarray(grey).save(tmp_path / "s" / "g0.png")
    rgba = np.zeros((6, 8, 4), np.uint8)
    rgba[3, 3] = (20, 20, 20, 250)  # dark but opaque: solid
    rgba[4, 4] = (250, 250, 250, 30)  # bright but nearly transparent: not
    Image.fromarray(rgba, "RGBA").save(tmp_path / "s" / "a0.png")
    text = "volumes: [VOLUME v]\nVOLUME v:\n  name: v\n  dimensions: {x: 0.08, y: 0.06, z: 0.04}\n"
    (tmp_path / "rgb.yaml").write_text(text + "  images: {path: s/, prefix: r, format: png, count: 3}\n")
    (tmp_path / "a.yaml").write_text(text + "  images: {path: s/, prefix: a, format: png, count: 0}\n")
    data = _load(tmp_path / "rgb.yaml")
    assert data.voxels.min() == 1.0 and [d.rule for d in data.findings] == ["volume-slice-opaque"]
    # an RGBA slice by its alpha, not its colour; count 0 is refused as before
    assert ("error", "volume-images") in [(str(s), r) for s, r in _rules(tmp_path / "a.yaml")]
    (tmp_path / "a.yaml").write_text(text + "  images: {path: s/, prefix: a, format: png, count: 1}\n")
    a = _load(tmp_path / "a.yaml").voxels[0]
    assert a[6 - 1 - 3, 3] == pytest.approx(250 / 255) and a[6 - 1 - 4, 4] == pytest.approx(30 / 255)


@pytest.mark.parametrize(
    "images, rule, says",
    [
        ("{path: s/, prefix: g, format: .png, count: 3}", "volume-format", "without the dot"),
        ("{path: s/, prefix: g, format: tif, count: 3}", "volume-format", "bmp, gif, jpg, png, ppm, raw"),
        ("{path: s/, prefix: h, format: png, count: 3}", "volume-slice-missing", "it holds g0.png"),
        ("{path: nowhere/, prefix: g, format: png, count: 3}", "volume-slice-missing", "does not exist"),
    ],
)
def test_a_volume_ambf_would_skip_is_a_located_error(tmp_path, images, rule, says):
    from PIL import Image

    (tmp_path / "s").mkdir()
    for i in range(3):
        Image.fromarray(np.full((4, 4), 200, np.uint8)).save(tmp_path / "s" / f"g{i}.png")
    f = tmp_path / "m.yaml"
    f.write_text(f"volumes: [VOLUME v]\nVOLUME v:\n  name: v\n  images: {images}\n")
    model = load_scene(f).models[0]
    with pytest.raises(AdfError) as exc:
        load_volume(model, model.volumes[0])
    (d,) = exc.value.diagnostics
    assert d.rule == rule and says in d.message and d.location.line == 4 and d.hint  # at `images`


def test_two_files_of_one_index_are_both_read_and_a_warning(tmp_path):
    rgba = skull_rgba(3, 6)
    write_slices(tmp_path, rgba, prefix="p", indices=range(3))
    write_slices(tmp_path, rgba[1:2], prefix="p0", indices=[1])  # p01.png beside p1.png
    found = find_slice_files(tmp_path, "p", "png", 12)
    assert [p.name for p in found.files] == ["p0.png", "p1.png", "p01.png", "p2.png"] and found.twice == [1]


def test_info_names_each_volume_with_its_voxels_slices_and_size(tmp_path, capsys):
    adf = project(tmp_path, slices=20, side=24, count=512)
    (adf / "broken.yaml").write_text((adf / "volume_a.yaml").read_text().replace("prefix: plane00", "prefix: slice_"))
    assert main(["info", str(adf / "volume_a.yaml"), str(adf / "broken.yaml")]) == 0
    out = capsys.readouterr().out
    assert (
        "- name: mastoidectomy_volume, voxels: 24x24x20, slices found: 20, count: 512, "
        "size m: 0.0492027x0.0492027x0.048485, voxel mm: 2.05x2.05x2.424"
    ) in out
    assert "- name: mastoidectomy_volume, problem: volume 'VOLUME mastoidectomy_volume': no slice slice_<0..512>" in out


def test_a_project_shaped_volume_converts_to_files_both_engines_load(tmp_path, capsys):
    mujoco = pytest.importorskip("mujoco")
    pb = pytest.importorskip("pybullet")
    adf = project(tmp_path, slices=20, side=24, count=512)
    for out in ("v.xml", "v.urdf"):
        assert main(["convert", str(adf / "volume_a.yaml"), str(tmp_path / out)]) == 0
    assert "0 bodies, 0 joints, 1 volume(s) as their iso-surfaces" in capsys.readouterr().out
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "v.xml"))
    assert (m.geom_group == 1).sum() == 1 and (m.geom_group == 3).sum() > 5  # drawn surface, convex parts
    cid = pb.connect(pb.DIRECT)
    try:
        uid = pb.loadURDF(str(tmp_path / "v.urdf"), useFixedBase=True, physicsClientId=cid)
        lo, hi = np.array(pb.getAABB(uid, 0, physicsClientId=cid))
        assert np.all(hi - lo > 0.02)  # the skull's surface, about its 49 mm box
    finally:
        pb.disconnect(cid)
