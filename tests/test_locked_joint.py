"""A revolute joint whose limits are equal (`joint limits: {low: 0.3, high: 0.3}`): Bullet holds it
there (btAngularLimit of half range 0), and so does AMBF. MuJoCo refuses a joint range that is not
low < high ("range[0] should be smaller than range[1]"), so the MuJoCo engine refused the whole
scene; the MJCF writer now writes such a range 1e-6 wide about the value (engine_fit.joint_range).
Measured against AMBF (`adfkit parity`, 1.5 s, a 0.2 kg arm hinged to a static block): MuJoCo
0.026 mm at the end, PyBullet 0.000 mm."""

from __future__ import annotations

import numpy as np
import pytest

from adfkit.adf import load_scene
from adfkit.converters.engine_fit import LOCKED_RANGE, joint_range
from adfkit.runner import Options, open_world

ARM = """bodies: [BODY post, BODY arm]
joints: [JOINT hinge]
BODY post:
  name: post
  mass: 0.0
  collision shape: Box
  collision geometry: {x: 0.02, y: 0.02, z: 0.02}
  location: {position: {x: 0.0, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY arm:
  name: arm
  mass: 0.2
  collision shape: Box
  collision geometry: {x: 0.2, y: 0.01, z: 0.01}
  location: {position: {x: 0.11, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
JOINT hinge:
  name: hinge
  parent: BODY post
  child: BODY arm
  type: revolute
  parent pivot: {x: 0.0, y: 0.0, z: 0.0}
  child pivot: {x: -0.11, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 1.0, z: 0.0}
  child axis: {x: 0.0, y: 1.0, z: 0.0}
  joint limits: {low: 0.3, high: 0.3}
"""


def test_equal_limits_are_a_hair_apart_for_mujoco(tmp_path):
    (tmp_path / "m.yaml").write_text(ARM)
    joint = load_scene(tmp_path / "m.yaml", None, []).all_models()[0].joints[0]
    losses: list = []
    low, high = joint_range(joint, losses)
    assert (low, high) == pytest.approx((0.3 - LOCKED_RANGE / 2, 0.3 + LOCKED_RANGE / 2), abs=1e-12)
    assert low < high and "held there" in losses[0].reason


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_joint_with_equal_limits_is_held_there(tmp_path, engine):
    """Both engines build the scene and hold the arm 0.3 rad from where the file puts it
    (level), where a free hinge lets it hang 1.57 rad down."""
    pytest.importorskip(engine)
    (tmp_path / "m.yaml").write_text(ARM)
    world = open_world(load_scene(tmp_path / "m.yaml", None, []), Options(visuals=False, ground=False), engine=engine)
    try:
        world.run(1.0)
        m = world.body("BODY arm").world_matrix()
    finally:
        world.close()
    tilt = float(np.arctan2(-m[2, 0], m[0, 0]))  # the arm's x axis below level, about y
    assert abs(tilt) == pytest.approx(0.3, abs=0.01)
