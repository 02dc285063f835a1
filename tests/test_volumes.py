"""ADF volumes: the bundled drilling scene's bone, read from its PNG slices, validated, and played
as an iso-surface body in the camera images and the segmentation; hostile volume inputs are
located errors; whatever an engine does not play is named in report.json."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("skimage", reason="scikit-image (geometry extra) is not installed")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.cli import main  # noqa: E402
from adfkit.scenes.drilling import BONE, CANAL, DrillingParams, bone_voxels, write_drilling  # noqa: E402
from adfkit.validator.engine import validate_file  # noqa: E402


@pytest.fixture(scope="module")
def drilling(tmp_path_factory):
    out = tmp_path_factory.mktemp("drilling")
    return write_drilling(out)


def _copy(launch, tmp_path):
    dest = tmp_path / "scene"
    shutil.copytree(launch.parent, dest)
    return dest


def test_the_bone_has_two_tissues_and_its_iso_surface_is_closed(drilling):
    from adfkit.geometry.volume import iso_surface, load_volume

    vox = bone_voxels(DrillingParams())
    assert (vox == CANAL).sum() > 100 and (vox >= BONE - 20).sum() > 10_000 and (vox == 0).sum() > 10_000
    scene = load_scene(drilling)
    model = scene.models[0]
    data = load_volume(model, model.volumes[0])
    assert data.voxels.shape == (48, 48, 48) and np.allclose(data.dimensions, 0.04)
    verts, faces = iso_surface(data, model.volumes[0].iso_surface_value)
    import trimesh

    surface = trimesh.Trimesh(verts, faces)
    assert surface.is_watertight and surface.volume > 0
    bone = ((data.voxels >= 0.5).sum()) * (0.04 / 48) ** 3  # the voxels above the level
    assert surface.volume == pytest.approx(bone, rel=0.1)
    assert np.all(np.abs(verts) <= 0.02 + 1e-9)  # inside the volume's box


def test_the_drilling_scene_validates_clean_and_plays_with_its_volume(drilling, tmp_path, capsys):
    assert main(["validate", str(drilling)]) == 0
    out = tmp_path / "run"
    assert main(["run", str(drilling), "--seconds", "0.05", "--out", str(out)]) == 0
    rep = json.loads((out / "report.json").read_text())
    (vol,) = rep["volumes"]
    assert vol["object"] == "VOLUME Bone" and vol["triangles"] > 1000 and rep["not_played"] == []
    from adfkit.runner import open_world
    from adfkit.runner.options import Options

    world = open_world(load_scene(drilling), Options())
    try:
        label = next(i for i, sb in enumerate(world.bodies) if sb.key.endswith("VOLUME Bone"))
        frame = world.cameras[0].render(world)
        seen = frame["segmentation"] == label
        assert seen.mean() > 0.02  # the bone is in the picture, labelled
        assert np.isfinite(frame["depth"][seen]).all()
    finally:
        world.close()


def test_the_mujoco_engine_plays_the_volume_in_its_images_and_segmentation(drilling, tmp_path, capsys):
    pytest.importorskip("mujoco")
    from adfkit.geometry.volume import iso_surface, load_volume
    from adfkit.runner import open_world
    from adfkit.runner.options import Options

    out = tmp_path / "mj"
    assert (
        main(["run", str(drilling), "--engine", "mujoco", "--seconds", "0.05", "--no-frames", "--out", str(out)]) == 0
    )
    rep = json.loads((out / "report.json").read_text())
    scene = load_scene(drilling)
    model = scene.models[0]
    _, faces = iso_surface(load_volume(model, model.volumes[0]), 0.5)
    (vol,) = rep["volumes"]  # the same iso-surface as the PyBullet runner's
    assert vol["object"] == "VOLUME Bone" and vol["triangles"] == len(faces) and vol["voxels"] == [48, 48, 48]
    # played now; what MuJoCo cannot do of it (a concave collision) is named
    assert rep["not_played"] == [
        {
            "object": "VOLUME Bone",
            "what": "concave collision",
            "why": "MuJoCo collides a mesh as its convex hull: the volume collides by "
            f"{vol['convex_parts']} convex parts of at most 8³ voxels, so a cavity smaller than a part is solid "
            "to contacts",
        }
    ]
    assert 50 < vol["convex_parts"] < 216  # 6³ blocks of 8³ voxels; those the surface crosses
    assert "runner-volume" not in capsys.readouterr().err
    world = open_world(scene, Options(), engine="mujoco")
    try:
        label = next(i for i, sb in enumerate(world.bodies) if sb.key.endswith("VOLUME Bone"))
        sb = world.bodies[label]
        assert sb.static and sb.has_collision
        assert len(sb.surface[1]) == len(faces)  # what the viewer draws of it
        assert np.allclose(sb.world_matrix()[:3, 3], [0, 0, 0.02])  # at the volume's location
        m = world.model
        g, *parts = np.nonzero(m.geom_bodyid == sb.id)[0]  # the drawn surface, then the convex parts
        assert len(parts) == vol["convex_parts"] and set(m.geom_group[parts]) == {3} and m.geom_contype[g] == 0
        r = world.data.geom_xmat[g].reshape(3, 3)  # MuJoCo turns a mesh to its principal axes
        top = (r @ m.geom_aabb[g, :3] + world.data.geom_xpos[g])[2] + np.abs(r[2]) @ m.geom_aabb[g, 3:]
        assert top == pytest.approx(0.02 + 0.3 * 0.04, abs=0.04 / 48)  # the bone's top face
        frame = world.cameras[0].render(world)
        seen = frame["segmentation"] == label
        assert seen.mean() > 0.02  # the bone is in the picture, labelled
        assert np.isfinite(frame["depth"][seen]).all()
        bone = frame["rgb"][seen].mean(axis=0)
        assert bone[0] > bone[2] + 10  # ivory, the volume's colour, not the grey floor
    finally:
        world.close()


def _volume_findings(scene_dir) -> list:
    return [d for d in validate_file(scene_dir / "drill.yaml").diagnostics if d.rule.startswith("volume")]


def _images_line(scene_dir) -> int:
    return next(
        n
        for n, line in enumerate((scene_dir / "drill.yaml").read_text().splitlines(), 1)
        if line.strip().startswith("images:")
    )


@pytest.mark.parametrize(
    "case, rule",
    [
        ("no slice of the prefix", "volume-slice-missing"),
        ("a format AMBF cannot read", "volume-format"),
        ("mixed sizes", "volume-slice-size"),
        ("count 10^9", "volume-images"),
        ("outside the tree", "volume-slice-missing"),
        ("not an image", "volume-slice-unreadable"),
    ],
)
def test_hostile_volume_inputs_are_located_errors(drilling, tmp_path, case, rule):
    from PIL import Image

    scene = _copy(drilling, tmp_path)
    drill = scene / "drill.yaml"
    if case == "no slice of the prefix":
        drill.write_text(drill.read_text().replace("prefix: bone_", "prefix: bone"))
    elif case == "a format AMBF cannot read":
        drill.write_text(drill.read_text().replace("format: png", "format: tif"))
    elif case == "mixed sizes":
        Image.fromarray(np.zeros((10, 12), np.uint8)).save(scene / "slices" / "bone_5.png")
    elif case == "count 10^9":
        drill.write_text(drill.read_text().replace("count: 48", "count: 1000000000"))
    elif case == "outside the tree":
        import tempfile

        outside = Path(tempfile.mkdtemp(dir="/var/tmp")) / "slices"  # far from the scene's folders
        shutil.copytree(scene / "slices", outside)
        drill.write_text(drill.read_text().replace("path: slices/", f"path: {outside}/"))
    else:
        (scene / "slices" / "bone_3.png").write_text("not an image at all")
    found = _volume_findings(scene)
    assert [d.rule for d in found] == [rule], [str(d) for d in found]
    d = found[0]
    assert d.location.file == str(drill) and d.location.line >= _images_line(scene) and d.hint
    assert main(["validate", str(drill)]) == 1
    # the runner does not play it, and says so
    out = tmp_path / "run"
    assert main(["run", str(scene / "launch.yaml"), "--seconds", "0.02", "--no-frames", "--out", str(out)]) == 0
    rep = json.loads((out / "report.json").read_text())
    assert rep["volumes"] == [] and rep["not_played"][0]["object"] == "VOLUME Bone"
    if case == "outside the tree":
        shutil.rmtree(outside.parent, ignore_errors=True)
