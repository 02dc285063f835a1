"""A joint whose child is a static body (mass 0): AMBF hinges the dynamic parent to it wherever the
file puts it. The MJCF writer's tree hung the static body under its dynamic parent, so in the
MuJoCo engine the post fell with the arm (`adfkit parity` on a hand-made model, 1.5 s: 1005.6 mm
from AMBF). A static body is now the tree's root and the arm hangs from it by the hinge taken from
the child's side (ReversedJoint): 0.47 mm (PyBullet, which made the joint a constraint to the
static body already: 0.17 mm)."""

from __future__ import annotations

import numpy as np
import pytest
from parity_scene import body, launch_with, parity

from adfkit.parity import ambf

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)

ARM_ON_POST = """\
bodies: [BODY post, BODY arm]
joints: [JOINT arm-post]
namespace: /ambf/env/
BODY post:
  name: post
  mass: 0.0
  collision shape: BOX
  collision geometry: {x: 0.04, y: 0.04, z: 0.04}
  location: {position: {x: 0.0, y: 0.0, z: 1.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY arm:
  name: arm
  mass: 0.3
  collision shape: BOX
  collision geometry: {x: 0.3, y: 0.02, z: 0.02}
  location: {position: {x: 0.17, y: 0.0, z: 1.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
JOINT arm-post:
  name: arm-post
  parent: BODY arm
  child: BODY post
  type: revolute
  parent pivot: {x: -0.17, y: 0.0, z: 0.0}
  child pivot: {x: 0.0, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 1.0, z: 0.0}
  child axis: {x: 0.0, y: 1.0, z: 0.0}
"""


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_an_arm_swings_from_the_static_post_its_joint_names_as_child(tmp_path, engine):
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    path = tmp_path / "post.yaml"
    path.write_text(ARM_ON_POST)
    world = open_world(load_scene(path), Options(visuals=False, ground=False), engine=engine)
    try:
        post, arm = world.body("post"), world.body("arm")
        start = np.array(post.world_matrix())
        lowest, apart, off_plane = 1.0, 0.0, 0.0
        for _ in range(100):  # 0.4 s: past the bottom of the swing
            world.step(1)
            t = np.array(arm.world_matrix())
            pivot = t[:3, :3] @ np.array([-0.17, 0.0, 0.0]) + t[:3, 3]
            apart = max(apart, float(np.linalg.norm(pivot - start[:3, 3])))
            off_plane = max(off_plane, abs(float(t[1, 3])))
            lowest = min(lowest, float(t[2, 3]))
        assert np.array_equal(np.array(post.world_matrix()), start)  # the static post stays put
    finally:
        world.close()
    assert apart < 2e-4 and off_plane < 1e-4  # a hinge at the post's centre
    assert lowest < 1.0 - 0.16  # the arm swung down through its lowest point, 0.17 m below


def test_the_mjcf_writer_hangs_the_arm_from_its_static_child_by_the_joint_reversed(tmp_path):
    """The static post is the tree's root and the arm hangs from it by the file's hinge taken
    from the child's side (ReversedJoint): MJCF's joint value is the file's, sign included (the
    post turns +q about y relative to the arm, so the arm turns -q relative to the post)."""
    import xml.etree.ElementTree as ET

    import mujoco

    from adfkit.adf.reader import load
    from adfkit.converters import write

    path = tmp_path / "post.yaml"
    path.write_text(ARM_ON_POST)
    out = tmp_path / "post.xml"
    write(load(path), out)
    root = ET.parse(out).getroot()
    tops = root.find("worldbody").findall("body")
    assert [b.get("name") for b in tops] == ["post"]  # the static post is the root, nobody's child
    assert root.find("equality") is None  # no loop to close
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    assert m.njnt == 1 and m.jnt_type[0] == mujoco.mjtJoint.mjJNT_HINGE
    d.qpos[0] = 0.3
    mujoco.mj_kinematics(m, d)
    arm = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "arm")
    pivot = np.array([0.0, 0.0, 1.0])  # the post's centre
    turn = np.array([[np.cos(-0.3), 0.0, np.sin(-0.3)], [0.0, 1.0, 0.0], [-np.sin(-0.3), 0.0, np.cos(-0.3)]])
    assert np.allclose(d.xipos[arm], pivot + turn @ np.array([0.17, 0.0, 0.0]), atol=1e-9)  # 51 mm up


@needs_ambf
def test_an_arm_swings_from_a_static_child_as_in_ambf(tmp_path, capsys):
    for doc in parity(capsys, launch_with(tmp_path, {"post.yaml": ARM_ON_POST}), 1.5):
        arm, post = body(doc, "arm"), body(doc, "post")
        assert arm["max_position_gap_m"] < 1e-3 and arm["max_angle_gap_deg"] < 0.5, doc["engine"]
        assert post["max_position_gap_m"] == 0.0, doc["engine"]
