"""Cameras and lights through the MJCF converter, checked in real MuJoCo: where a camera is,
where it looks, which way is up and its field of view; where a light is and where it points."""

from __future__ import annotations

import math
import random
import textwrap

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from adfkit.adf.reader import load  # noqa: E402
from adfkit.converters import read, write  # noqa: E402
from adfkit.converters.losses import loss_keys  # noqa: E402
from adfkit.model.pose import Vec3  # noqa: E402
from adfkit.model.tree import build_tree  # noqa: E402

ARM = """
bodies: [BODY base, BODY arm]
joints: [JOINT base-arm]
cameras: [CAMERA wrist]
lights: [LIGHT lamp]
BODY base:
  name: base
  mass: 0.0
  location: {position: {x: 0.1, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.3}}
  collision shape: BOX
  collision geometry: {x: 0.1, y: 0.1, z: 0.1}
BODY arm:
  name: arm
  mass: 1.0
  inertia: {ix: 0.01, iy: 0.02, iz: 0.03}
  location: {position: {x: 0.1, y: 0.0, z: 0.8}, orientation: {r: 0.0, p: 0.0, y: 0.3}}
  collision shape: BOX
  collision geometry: {x: 0.05, y: 0.05, z: 0.4}
JOINT base-arm:
  name: base-arm
  parent: BODY base
  child: BODY arm
  parent pivot: {x: 0.0, y: 0.0, z: 0.1}
  parent axis: {x: 0.0, y: 1.0, z: 0.0}
  child pivot: {x: 0.0, y: 0.0, z: -0.2}
  child axis: {x: 0.0, y: 1.0, z: 0.0}
  type: revolute
  joint limits: {low: -1.5, high: 1.5}
CAMERA wrist:
  name: wrist
  parent: BODY arm
  location: {x: 0.05, y: -0.3, z: 0.2}
  look at: {x: 0.0, y: 0.0, z: 0.1}
  up: {x: 0.0, y: 0.2, z: 1.0}
  field view angle: 0.9
  publish image resolution: {width: 640, height: 480}
  clipping plane: {near: 0.01, far: 5.0}
  stereo: {mode: PASSIVE, eye separation: 0.005, focal length: 0.1}
LIGHT lamp:
  name: lamp
  parent: BODY arm
  location: {x: 0.0, y: 0.1, z: 0.3}
  direction: {x: 0.0, y: -1.0, z: -1.0}
  spot exponent: 2.0
  cutoff angle: 0.5
  shadow quality: 0
  attenuation: {constant: 1.0, linear: 0.2, quadratic: 0.05}
"""


def _adf(tmp_path, text=ARM):
    p = tmp_path / "arm.yaml"
    p.write_text(textwrap.dedent(text))
    return load(p)


def _mj(path):
    m = mujoco.MjModel.from_xml_path(str(path))
    return m, mujoco.MjData(m)


def _at(m, d, q: float | None = None):
    """Forward kinematics, cameras and lights at hinge value ``q`` (qpos0 when None)."""
    d.qpos[:] = m.qpos0
    if q is not None:
        d.qpos[0] = q
    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    mujoco.mj_camlight(m, d)


def _expected_view(model, q: float):
    """The ADF camera's eye, view direction and image-up in the world (adf-format.md §9), and
    the light's position and direction, from the model's own forward kinematics."""
    tree = build_tree(model)
    arm = tree.fk({"JOINT base-arm": q})["BODY arm"]
    cam, lamp = model.cameras[0], model.lights[0]
    eye = arm.transform(cam.location)
    forward = arm.orientation.rotate((cam.look_at - cam.location).normalized())
    up = arm.orientation.rotate(cam.up)
    up = (up - forward.scaled(up.dot(forward))).normalized()
    return (
        np.array(eye),
        np.array(forward),
        np.array(up),
        np.array(arm.transform(lamp.location)),
        np.array(arm.orientation.rotate(lamp.direction.normalized())),
    )


def test_adf_camera_and_light_written_to_mjcf_see_what_adf_says(tmp_path):
    model = _adf(tmp_path)
    out = tmp_path / "arm.xml"
    losses = write(model, out)
    assert loss_keys(losses) == [("CAMERA wrist", "clipping plane"), ("CAMERA wrist", "stereo")]
    m, d = _mj(out)
    c, li = m.camera("wrist").id, m.light("lamp").id
    assert m.cam_fovy[c] == pytest.approx(math.degrees(0.9))
    assert tuple(m.cam_resolution[c]) == (640, 480) and m.cam_ipd[c] == pytest.approx(0.005)
    assert m.light_cutoff[li] == pytest.approx(math.degrees(0.5)) and m.light_exponent[li] == pytest.approx(2.0)
    assert np.allclose(m.light_attenuation[li], [1.0, 0.2, 0.05]) and not m.light_castshadow[li]
    rng = random.Random(3)
    for q in [0.0] + [rng.uniform(-1.5, 1.5) for _ in range(20)]:
        _at(m, d, q)
        eye, forward, up, lamp_at, lamp_dir = _expected_view(model, q)
        frame = d.cam_xmat[c].reshape(3, 3)
        assert np.allclose(d.cam_xpos[c], eye, atol=1e-9)
        assert np.allclose(-frame[:, 2], forward, atol=1e-9)  # MuJoCo looks along -Z
        assert np.allclose(frame[:, 1], up, atol=1e-9)  # +Y is image up
        assert np.allclose(d.light_xpos[li], lamp_at, atol=1e-9)
        assert np.allclose(d.light_xdir[li], lamp_dir, atol=1e-9)


