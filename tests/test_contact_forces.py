"""Contact forces in newtons in both engines, however a PyBullet world steps, and the suture's
force limits per engine (adfkit/tasks/contact_forces.py)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from adfkit.adf import load_scene
from adfkit.runner import Options, open_world
from adfkit.tasks.contact_forces import limit_scale
from adfkit.tasks.verdicts import force_limits

BOX_ON_PLANE = (
    "bodies: [BODY Plane, BODY Box]\njoints: []\nnamespace: /ambf/env/\n"
    "BODY Plane:\n  name: Plane\n  mass: 0.0\n"
    "  location: {position: {x: 0.0, y: 0.0, z: -0.05}, orientation: {r: 0.0, p: 0.0, y: 0.0}}\n"
    "  collision shape: BOX\n  collision geometry: {x: 1.0, y: 1.0, z: 0.1}\n"
    "BODY Box:\n  name: Box\n  mass: 1.0\n  inertia: {ix: 0.01, iy: 0.01, iz: 0.01}\n"
    "  location: {position: {x: 0.0, y: 0.0, z: 0.05}, orientation: {r: 0.0, p: 0.0, y: 0.0}}\n"
    "  collision shape: BOX\n  collision geometry: {x: 0.1, y: 0.1, z: 0.1}\n"
)


@pytest.mark.parametrize("substeps", [4, 1])
@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_1_kg_box_at_rest_presses_on_the_plane_with_its_weight(tmp_path, engine, substeps):
    """World.contacts and contacts_among: a 1 kg box resting on a plane presses on it with
    9.81 N, whether a control step is one stepSimulation of four physics steps (PyBullet reports
    a quarter of the force there, the last physics step's impulse over the whole control step:
    read 2.45 N before) or one."""
    pytest.importorskip(engine)
    path = tmp_path / "box.yaml"
    path.write_text(BOX_ON_PLANE)
    awake = {"sleep": False} if engine == "mujoco" else {}  # a sleeping body reports no contacts
    world = open_world(load_scene(path), Options(visuals=False, control_substeps=substeps), engine=engine, **awake)
    try:
        assert engine == "mujoco" or world.physics_steps_a_call == substeps
        world.run(0.5)
        box = world.body("Box")
        pressed = sum(f for other, f, _ in world.contacts(box) if other.name == "Plane")
        among = sum(f for sb, other, f, _ in world.contacts_among([box]) if other.name == "Plane")
    finally:
        world.close()
    assert pressed == pytest.approx(9.81, rel=0.01)
    assert among == pytest.approx(pressed, rel=1e-12)


def test_the_suture_limits_per_engine():
    """MuJoCo's limits are the figures written in verdicts.py and motions.py; PyBullet's, set on
    its reading at 4 substeps (a quarter of the force), are 4x in newtons."""
    assert limit_scale(SimpleNamespace(engine="mujoco")) == 1.0
    assert limit_scale(SimpleNamespace(engine="pybullet")) == 4.0
    assert force_limits(1.0) == {
        "tool_hit_n": 50.0,
        "forced_n": 40.0,
        "thread_forced_n": 1000.0,
        "block_n": 1.0,
        "touch_n": 0.05,
    }
    assert force_limits(4.0) == {
        "tool_hit_n": 200.0,
        "forced_n": 160.0,
        "thread_forced_n": 4000.0,
        "block_n": 4.0,
        "touch_n": 0.2,
    }
