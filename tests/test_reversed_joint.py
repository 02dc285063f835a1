"""A joint written from a free body into a body already in a kinematic tree: the file's parent
(a bob) hangs on the file's child (an arm hinged to a static post) by a slider. AMBF slides it.
Neither engine's tree took a joint from its child's side: PyBullet built the slider fixed (a
prismatic joint closing a loop through a maximal body) and MuJoCo closed it with a connect
(`adfkit parity` on this model, 1.5 s: 174 and 177 mm from AMBF's bob). Both trees now take it
reversed (model.semantics.ReversedJoint), its value the file's: 1.13 and 1.16 mm."""

from __future__ import annotations

import numpy as np
import pytest
from parity_scene import body, launch_with, parity

from adfkit.model.semantics import ReversedJoint, body_joint_frames
from adfkit.parity import ambf

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)

BOB_ON_ARM = """\
bodies: [BODY post, BODY arm, BODY bob]
joints: [JOINT post-arm, JOINT bob-arm]
namespace: /ambf/env/
BODY post:
  name: post
  mass: 0.0
  collision shape: BOX
  collision geometry: {x: 0.04, y: 0.04, z: 0.04}
  location: {position: {x: 0.0, y: 0.0, z: 1.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY arm:
  name: arm
  mass: 0.2
  collision shape: BOX
  collision geometry: {x: 0.02, y: 0.3, z: 0.02}
  location: {position: {x: 0.0, y: 0.17, z: 1.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY bob:
  name: bob
  mass: 0.1
  collision shape: SPHERE
  collision geometry: {radius: 0.02}
  location: {position: {x: 0.0, y: 0.35, z: 1.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
JOINT post-arm:
  name: post-arm
  parent: BODY post
  child: BODY arm
  type: revolute
  parent pivot: {x: 0.0, y: 0.02, z: 0.0}
  child pivot: {x: 0.0, y: -0.15, z: 0.0}
  parent axis: {x: 1.0, y: 0.0, z: 0.0}
  child axis: {x: 1.0, y: 0.0, z: 0.0}
JOINT bob-arm:
  name: bob-arm
  parent: BODY bob
  child: BODY arm
  type: prismatic
  parent pivot: {x: 0.0, y: 0.0, z: 0.0}
  child pivot: {x: 0.0, y: 0.18, z: 0.0}
  parent axis: {x: 0.0, y: 1.0, z: 0.0}
  child axis: {x: 0.0, y: 1.0, z: 0.0}
  joint limits: {low: -0.05, high: 0.05}
"""


def _slide(bob: np.ndarray, arm: np.ndarray) -> float:
    """The file's joint value: the arm's pivot from the bob's along the bob's y axis."""
    return float((arm[:3, :3] @ np.array([0.0, 0.18, 0.0]) + arm[:3, 3] - bob[:3, 3]) @ bob[:3, 1])


@pytest.mark.parametrize("kind", ["prismatic", "revolute"])
def test_a_reversed_joint_moves_its_child_frame_as_the_file_s_by_the_same_value(tmp_path, kind):
    """At joint value q the file's child frame is its parent's moved by q (along x for a slide,
    about z for a hinge); the reversed joint's frames, at the same q, put the file's parent back
    where it was: the two relations compose to the identity."""
    from adfkit.adf.reader import load
    from adfkit.model.pose import Pose, Quat, Vec3

    path = tmp_path / "bob.yaml"
    path.write_text(BOB_ON_ARM.replace("type: prismatic", f"type: {kind}"))
    model = load(path)
    joint = next(j for j in model.joints if j.identifier == "JOINT bob-arm")
    bob, arm = (next(b for b in model.bodies if b.name == n) for n in ("bob", "arm"))
    a, b = body_joint_frames(joint, bob, arm)
    ra, rb = body_joint_frames(ReversedJoint(joint), arm, bob)
    q = 0.03
    move = Pose(Vec3(q, 0.0, 0.0)) if kind == "prismatic" else Pose(Vec3(), Quat.from_axis_angle(Vec3(0, 0, 1), q))
    arm_in_bob = a * move * b.inverse()
    bob_in_arm = ra * move * rb.inverse()
    back = arm_in_bob * bob_in_arm
    assert np.allclose(back.position, 0.0, atol=1e-12)
    assert abs(abs(back.orientation.w) - 1.0) < 1e-12


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_bob_slides_on_the_arm_its_joint_names_as_child(tmp_path, engine):
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    path = tmp_path / "bob.yaml"
    path.write_text(BOB_ON_ARM)
    world = open_world(load_scene(path), Options(visuals=False, ground=False, bodies="ambf"), engine=engine)
    try:
        assert not [d for d in world.diagnostics if "prismatic-loop" in str(d)]
        bob, arm = world.body("bob"), world.body("arm")
        assert _slide(np.array(bob.world_matrix()), np.array(arm.world_matrix())) == pytest.approx(0.0, abs=1e-6)
        world.run(0.6)
        # the arm swings down and the bob slides out onto its lower limit, as AMBF's does
        assert _slide(np.array(bob.world_matrix()), np.array(arm.world_matrix())) == pytest.approx(-0.05, abs=2e-3)
    finally:
        world.close()


@needs_ambf
def test_a_bob_slides_on_the_arm_its_joint_names_as_child_as_in_ambf(tmp_path, capsys):
    for doc in parity(capsys, launch_with(tmp_path, {"bob.yaml": BOB_ON_ARM}), 1.5):
        bob = body(doc, "bob")
        assert bob["max_position_gap_m"] < 2e-3 and bob["max_angle_gap_deg"] < 0.5, doc["engine"]


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_reversed_joint_follows_a_velocity_command_in_the_file_s_sign(tmp_path, engine):
    """Without gravity, the slider commanded at +0.05 m/s moves the file's child (the arm's
    pivot) +0.02 m along the file's parent's (the bob's) axis in 0.4 s, as AMBF's slider would."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.runner.joint_commands import JointCommands

    path = tmp_path / "bob.yaml"
    path.write_text(BOB_ON_ARM)
    opt = Options(visuals=False, ground=False, bodies="ambf", gravity=(0.0, 0.0, 0.0), control_substeps=1)
    world = open_world(load_scene(path), opt, engine=engine)
    try:
        joint, _parent, child = next(r for r in world.joints_made if r[0].identifier == "JOINT bob-arm")
        commands = JointCommands(world)
        commands.command(joint, child, "velocity", 0.05)
        for _ in range(400):
            commands.apply(world.sim_time)
            world.step(1)
        bob, arm = world.body("bob"), world.body("arm")
        assert _slide(np.array(bob.world_matrix()), np.array(arm.world_matrix())) == pytest.approx(0.02, abs=2e-3)
    finally:
        world.close()