def test_mjcf_cameras_and_lights_read_into_adf_keep_their_view(tmp_path):
    """MJCF → ADF → MJCF: a fixed camera with a resolution, an orthographic one, a camera
    tracking a body and a light on a hinged body with a reference angle (20°: MJCF's default
    unit) are where MuJoCo puts them; the tracking camera keeps its view at qpos0 (and says it
    no longer tracks)."""
    src = tmp_path / "src.xml"
    src.write_text(
        textwrap.dedent("""
        <mujoco>
          <worldbody>
            <camera name="watch" mode="targetbody" target="link" pos="1 -1 1"/>
            <body name="link" pos="0 0 1" euler="0 0 30">
              <joint name="hinge" type="hinge" axis="0 1 0" pos="0 0 0.1" ref="20"/>
              <geom type="capsule" size="0.02 0.2" pos="0 0 -0.2"/>
              <camera name="eye" pos="0.05 0 -0.3" xyaxes="0 1 0 -1 0 0.2" fovy="60" resolution="320 240"/>
              <camera name="plan" pos="0 0 0.5" projection="orthographic" fovy="0.3" resolution="400 200"/>
              <light name="lamp" pos="0 0.1 0" dir="0 -1 -1" cutoff="20" exponent="3" castshadow="false"
                     attenuation="1 0.1 0.01"/>
            </body>
          </worldbody>
        </mujoco>""")
    )
    model, losses = read(src)
    assert loss_keys(losses) == [("CAMERA watch", "camera mode")]
    plan = next(c for c in model.cameras if c.name == "plan")
    assert plan.orthographic_view_width == pytest.approx(0.6) and plan.field_view_angle is None
    adf = tmp_path / "src.yaml"
    write(model, adf)
    back, _ = read(adf)
    out = tmp_path / "back.xml"
    # MuJoCo's global near/far, read into each ADF camera, cannot be written per camera
    assert loss_keys(write(back, out)) == [
        ("CAMERA eye", "clipping plane"),
        ("CAMERA plan", "clipping plane"),
        ("CAMERA watch", "clipping plane"),
    ]
    ma, da = _mj(src)
    mb, db = _mj(out)
    rng = random.Random(5)
    for q in [None] + [rng.uniform(-3, 3) for _ in range(20)]:
        for m, d in ((ma, da), (mb, db)):
            _at(m, d, q)
        for name in ("eye", "plan"):
            a, b = ma.camera(name).id, mb.camera(name).id
            assert np.allclose(da.cam_xpos[a], db.cam_xpos[b], atol=1e-9), name
            assert np.allclose(da.cam_xmat[a], db.cam_xmat[b], atol=1e-9), name
            assert mb.cam_fovy[b] == pytest.approx(ma.cam_fovy[a]), name
            assert tuple(mb.cam_resolution[b]) == tuple(ma.cam_resolution[a]), name
            assert mb.cam_projection[b] == ma.cam_projection[a], name
        a, b = ma.light("lamp").id, mb.light("lamp").id
        assert np.allclose(da.light_xpos[a], db.light_xpos[b], atol=1e-9)
        assert np.allclose(da.light_xdir[a], db.light_xdir[b], atol=1e-9)
        for attr in ("light_cutoff", "light_exponent", "light_attenuation", "light_castshadow"):
            assert np.allclose(getattr(mb, attr)[b], getattr(ma, attr)[a]), attr
    # the tracking camera: fixed in ADF, seeing at qpos0 what MuJoCo's sees
    _at(ma, da)
    _at(mb, db)
    assert mb.qpos0[0] == pytest.approx(math.radians(20))
    a, b = ma.camera("watch").id, mb.camera("watch").id
    assert mb.cam_mode[b] == 0
    assert np.allclose(da.cam_xpos[a], db.cam_xpos[b], atol=1e-9)
    assert np.allclose(da.cam_xmat[a], db.cam_xmat[b], atol=1e-9)
    watch = next(c for c in model.cameras if c.name == "watch")
    view = (watch.look_at - watch.location).normalized()
    to_link = Vec3(*(da.xpos[ma.body("link").id] - da.cam_xpos[a])).normalized()
    assert view.dot(to_link) == pytest.approx(1.0)  # it looks at the body it tracked
