"""A velocity motor with a small `max motor impulse` pushing a slider's sled against a wall: in
AMBF the sled stops against the wall and stays. adfkit's sled bounces back off it (a known bug,
marked xfail): on the chain step's path (runner/joint_commands.py, JointCommands._soft_rows) the
correction for the other forces, extrapolated from the step before, takes in the wall's contact
impulse and the push that answers it is not held to the motor's cap. Holding the push to the cap
stops the sled (0.001 mm from AMBF's, PyBullet; 1.16 mm, MuJoCo) but takes the MTM's position
program from 1.25 to 1.79 mm (test_parity.py): the fix waits on that choice."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pybullet")

from adfkit.parity import ambf  # noqa: E402

BUILD, WHY = ambf.available()

# a 0.5 kg sled on a slider along x (limits ±0.3 m) from a static rail, at x = -0.3, driven at
# 0.5 m/s by a motor of 0.002 N·s per step (2 N) toward a static wall whose face is at x = -0.11:
# the sled (6 cm) touches it at q = 0.16 m
SCENE = """
bodies: [BODY floor, BODY rail, BODY sled, BODY wall]
joints: [JOINT rail-sled]
namespace: /ambf/env/cap/
BODY floor:
  name: floor
  mass: 0
  shape: BOX
  geometry: {x: 3.0, y: 3.0, z: 0.1}
  collision shape: BOX
  collision geometry: {x: 3.0, y: 3.0, z: 0.1}
  location: {position: {x: 0, y: 0, z: -0.05}, orientation: {r: 0, p: 0, y: 0}}
  friction: {static: 0.5}
BODY rail:
  name: rail
  mass: 0
  shape: BOX
  geometry: {x: 0.6, y: 0.02, z: 0.02}
  collision shape: BOX
  collision geometry: {x: 0.6, y: 0.02, z: 0.02}
  location: {position: {x: -0.4, y: 0.3, z: 0.01}, orientation: {r: 0, p: 0, y: 0}}
BODY sled:
  name: sled
  mass: 0.5
  shape: BOX
  geometry: {x: 0.06, y: 0.06, z: 0.06}
  collision shape: BOX
  collision geometry: {x: 0.06, y: 0.06, z: 0.06}
  location: {position: {x: -0.3, y: 0, z: 0.03}, orientation: {r: 0, p: 0, y: 0}}
  friction: {static: 0.3}
BODY wall:
  name: wall
  mass: 0
  shape: BOX
  geometry: {x: 0.02, y: 0.3, z: 0.2}
  collision shape: BOX
  collision geometry: {x: 0.02, y: 0.3, z: 0.2}
  location: {position: {x: -0.1, y: 0, z: 0.1}, orientation: {r: 0, p: 0, y: 0}}
JOINT rail-sled:
  name: rail-sled
  parent: BODY rail
  child: BODY sled
  type: prismatic
  parent pivot: {x: 0.1, y: -0.3, z: 0.02}
  child pivot: {x: 0, y: 0, z: 0}
  parent axis: {x: 1, y: 0, z: 0}
  child axis: {x: 1, y: 0, z: 0}
  joint limits: {low: -0.3, high: 0.3}
  controller output type: VELOCITY
  max motor impulse: 0.002
"""
TOUCH = 0.16  # m: the joint's position with the sled against the wall


def _scene(tmp_path):
    path = tmp_path / "capped_wall.yaml"
    path.write_text(SCENE)
    return path


BOUNCES = pytest.mark.xfail(
    strict=True, reason="the capped motor's push is not held to its cap on the chain step's path: the sled bounces"
)


@BOUNCES
@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_capped_velocity_motor_stops_against_a_wall(tmp_path, engine):
    """Played as `adfkit parity` plays a joint program (AMBF's bodies, one physics step a
    command): the sled reaches the wall (about 0.41 s) and stays against it, within 2 mm, to the
    end (with the push held to the cap; without, 54 mm back from the wall)."""
    if engine == "mujoco":
        pytest.importorskip("mujoco")
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.runner.joint_commands import JointCommands

    opt = Options(visuals=False, ground=False, control_substeps=1)
    opt.bodies = "ambf"  # as `adfkit parity` plays it: the chain step's rows (JointCommands._soft_rows)
    w = open_world(load_scene(_scene(tmp_path)), opt, engine=engine)
    try:
        commands = JointCommands(w)
        joint, _parent, child = next(r for r in w.joints_made if r[0].name == "rail-sled")
        commands.command(joint, child, "velocity", 0.5)
        dj = commands.joints[id(joint)]
        q = []
        for k in range(1, 1501):
            commands.apply(k * w.dt)
            w.step(1)
            q.append(float(w.joint_state(dj.art, [dj.index])[0][0]))
    finally:
        w.close()
    q = np.array(q)
    touched = int(np.argmax(q > TOUCH - 1e-3))
    assert q[touched] > TOUCH - 1e-3, q.max()  # it got there
    assert 0.3 < touched * 1e-3 < 0.7  # at 2 N on 0.5 kg: 0.125 s to 0.5 m/s, then 0.5 m/s
    # PyBullet: within 0.01 mm of the wall; MuJoCo's softer contact lets it in 0.45 mm and back
    # out 1.6 mm once, then it rests against the wall (before: 54 mm back)
    assert np.all(np.abs(q[touched:] - TOUCH) < 2e-3), (q[touched:].min(), q[touched:].max())
    assert abs(q[-1] - TOUCH) < 1e-5


@pytest.mark.skipif(BUILD is None, reason=WHY)
@BOUNCES
@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_the_capped_motor_against_the_wall_matches_ambf(tmp_path, engine):
    """`adfkit parity --seconds 1.5` with the velocity command: AMBF's sled stops against the
    wall too; the sled's largest gap stays under 1 mm (PyBullet), 1.5 mm (MuJoCo)."""
    if engine == "mujoco":
        pytest.importorskip("mujoco")
    from adfkit.parity import session

    cmds = tmp_path / "cmds.txt"
    cmds.write_text("0.0, velocity, rail-sled, 0.5\n")
    req = session.Request(
        _scene(tmp_path), None, BUILD, seconds=1.5, every=0.02, engines=(engine,), commands=cmds, ground=False
    )
    (c,) = session.run(req, progress=False).comparisons
    gaps = {g.name: g.max_position for g in c.bodies}
    # measured: 0.001 mm (PyBullet), 1.157 mm (MuJoCo: its contact lets the sled back 1.6 mm once)
    assert gaps["/ambf/env/cap/sled"] < (1e-3 if engine == "pybullet" else 1.5e-3), gaps
