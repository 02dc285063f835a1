"""A maximal-coordinate body turns by its own inertia from the first physics step.

PyBullet (Bullet's btRigidBody) recomputes a body's world-frame inverse inertia only when it
integrates the body, so an inertia set by changeDynamics reached the first physics step as the
collision shape's own: the springy-holes suturing copy's thread elements (5e-5 kg·m²) spun at
over 100 rad/s in their first control step, and its needle settled 1.8 mm and 11.6° from AMBF's.
AMBF makes its bodies with their inertia; so does the runner under AMBF's bodies."""

from __future__ import annotations

import pytest
from conftest import box_camera_model

pb = pytest.importorskip("pybullet")


def _spun(cid: int, uid: int, torque: float) -> float:
    """The body's angular velocity about x after one 1 ms physics step under ``torque`` N·m."""
    pb.setPhysicsEngineParameter(fixedTimeStep=0.001, numSubSteps=1, physicsClientId=cid)
    pb.applyExternalTorque(uid, -1, [torque, 0.0, 0.0], pb.WORLD_FRAME, physicsClientId=cid)
    pb.stepSimulation(physicsClientId=cid)
    return pb.getBaseVelocity(uid, physicsClientId=cid)[1][0]


@pytest.mark.parametrize("refresh", [False, True])
def test_an_inertia_set_by_change_dynamics_reaches_the_first_step_only_once_refreshed(refresh):
    from adfkit.runner.pybullet.bodies import refresh_inertia

    cid = pb.connect(pb.DIRECT)
    try:
        pb.setGravity(0, 0, 0, physicsClientId=cid)
        shape = pb.createCollisionShape(pb.GEOM_CAPSULE, radius=0.0005, height=0.0024, physicsClientId=cid)
        uid = pb.createMultiBody(0.03, shape, basePosition=[0, 0, 0.5], useMaximalCoordinates=True, physicsClientId=cid)
        pb.changeDynamics(uid, -1, localInertiaDiagonal=[5e-5] * 3, angularDamping=0.0, physicsClientId=cid)
        if refresh:
            refresh_inertia(cid)
            assert pb.getBasePositionAndOrientation(uid, physicsClientId=cid) == ((0.0, 0.0, 0.5), (0.0, 0.0, 0.0, 1.0))
            assert pb.getBaseVelocity(uid, physicsClientId=cid) == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        w = _spun(cid, uid, 0.054)
    finally:
        pb.disconnect(cid)
    if refresh:
        assert w == pytest.approx(0.054 * 0.001 / 5e-5, rel=1e-6)  # 1.08 rad/s: its own inertia
    else:  # the capsule's own inertia (about 3e-8 kg·m²): PyBullet's first step
        assert w > 1000.0


@pytest.mark.parametrize("bodies", ["ambf", "pybullet"])
def test_a_body_in_a_world_of_ambfs_bodies_turns_by_its_file_inertia_at_once(tmp_path, bodies):
    """A 1 kg, 0.2 m box whose file gives 1e-3 kg·m² (its box shape's own is 6.7e-3): 0.01 N·m
    for 1 ms turns it at 0.01 rad/s under AMBF's bodies (`adfkit run`, `adfkit parity`); the
    Options the tasks were accepted on keep PyBullet's first step (0.0015 rad/s)."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    model = tmp_path / "box.yaml"
    model.write_text(box_camera_model(mass=1.0, z=1.0))
    world = open_world(load_scene(model), Options(bodies=bodies, visuals=False, ground=False, gravity=(0.0, 0.0, 0.0)))
    try:
        box = next(b for b in world.bodies if b.key.endswith("box"))
        w = _spun(world.cid, box.uid, 0.01)
    finally:
        world.close()
    own = 0.01 * 0.001 / 1e-3
    if bodies == "ambf":
        assert w == pytest.approx(own, rel=1e-3)
    else:
        assert w == pytest.approx(0.01 * 0.001 / (1.0 * 0.08 / 12), rel=1e-2)  # the box shape's inertia
