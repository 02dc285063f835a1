"""`adfkit drill` on the bundled drilling scene: voxels removed along the burr's swept volume,
counted per tissue; the canal reported as a protected tissue; the burr held by bone it cannot
remove; hostile tool path files as located errors; the drilled slices read back, validate,
and the locally re-meshed surface equals a full re-mesh."""

from __future__ import annotations

import hashlib
import json
import shutil

import numpy as np
import pytest

pytest.importorskip("skimage", reason="scikit-image (geometry extra) is not installed")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.cli import main  # noqa: E402
from adfkit.scenes.drilling import CANAL, DrillingParams, bone_voxels, write_drilling  # noqa: E402

P = DrillingParams()
H = P.size / P.voxels  # voxel side, m
TOP = 0.02 + 0.30 * P.size  # the bone block's top face (its rounded box reaches 0.30 of the size)


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    return write_drilling(tmp_path_factory.mktemp("drilling"))


def _drill(scene, out, *extra) -> tuple[int, dict]:
    rc = main(["drill", str(scene), "--out", str(out), "--frames", "4", *extra])
    metrics = json.loads((out / "metrics.json").read_text()) if (out / "metrics.json").is_file() else {}
    return rc, metrics


def _centres():
    c = (np.arange(P.voxels) + 0.5) * H - P.size / 2
    z, y, x = np.meshgrid(c + 0.02, c, c, indexing="ij")  # world frame: the volume sits at z = 0.02
    return x, y, z


def _within(a, b, r):
    """Mask of voxel centres within r of the segment a-b (world frame)."""
    x, y, z = _centres()
    q = np.stack([x, y, z], axis=-1)
    ab = np.asarray(b) - np.asarray(a)
    t = np.clip(((q - a) @ ab) / max(ab @ ab, 1e-30), 0, 1)
    return np.linalg.norm(q - (np.asarray(a) + t[..., None] * ab), axis=-1) < r


def test_a_straight_path_removes_the_burrs_swept_volume(scene, tmp_path, capsys):
    rc, m = _drill(scene, tmp_path / "fast", "--removal-rate", "1000")  # a voxel goes at first touch
    assert rc == 0
    assert m["path_m"][0] == [0.0, 0.0, 0.07] and m["path_m"][1][2] < TOP  # from the burr, into the bone
    tissue = bone_voxels(P) > 0
    swept = _within(np.array(m["burr"]["start_m"]), np.array(m["final_burr_m"]), P.burr_radius) & tissue
    assert m["voxels_removed"]["bone"] == pytest.approx(int(swept.sum()), abs=2)
    assert m["voxels_removed"]["bone"] > 100 and m["voxels_removed"]["canal"] == 0
    assert m["voxels_removed_total"] * H**3 == pytest.approx(m["volume_removed_m3"])
    assert "bone" in capsys.readouterr().out
    # at the default removal rate (a voxel goes after 40 ms inside the burr) the burr removes
    # all the voxels well inside its path and none outside it
    rc, m = _drill(scene, tmp_path / "rate", "--removal-rate", "25")
    a, b = np.array(m["burr"]["start_m"]), np.array(m["final_burr_m"])
    outer = int((_within(a, b, P.burr_radius) & tissue).sum())
    inner = int((_within(a, b + [0, 0, H], P.burr_radius - H) & tissue).sum())
    assert inner <= m["voxels_removed"]["bone"] <= outer and 0.9 * outer <= m["voxels_removed"]["bone"]


def test_a_path_through_the_canal_reports_the_protected_tissue(scene, tmp_path, capsys):
    path = tmp_path / "through.txt"
    path.write_text("# straight down through the canal\n0 0 0.030\n0, 0, 0.012\n")
    rc, m = _drill(scene, tmp_path / "out", "--path", str(path), "--removal-rate", "1000")
    err = capsys.readouterr().err
    assert rc == 1  # drilled, but a protected tissue was touched
    assert "warning[drill-protected]" in err and "'canal'" in err and "drill.yaml:" in err
    hit = m["protected_touched"]["canal"]
    assert hit["voxels_touched"] >= m["voxels_removed"]["canal"] > 0
    # first touched when the burr's sphere reached the first canal voxel centre on its way down
    x, y, z = _centres()
    canal = bone_voxels(P) == CANAL
    xy2 = x[canal] ** 2 + y[canal] ** 2
    reach = (z[canal] + np.sqrt(np.maximum(P.burr_radius**2 - xy2, 0)))[xy2 < P.burr_radius**2].max()
    assert hit["first_burr_m"][2] == pytest.approx(reach, abs=2e-5)  # the burr moves 10 µm a step
    assert m["protected"] == ["canal"] and m["labels"]["canal"] == pytest.approx([60 / 255, 120 / 255])
    assert (bone_voxels(P) == CANAL).sum() > m["voxels_removed"]["canal"]


