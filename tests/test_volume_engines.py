"""Big and concave volume surfaces in both engines: a surface beyond PyBullet's mesh limits
(131,072 vertices, 524,288 indices) plays in pieces; the contact stays at the surface (a ball
dropped into a pit rests at the pit's bottom, not on the hull over it) in PyBullet (concave
pieces) and in MuJoCo (convex parts of 8³ voxels)."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("skimage", reason="scikit-image (geometry extra) is not installed")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.cli import main  # noqa: E402
from adfkit.runner import open_world  # noqa: E402
from adfkit.runner.options import Options  # noqa: E402

SIDE = 0.04  # m: the pit volume's cube
PIT = 0.012  # m: the pit's radius, centred on the top of the block
BALL = 0.002  # m


def _write(folder, vox: np.ndarray, extra: str = "", name: str = "Pit") -> None:
    from PIL import Image

    (folder / "s").mkdir(parents=True)
    for i, s in enumerate(vox):
        Image.fromarray(s[::-1]).save(folder / "s" / f"v{i}.png")  # the picture's top row is +y
    (folder / "m.yaml").write_text(
        f"bodies: [{'BODY Ball' if extra else ''}]\nvolumes: [VOLUME {name}]\n{extra}"
        f"VOLUME {name}:\n  name: {name}\n  location: {{position: {{x: 0, y: 0, z: {SIDE / 2}}}}}\n"
        f"  dimensions: {{x: {SIDE}, y: {SIDE}, z: {SIDE}}}\n"
        f"  images: {{path: s/, prefix: v, format: png, count: {len(vox)}}}\n"
    )


def _pit_scene(tmp_path):
    n = 40
    c = (np.arange(n) + 0.5) / n * SIDE - SIDE / 2
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    top = 0.0  # the block fills the volume's lower half
    solid = (z < top) & (x**2 + y**2 + (z - top) ** 2 > PIT**2)
    ball = (
        f"BODY Ball:\n  name: Ball\n  mass: 0.01\n  shape: Sphere\n  geometry: {{radius: {BALL}}}\n"
        f"  collision shape: Sphere\n  collision geometry: {{radius: {BALL}}}\n"
        f"  location: {{position: {{x: 0, y: 0, z: {SIDE / 2 + 0.004}}}}}\n"
    )
    _write(tmp_path, np.where(solid, 230, 0).astype(np.uint8), ball)
    return tmp_path / "m.yaml"


@pytest.mark.parametrize("engine, within", [("pybullet", 0.0005), ("mujoco", 0.0015)])
def test_a_ball_rests_at_the_bottom_of_a_pit_not_on_its_hull(tmp_path, engine, within):
    pytest.importorskip(engine)
    scene = load_scene(_pit_scene(tmp_path))
    awake = {"sleep": False} if engine == "mujoco" else {}  # a sleeping body reports no contacts
    world = open_world(scene, Options(), engine=engine, **awake)
    try:
        world.run(0.6)
        z = world.body("Ball").world_matrix()[2, 3]
        touching = [other.name for other, _, _ in world.contacts(world.body("Ball"))]
    finally:
        world.close()
    bottom = SIDE / 2 - PIT + BALL  # world z of the ball's centre on the pit's floor
    assert abs(z - bottom) < within, (engine, z, bottom)  # a whole-surface hull holds it 12 mm higher
    assert touching and set(touching) == {"Pit"}


def test_a_surface_beyond_pybullets_mesh_limits_plays_in_pieces_in_both_engines(tmp_path):
    rng = np.random.default_rng(1)
    vox = np.where(rng.random((48, 48, 48)) < 0.5, 230, 0).astype(np.uint8)  # 364k triangles, 179k vertices
    _write(tmp_path, vox, name="Noise")
    for engine in ("pybullet", "mujoco"):
        pytest.importorskip(engine)
        out = tmp_path / engine
        assert (
            main(
                [
                    "run",
                    str(tmp_path / "m.yaml"),
                    "--engine",
                    engine,
                    "--seconds",
                    "0.01",
                    "--no-frames",
                    "--out",
                    str(out),
                ]
            )
            == 0
        )
        (vol,) = json.loads((out / "report.json").read_text())["volumes"]
        assert vol["triangles"] > 300_000
        if engine == "pybullet":
            assert vol["pieces"] >= 3  # each within 131,072 vertices and 174,762 triangles
        else:
            assert vol["convex_parts"] == 216  # 6³ blocks of 8³ voxels, all crossed by the noise


def test_a_surface_beyond_mujocos_stl_limit_converts_to_files_both_engines_load(tmp_path, capsys):
    mujoco = pytest.importorskip("mujoco")
    pb = pytest.importorskip("pybullet")
    rng = np.random.default_rng(1)
    _write(tmp_path, np.where(rng.random((48, 48, 48)) < 0.5, 230, 0).astype(np.uint8), name="Noise")
    src = str(tmp_path / "m.yaml")
    assert main(["convert", src, str(tmp_path / "n.xml")]) == 0
    assert "0 bodies, 0 joints, 1 volume(s) as their iso-surfaces" in capsys.readouterr().out
    import trimesh

    pieces = sorted(tmp_path.glob("n_Noise_*.stl"))
    faces = [len(trimesh.load(p).faces) for p in pieces]
    assert len(pieces) >= 2 and max(faces) <= 200_000 and sum(faces) > 300_000
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "n.xml"))  # MuJoCo's STL reader takes each piece
    assert sum(m.geom_group == 1) == len(pieces) and sum(m.geom_group == 3) == 216
    assert main(["convert", src, str(tmp_path / "n.urdf")]) == 0
    cid = pb.connect(pb.DIRECT)
    try:
        uid = pb.loadURDF(str(tmp_path / "n.urdf"), useFixedBase=True, physicsClientId=cid)
        assert pb.getNumJoints(uid, physicsClientId=cid) == 1
        lo, hi = pb.getAABB(uid, 0, physicsClientId=cid)
        assert np.allclose(lo, [-0.02, -0.02, 0.0], atol=0.002) and np.allclose(hi, [0.02, 0.02, 0.04], atol=0.002)
    finally:
        pb.disconnect(cid)
