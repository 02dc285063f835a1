"""`ignore inter-collision: false` on a joint (adf-format.md §8): AMBF lets the joint's two
bodies collide. The PyBullet runner built every multibody with its links never meeting their
parents (URDF_USE_SELF_COLLISION_EXCLUDE_PARENT), so an arm hinged above a block fell through it
(`adfkit parity` on a hand-made model: 199.6 mm, 172.9 deg from AMBF's, which rests on the block)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from adfkit.cli import main
from adfkit.parity import ambf

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)

#: a 0.2 m arm, 2 cm thick, hinged 2 cm above the left top edge of a static 0.1 m block: it
#: falls until its underside meets the block's right top edge, atan(0.02/0.1) - asin(0.01/|(0.1, 0.02)|)
REST_DEG = math.degrees(math.atan2(0.02, 0.1) - math.asin(0.01 / math.hypot(0.1, 0.02)))

ARM_ON_BLOCK = """\
bodies: [BODY block, BODY arm]
joints: [JOINT block-arm]
namespace: /ambf/env/lid/
BODY block:
  name: block
  mass: 0.0
  collision shape: BOX
  collision geometry: {x: 0.1, y: 0.1, z: 0.1}
  location: {position: {x: 0.0, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY arm:
  name: arm
  mass: 0.2
  collision shape: BOX
  collision geometry: {x: 0.2, y: 0.02, z: 0.02}
  location: {position: {x: 0.05, y: 0.0, z: 0.57}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
JOINT block-arm:
  name: block-arm
  parent: BODY block
  child: BODY arm
  type: revolute
  parent pivot: {x: -0.05, y: 0.0, z: 0.07}
  child pivot: {x: -0.1, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 1.0, z: 0.0}
  child axis: {x: 0.0, y: 1.0, z: 0.0}
  ignore inter-collision: IGNORE
"""


def _arm_pitch_deg(tmp_path, engine: str, ignore: str) -> float:
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    path = tmp_path / f"lid_{ignore}.yaml"
    path.write_text(ARM_ON_BLOCK.replace("IGNORE", ignore))
    world = open_world(load_scene(path), Options(visuals=False, ground=False), engine=engine)
    try:
        world.run(1.0)
        arm = next(b for b in world.bodies if b.key.endswith("arm"))
        x_axis = np.asarray(arm.world_matrix())[:3, 0]
    finally:
        world.close()
    return math.degrees(math.atan2(-x_axis[2], x_axis[0]))


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_joint_that_does_not_ignore_inter_collision_lets_its_bodies_meet(tmp_path, engine):
    """The arm rests on the block's edge at REST_DEG (5.68 deg below level); control: the same
    joint ignoring inter-collision (AMBF's default) lets the arm swing down through the block."""
    assert _arm_pitch_deg(tmp_path, engine, "false") == pytest.approx(REST_DEG, abs=0.1)
    assert _arm_pitch_deg(tmp_path, engine, "true") > 30.0


@needs_ambf
def test_an_arm_rests_on_the_block_it_is_hinged_to_as_in_ambf(tmp_path, capsys):
    path = tmp_path / "lid.yaml"
    path.write_text(ARM_ON_BLOCK.replace("IGNORE", "false"))
    main(["parity", str(path), "--seconds", "1.0", "--engine", "both", "--json"])
    for doc in json.loads(capsys.readouterr().out):
        arm = next(b for b in doc["bodies"] if b["name"].endswith("/arm"))
        assert arm["final_position_gap_m"] < 1e-4 and arm["final_angle_gap_deg"] < 0.05, doc["engine"]
