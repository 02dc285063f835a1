"""Parents followed as AMBF follows them (afBaseObject::updateGlobalPose: the parent's pose
times the object's own location; a parent found by its name or a unique part of it; a camera
may be a parent, its frame the one afCamera::setView makes): a volume under a body (the
skull-base project's ``BODY volume_Anatomical_Origin``), cameras and a light under a camera
(the drilling projects' ``stereoL``, ``stereoR`` and ``light1`` under ``main_camera``)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("skimage", reason="scikit-image (geometry extra) is not installed")

from volume_shapes import ORIGIN, skull_base, write_launch  # noqa: E402

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import open_world  # noqa: E402
from adfkit.runner.frames import camera_frame  # noqa: E402
from adfkit.runner.options import Options  # noqa: E402
from adfkit.runner.rotations import pose_to_matrix  # noqa: E402


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def _skull_base(tmp_path, mass: float = 0.0):
    return load_scene(skull_base(tmp_path, mass))


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_volume_hangs_from_its_parent_body(tmp_path, engine):
    pytest.importorskip(engine)
    world = open_world(_skull_base(tmp_path), Options(gravity=(0.0, 0.0, 0.0)), engine=engine)
    try:
        vol = world.body("VOLUME skull")
        t = vol.world_matrix()
        # AMBF's probe: the parent at (0.1, 0.2, 0.3) turned 90° about z, the volume 10 mm along
        # the parent's x: at (0.1, 0.21, 0.3), turned with it
        assert np.allclose(t[:3, 3], [0.1, 0.21, 0.3], atol=1e-9)
        assert np.allclose(t[:3, :3], _rz(np.pi / 2), atol=1e-9)
    finally:
        world.close()


def test_a_volume_follows_a_moving_parent_in_mujoco_and_pybullet_says_it_cannot(tmp_path, capsys):
    pytest.importorskip("mujoco")
    scene = _skull_base(tmp_path, mass=0.1)
    world = open_world(scene, Options(gravity=(0.0, 0.0, -9.81), ground=False), engine="mujoco", sleep=False)
    try:
        world.run(0.1)
        parent, vol = world.body("volume_Anatomical_Origin").world_matrix(), world.body("VOLUME skull").world_matrix()
        assert parent[2, 3] < ORIGIN[2] - 0.03  # falling
        assert np.allclose(vol, parent @ pose_to_matrix(scene.models[0].volumes[0].location), atol=1e-9)
    finally:
        world.close()
    world = open_world(scene, Options(), engine="pybullet")
    try:
        assert any(d.rule == "runner-volume" and "does not follow" in d.message for d in world.diagnostics)
        assert {"object": "VOLUME skull", "what": "moving parent", "why": "PyBullet: a static triangle mesh"} in (
            world.not_played
        )
    finally:
        world.close()


WORLD = """\
enclosure size: {length: 10.0, width: 10.0, height: 3.0}
lights: [light1]
cameras: [main_camera]
namespace: /ambf/env/
gravity: {x: 0.0, y: 0.0, z: 0.0}
light1:
  namespace: lights/
  name: light1
  location: {x: 0.0, y: 0.0, z: 0.025}
  direction: {x: -1.0, y: 0.0, z: 0.0}
  spot exponent: 0.3
  shadow quality: 0
  cutoff angle: 0.5
  parent: main_camera
main_camera:
  namespace: cameras/
  name: main_camera
  location: {x: 0.3, y: 0.1, z: 0.2}
  look at: {x: 0.0, y: 0.0, z: 0.0}
  up: {x: 0.0, y: 0.0, z: 1.0}
  field view angle: 0.7
  publish image resolution: {width: 64, height: 48}
"""

STEREO = """\
bodies: [BODY box]
cameras: [stereoR, stereoL]
namespace: /ambf/env/
BODY box:
  name: box
  mass: 0.0
  shape: Box
  geometry: {x: 0.05, y: 0.05, z: 0.05}
stereoL:
  namespace: cameras/
  name: stereoL
  location: {x: 0.0, y: 0.0, z: 0.0}
  look at: {x: -0.3, y: 0.0, z: 0.0}
  up: {x: 0.0, y: 0.0, z: 1.0}
  field view angle: 0.2
  publish image resolution: {width: 64, height: 48}
  parent: main_camera
