"""Primitives on a floor as AMBF's Bullet plays them: PyBullet's cylinder is Bullet's implicit,
round btCylinderShapeZ (as AMBF's, not a polygonal hull), and the MuJoCo engine, where AMBF's
bodies are asked for (Options.bodies "ambf"), gives a body AMBF's friction (static 0.5 and rolling
0.01 where the file gives none) and plays its rolling friction (contacts.ambf_surface)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco")
pb = pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402

R = 0.03  # m, the cylinder's and the ball's radius

CYLINDER = """\
bodies: [BODY roller]
joints: []
namespace: /ambf/env/
BODY roller:
  name: roller
  mass: 0.2
  inertia: {ix: 0.000211667, iy: 0.000211667, iz: 9.0e-05}
  collision shape: CYLINDER
  collision geometry: {radius: 0.03, height: 0.1, axis: y}
  friction: {static: 0.5, rolling: 0.0}
  location: {position: {x: 0.0, y: 0.0, z: 0.03}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
"""

BALL = """\
bodies: [BODY ball]
joints: []
namespace: /ambf/env/
BODY ball:
  name: ball
  mass: 0.2
  inertia: {ix: 7.2e-05, iy: 7.2e-05, iz: 7.2e-05}
  collision shape: SPHERE
  collision geometry: {radius: 0.03}
  location: {position: {x: 0.0, y: 0.0, z: 0.03}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
"""


def _heights_rolling(step, height, steps: int) -> np.ndarray:
    """The body's centre height at each of ``steps`` steps after the first tenth."""
    zs = []
    for _ in range(steps):
        step()
        zs.append(height())
    return np.array(zs[steps // 10 :])


def test_the_pybullet_runners_cylinder_rolls_round(tmp_path):
    """Pushed at 0.5 m/s, the cylinder slides into rolling on the floor and its centre stays
    within 0.05 mm of one height over 0.9 s and 0.24 m (measured 0.008 mm): Bullet's implicit cylinder, as
    AMBF's. Control: PyBullet's URDF cylinder, a hull of 32 sides, bounces 0.17 mm."""
    path = tmp_path / "roller.yaml"
    path.write_text(CYLINDER)
    w = open_world(load_scene(path), Options(visuals=False, bodies="ambf"))
    try:
        sb = w.bodies[0]
        w.set_body_velocity(sb, [0.5, 0.0, 0.0], [0.0, 0.0, 0.0])
        zs = _heights_rolling(lambda: w.step(1), lambda: sb.com_position()[2], 250)  # 4 ms control steps
        travelled = sb.com_position()[0]
    finally:
        w.close()
    assert travelled > 0.2  # it rolled (0.24 m; the file gives it no rolling friction)
    assert np.ptp(zs) < 5e-5, np.ptp(zs)

    cid = pb.connect(pb.DIRECT)
    try:
        pb.setTimeStep(0.001, physicsClientId=cid)
        pb.setGravity(0, 0, -9.81, physicsClientId=cid)
        floor = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[5, 5, 0.05], physicsClientId=cid)
        pb.createMultiBody(0, floor, basePosition=[0, 0, -0.05], physicsClientId=cid)
        urdf = tmp_path / "roller.urdf"
        urdf.write_text(
            '<robot name="r"><link name="l"><inertial><mass value="0.2"/>'
            '<inertia ixx="2.1e-4" iyy="2.1e-4" izz="9e-5" ixy="0" ixz="0" iyz="0"/></inertial>'
            f'<collision><geometry><cylinder radius="{R}" length="0.1"/></geometry></collision></link></robot>'
        )
        along_y = pb.getQuaternionFromEuler([np.pi / 2, 0, 0])
        hull = pb.loadURDF(str(urdf), [0, 0, R], along_y, useMaximalCoordinates=True, physicsClientId=cid)
        pb.resetBaseVelocity(hull, [0.5, 0, 0], [0, 0, 0], physicsClientId=cid)
        zs = _heights_rolling(
            lambda: pb.stepSimulation(physicsClientId=cid),
            lambda: pb.getBasePositionAndOrientation(hull, physicsClientId=cid)[0][2],
            1000,
        )
    finally:
        pb.disconnect(cid)
    assert np.ptp(zs) > 1e-4, np.ptp(zs)


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_rolling_ball_stops_as_bullets_rolling_friction_stops_it(tmp_path, engine):
    """A 0.2 kg, 3 cm ball rolling at 0.15 m/s on the floor (rolling friction 0.01 × the floor's
    0.5, Bullet's combination: 0.005 m) stops after v²/2a = 9.6 mm, a = μr·m·g·r/(I + m·r²)
    (PyBullet measured 9.52 mm, its damping too; MuJoCo 11.19 mm, its elliptic friction cone
    sharing the rolling limit with the friction that keeps the ball rolling). Control: the MuJoCo
    engine with Options() defaults plays no rolling friction: the ball rolls on (59 mm by 0.4 s)."""
    path = tmp_path / "ball.yaml"
    path.write_text(BALL)
    travel = {}
    for bodies in ("ambf", "pybullet"):
        w = open_world(load_scene(path), Options(visuals=False, bodies=bodies), engine=engine)
        try:
            sb = w.bodies[0]
            w.step(25)  # resting on the floor
            x0 = sb.com_position()[0]
            w.set_body_velocity(sb, [0.15, 0.0, 0.0], [0.0, 0.15 / R, 0.0])
            w.step(100)  # 0.4 s
            travel[bodies] = sb.com_position()[0] - x0
            w.step(25)
            rolled_on = sb.com_position()[0] - x0 - travel[bodies]
            if engine == "mujoco":
                gid = int(np.flatnonzero(w.model.geom_bodyid == sb.id)[0])
                friction, condim = w.model.geom_friction[gid], int(w.model.geom_condim[gid])
        finally:
            w.close()
        if engine == "mujoco":  # AMBF's 0.5 and 0.01 where the file gives none, rolling played
            assert (condim, friction[0], friction[2]) == ((6, 0.5, 0.01) if bodies == "ambf" else (3, 1.0, 1e-4))
        if bodies == "ambf":
            assert abs(rolled_on) < 1e-5  # stopped
    assert travel["ambf"] == pytest.approx(9.6e-3, rel=0.2), travel
    if engine == "pybullet":
        assert travel["pybullet"] == pytest.approx(travel["ambf"], abs=1e-6)
    else:
        assert travel["pybullet"] > 0.04, travel
