"""ADF volumes through the MJCF and URDF writers: each volume's iso-surface written as an STL
beside the output, placed as a static mesh at the volume's location (loaded back in MuJoCo
and PyBullet), the voxel data named as a loss; a volume whose slices cannot be read is a loss
too, never a traceback."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

pytest.importorskip("skimage", reason="scikit-image (geometry extra) is not installed")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.cli import main  # noqa: E402
from adfkit.converters.losses import loss_keys  # noqa: E402
from adfkit.scenes.drilling import write_drilling  # noqa: E402

H = 0.04 / 48  # the sample's voxel side


@pytest.fixture(scope="module")
def drilling(tmp_path_factory):
    return write_drilling(tmp_path_factory.mktemp("drilling")).parent


def _bone_surface(scene_dir):
    import trimesh

    from adfkit.geometry.volume import iso_surface, load_volume

    model = load_scene(scene_dir / "drill.yaml").models[0]
    return trimesh.Trimesh(*iso_surface(load_volume(model, model.volumes[0]), 0.5))


def test_mjcf_gets_the_iso_surface_as_a_static_mesh_and_names_the_voxel_data(drilling, tmp_path):
    import mujoco
    import trimesh

    from adfkit.converters import mjcf_write

    model = load_scene(drilling / "drill.yaml").models[0]
    losses = mjcf_write.write(model, tmp_path / "drill.xml")
    keys = loss_keys(losses)
    assert ("VOLUME Bone", "voxel data") in keys and ("VOLUME Bone", "concave collision") in keys
    assert ("VOLUME Bone", "volume") not in keys  # it was written
    stl = trimesh.load(tmp_path / "drill_Bone.stl")
    expected = _bone_surface(drilling)
    assert stl.is_watertight and stl.volume == pytest.approx(expected.volume, rel=1e-6)
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "drill.xml"))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "Bone")
    g = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "Bone")
    assert np.allclose(d.xpos[b], [0, 0, 0.02]) and m.body_weldid[b] == 0  # static, at the volume's location
    assert m.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH and m.geom_contype[g] == 0 and m.geom_group[g] == 1  # drawn
    assert np.allclose(m.geom_rgba[g], [0.93, 0.89, 0.78, 1.0])
    assert m.mesh_vertnum[m.geom_dataid[g]] > 1000
    parts = [i for i in range(m.ngeom) if m.geom_bodyid[i] == b and i != g]  # what collides
    assert 50 < len(parts) < 216 and all(m.geom_group[i] == 3 and m.geom_contype[i] != 0 for i in parts)
    # the parts cover the bone: its top face at 0.032 (a ray down beside the drill stops there)
    hit = np.zeros(1, dtype=np.int32)
    dist = mujoco.mj_ray(
        m, d, np.array([0.01, 0.01, 0.1]), np.array([0, 0, -1.0]), np.array([0, 0, 0, 1, 0, 0], np.uint8), 1, -1, hit
    )
    assert hit[0] in parts and 0.1 - dist == pytest.approx(0.032, abs=2 * H)


def test_urdf_gets_the_iso_surface_as_a_fixed_link_and_names_the_voxel_data(drilling, tmp_path):
    import pybullet as pb

    from adfkit.converters import urdf_write

    model = load_scene(drilling / "drill.yaml").models[0]
    losses = urdf_write.write(model, tmp_path / "drill.urdf")
    keys = loss_keys(losses)
    assert ("VOLUME Bone", "voxel data") in keys and ("VOLUME Bone", "concave collision") in keys
    assert (tmp_path / "drill_Bone.stl").is_file()
    cid = pb.connect(pb.DIRECT)
    try:
        uid = pb.loadURDF(str(tmp_path / "drill.urdf"), physicsClientId=cid)
        (j,) = [
            j
            for j in range(pb.getNumJoints(uid, physicsClientId=cid))
            if pb.getJointInfo(uid, j, physicsClientId=cid)[12] == b"Bone"
        ]
        assert np.allclose(pb.getLinkState(uid, j, physicsClientId=cid)[4], [0, 0, 0.02], atol=1e-7)
        lo, hi = np.array(pb.getAABB(uid, j, physicsClientId=cid))
        # the bone block spans z 0.008 .. 0.032 (0.3 of 40 mm about the centre); AABB margin < 1 voxel
        assert lo[2] == pytest.approx(0.008, abs=2 * H) and hi[2] == pytest.approx(0.032, abs=2 * H)
    finally:
        pb.disconnect(cid)


def test_a_volume_without_bodies_converts_and_unreadable_slices_are_a_loss(drilling, tmp_path, capsys):
    scene = tmp_path / "scene"
    shutil.copytree(drilling, scene)
    only = scene / "bone_only.yaml"
    text = (scene / "drill.yaml").read_text()
    only.write_text("volumes:\n- VOLUME Bone\n" + text[text.index("VOLUME Bone:\n") :])
    assert main(["convert", str(only), str(tmp_path / "a.urdf")]) == 0
    assert main(["convert", str(only), str(tmp_path / "a.xml")]) == 0
    assert (tmp_path / "a_Bone.stl").is_file()
    assert "VOLUME Bone: voxel data: URDF has no voxel volume" in capsys.readouterr().out
    (scene / "slices" / "bone_20.png").write_text("not an image")
    assert main(["convert", str(scene / "drill.yaml"), str(tmp_path / "b.xml")]) == 0
    out = capsys.readouterr()
    assert "VOLUME Bone: volume: not written:" in out.out and "bone_20.png" in out.out and "Traceback" not in out.err
    assert not (tmp_path / "b_Bone.stl").exists()
    assert main(["convert", "--fail-on-loss", str(scene / "drill.yaml"), str(tmp_path / "c.xml")]) == 1