stereoR:
  namespace: cameras/
  name: stereoR
  location: {x: 0.0, y: 0.025, z: 0.0}
  look at: {x: -0.3, y: 0.025, z: 0.0}
  up: {x: 0.0, y: 0.0, z: 1.0}
  field view angle: 0.2
  publish image resolution: {width: 64, height: 48}
  parent: main_camera
"""


def _stereo_scene(tmp_path):
    (tmp_path / "world.yaml").write_text(WORLD)
    (tmp_path / "stereo.yaml").write_text(STEREO)
    return load_scene(write_launch(tmp_path, "", "world.yaml", ["stereo.yaml"]))


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_cameras_and_a_light_hang_from_a_camera(tmp_path, engine):
    pytest.importorskip(engine)
    scene = _stereo_scene(tmp_path)
    main_frame = camera_frame(scene.world.cameras[0])
    x, y = main_frame[:3, 0], main_frame[:3, 1]
    eye_main = np.array([0.3, 0.1, 0.2])
    assert np.allclose(x, eye_main / np.linalg.norm(eye_main))  # from the point looked at to the eye
    world = open_world(scene, Options(), engine=engine)
    try:
        cams = {c.name: c for c in world.cameras}
        assert set(cams) == {"main_camera", "stereoL", "stereoR"}  # none skipped
        for name, side in (("stereoL", 0.0), ("stereoR", 0.025)):
            eye, target, up = (np.array(v) for v in cams[name].view(world))
            assert np.allclose(eye, eye_main + side * y, atol=1e-9)  # offset along the main camera's y
            assert np.allclose(target, eye_main - 0.3 * x + side * y, atol=1e-9)
            assert np.allclose(up, main_frame[:3, 2], atol=1e-9)
        if engine == "mujoco":
            m, d = world.model, world.data
            (light,) = range(m.nlight)
            assert np.allclose(d.light_xpos[light], eye_main + 0.025 * main_frame[:3, 2], atol=1e-9)
            assert np.allclose(d.light_xdir[light], -x, atol=1e-9)  # its x: (-1, 0, 0) in the camera's frame
    finally:
        world.close()
    assert not [d for d in world.diagnostics if d.rule in ("runner-parent", "runner-camera")]


def test_validate_knows_a_camera_is_a_parent(tmp_path):
    from adfkit.validator.engine import validate_paths

    _stereo_scene(tmp_path)
    rules = [d.rule for r in validate_paths([tmp_path / "launch.yaml"])[0] for d in r.diagnostics]
    assert "dangling-reference" not in rules
    (tmp_path / "stereo.yaml").write_text(STEREO.replace("parent: main_camera", "parent: side_camera", 1))
    found = [d for r in validate_paths([tmp_path / "launch.yaml"])[0] for d in r.diagnostics]
    assert [d.message for d in found if d.rule == "dangling-reference"] == [
        "'parent' of 'stereoL' is 'side_camera', which names no body in this file or the models loaded before it"
    ]


def test_a_camera_under_a_camera_of_the_same_file_converts_to_mjcf_where_ambf_puts_it(tmp_path):
    mujoco = pytest.importorskip("mujoco")
    from adfkit.cli import main

    main_cam = WORLD[WORLD.index("main_camera:\n") :]
    (tmp_path / "stereo.yaml").write_text(
        STEREO.replace("cameras: [stereoR, stereoL]", "cameras: [stereoR, stereoL, main_camera]") + main_cam
    )
    assert main(["convert", str(tmp_path / "stereo.yaml"), str(tmp_path / "s.xml")]) == 0
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "s.xml"))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    frame = camera_frame(load_scene(tmp_path / "stereo.yaml").models[0].cameras[2])
    eye_r = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_CAMERA, "stereoR")
    assert np.allclose(d.cam_xpos[eye_r], frame[:3, 3] + 0.025 * frame[:3, 1], atol=1e-9)
    # MJCF cameras look along their -z: stereoR looks along the main camera's -x, as AMBF has it
    assert np.allclose(-d.cam_xmat[eye_r].reshape(3, 3)[:, 2], -frame[:3, 0], atol=1e-9)