def test_the_burr_stops_against_bone_it_cannot_remove(scene, tmp_path):
    path = tmp_path / "through.txt"
    path.write_text("0 0 0.005\n")  # through the whole bone
    rc, m = _drill(scene, tmp_path / "none", "--path", str(path), "--removal-rate", "0")
    assert rc == 0 and m["voxels_removed_total"] == 0
    z = m["final_burr_m"][2]
    # it rests on the bone: the nearest solid voxel centres (the top layer's four around the axis,
    # H/2 off it in x and y) sit 5 N / 20 kN/m = 0.25 mm inside its sphere, no deeper
    top_centre = 0.02 + (np.nonzero((bone_voxels(P) >= 128).any(axis=(1, 2)))[0].max() + 0.5) * H - P.size / 2
    rest = top_centre + np.sqrt((P.burr_radius - 5.0 / 20_000) ** 2 - 2 * (H / 2) ** 2)
    assert z == pytest.approx(rest, abs=1e-7)
    assert m["force"]["max_n"] == pytest.approx(5.0, rel=0.05)  # the hand's full push, held by the bone
    # a slow removal rate: through the bone no faster than the burr wears it away
    rc, slow = _drill(scene, tmp_path / "slow", "--path", str(path), "--removal-rate", "2")
    assert slow["voxels_removed"]["bone"] > 0
    assert top_centre - 0.01 < slow["final_burr_m"][2] < z  # into the bone, far from the path's end
    assert slow["force"]["max_n"] > 1.0


@pytest.mark.parametrize(
    "text,line,col",
    [
        ("0 0 0.03\n0 0 abc\n", 2, 5),
        ("0 0 0.03\n\n0 0 0.02 7\n", 3, 10),
        ("0 0 nan\n", 1, 5),
        ("# only a comment\n", 1, 1),
        ("0 0 0.03\n1e9 0 0\n", 2, 1),
        ("0 0\n", 1, 4),
    ],
)
def test_a_hostile_path_file_is_a_located_error(scene, tmp_path, capsys, text, line, col):
    path = tmp_path / "bad.txt"
    path.write_text(text)
    rc = main(["drill", str(scene), "--path", str(path), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert rc == 2
    assert f"bad.txt:{line}:{col}: error[drill-path]:" in err and "hint:" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_a_path_file_that_is_not_a_file_or_an_output_over_the_input_is_refused(scene, tmp_path, capsys):
    assert main(["drill", str(scene), "--path", "/dev/zero", "--out", str(tmp_path / "o")]) == 2
    assert "error[not-a-regular-file]" in capsys.readouterr().err
    copy = tmp_path / "scene"
    shutil.copytree(scene.parent, copy)
    before = hashlib.sha256(b"".join(p.read_bytes() for p in sorted((copy / "slices").iterdir()))).hexdigest()
    assert main(["drill", str(copy), "--out", str(copy)]) == 2
    assert "error[drill-out]" in capsys.readouterr().err
    after = hashlib.sha256(b"".join(p.read_bytes() for p in sorted((copy / "slices").iterdir()))).hexdigest()
    assert before == after


def test_the_drilled_slices_read_back_and_validate(scene, tmp_path, capsys):
    from PIL import Image

    from adfkit.geometry.volume import iso_surface, load_volume

    out = tmp_path / "out"
    rc, m = _drill(scene, out)
    assert rc == 0
    assert main(["validate", str(out / "volume.yaml")]) == 0
    model = load_scene(out / "volume.yaml").models[0]
    data = load_volume(model, model.volumes[0])
    before = bone_voxels(P)[:, ::-1]  # the loader puts a slice's bottom row first, as AMBF does
    after = np.rint(data.voxels * 255).astype(np.uint8)
    assert data.voxels.shape == before.shape and data.full_scale == 255.0
    gone = (before > 0) & (after == 0)
    assert int(gone.sum()) == m["voxels_removed_total"] > 0
    assert np.array_equal(after[~gone], before[~gone])  # nothing else changed
    # the surface re-meshed block by block equals marching cubes over the whole drilled volume
    import trimesh

    local = trimesh.load(out / "surface.stl")
    full = trimesh.Trimesh(*iso_surface(data, 0.5))
    assert local.area == pytest.approx(full.area, rel=1e-6)
    assert 0 < m["surface"]["blocks_remeshed"] < 27  # 4³ blocks in all: only those it touched
    gif = Image.open(out / "drilling.gif")
    assert gif.size == (486, 240) and gif.n_frames >= 2


def test_a_bad_labels_file_or_out_folder_is_a_located_error(scene, tmp_path, capsys):
    copy = tmp_path / "scene"
    shutil.copytree(scene.parent, copy)
    (copy / "slices" / "labels.yaml").write_text("bone: [150, 255]\ncanal: [x, 120]\n")
    assert main(["drill", str(copy), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "labels.yaml:2:8: error[drill-labels]:" in err and "hint:" in err
    (copy / "slices" / "labels.yaml").write_text("bone: [150, 255]\nprotected: [nerve]\n")
    assert main(["drill", str(copy), "--out", str(tmp_path / "o")]) == 2
    assert "labels.yaml:2:13: error[drill-labels]: protected tissue 'nerve'" in capsys.readouterr().err
    (copy / "slices" / "labels.yaml").unlink()  # defaults: bone and soft tissue, nothing protected
    assert main(["drill", str(copy), "--out", str(tmp_path / "o"), "--protect", "canal"]) == 2
    assert "error[bad-option]: --protect 'canal' is not a tissue" in capsys.readouterr().err
    (tmp_path / "file").write_text("")
    assert main(["drill", str(copy), "--out", str(tmp_path / "file")]) == 2
    assert "error[drill-out]" in capsys.readouterr().err
