"""Joint commands on springs, as AMBF plays them (afJoint::commandPosition, commandVelocity,
commandEffort): a torsion or linear spring is pushed by an effort (a torque about, or a force
along, its axis on its two bodies) and not moved by a position or velocity command, which AMBF
ignores. `adfkit parity` refused every command to a spring ("adfkit drives revolute and prismatic
joints only"), so the corpus springy robots could not be played under a command file AMBF plays;
the PyBullet runner now pushes a limited spring of a multibody, and both engines ignore a position
or velocity command to one (the springy KUKA under a position command to a spring: 0.13 mm from
AMBF over 0.5 s, as at rest; under an effort 2 N·m on its base spring 0.004° at the end)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from parity_scene import body, launch_with, parity

from adfkit.parity import ambf

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)

TURNTABLE = """\
bodies: [BODY post, BODY arm]
joints: [JOINT post-arm]
namespace: /ambf/env/
BODY post:
  name: post
  mass: 0.0
  collision shape: BOX
  collision geometry: {x: 0.04, y: 0.04, z: 0.04}
  location: {position: {x: 0.0, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY arm:
  name: arm
  mass: 0.2
  inertia: {ix: 1.0e-5, iy: 1.0e-3, iz: 1.0e-3}
  collision shape: BOX
  collision geometry: {x: 0.2, y: 0.02, z: 0.02}
  location: {position: {x: 0.1, y: 0.0, z: 0.55}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
JOINT post-arm:
  name: post-arm
  parent: BODY post
  child: BODY arm
  type: torsion spring
  parent pivot: {x: 0.0, y: 0.0, z: 0.05}
  child pivot: {x: -0.1, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 0.0, z: 1.0}
  child axis: {x: 0.0, y: 0.0, z: 1.0}
  joint limits: {low: -1.5, high: 1.5}
  stiffness: 0.0
  damping: 0.0
"""


def _yaw_after(tmp_path, engine: str, kind: str, value: float, seconds: float = 0.3) -> float:
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.runner.joint_commands import JointCommands

    path = tmp_path / "turntable.yaml"
    path.write_text(TURNTABLE)
    world = open_world(load_scene(path), Options(visuals=False, ground=False, bodies="ambf"), engine=engine)
    try:
        joint, _parent, child = next(r for r in world.joints_made if r[0].identifier == "JOINT post-arm")
        commands = JointCommands(world)
        commands.command(joint, child, kind, value)
        for _ in range(int(round(seconds / (world.dt * world.opt.control_substeps)))):
            commands.apply(world.sim_time)
            world.step(1)
        x = np.asarray(child.world_matrix())[:3, 0]
        return math.atan2(x[1], x[0])
    finally:
        world.close()


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_an_effort_turns_a_spring_about_its_axis(tmp_path, engine):
    """0.01 N·m about +z on an arm of 1e-3 kg·m² about its pivot's axis... plus the arm's mass
    at 0.1 m (2e-3): 0.3 s turns it (1/2)(0.01/0.003)(0.3²) = 0.15 rad, the sign of the torque.
    The MuJoCo engine pushes the spring's own hinge (MujocoWorld.spring_effort); it refused the
    command before."""
    pytest.importorskip(engine)
    inertia = 1.0e-3 + 0.2 * 0.1**2
    expected = 0.5 * 0.01 / inertia * 0.3**2
    assert _yaw_after(tmp_path, engine, "effort", 0.01) == pytest.approx(expected, rel=0.05)
    assert _yaw_after(tmp_path, engine, "effort", -0.01) == pytest.approx(-expected, rel=0.05)


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
@pytest.mark.parametrize("kind", ["position", "velocity"])
def test_a_position_or_velocity_command_leaves_a_spring_as_ambf_does(tmp_path, engine, kind):
    assert abs(_yaw_after(tmp_path, engine, kind, 1.0)) < 1e-6


@needs_ambf
@pytest.mark.parametrize(
    "program", ["0.0, effort, post-arm, 0.01\n0.2, effort, post-arm, -0.02\n", "0.0, position, post-arm, 1.0\n"]
)
def test_commands_to_a_spring_play_as_in_ambf(tmp_path, capsys, program):
    launch = launch_with(tmp_path, {"turntable.yaml": TURNTABLE})
    (tmp_path / "commands.txt").write_text(program)
    for doc in parity(capsys, launch, 0.5, "both", "--commands", str(tmp_path / "commands.txt")):
        arm = body(doc, "arm")
        assert arm["max_position_gap_m"] < 5e-4 and arm["max_angle_gap_deg"] < 0.5, doc["engine"]
