"""AMBF's `resistance` sensors (adf-format.md §11.1; afResistanceSensor::update), played by both
engines under AMBF's bodies (runner/resistance.py, runner/pybullet/resist.py,
runner/mujoco/resist.py). Before, the runner skipped them: a 0.1 kg tip whose 50 mm ray reaches
39 mm into a block, contact stiffness 3, was thrown up by AMBF (168.6 mm at 0.14 s) and lay on the
block in adfkit (47 mm apart at 0.14 s). Now (`adfkit parity`) over 0.3 s, thrown, landed and thrown
again: PyBullet 0.015 mm, MuJoCo 0.14 mm (it lands the tip level, where Bullet's contact solver
tilts it 0.11°: 4.1 mm / 12.8° by 0.6 s, PyBullet 1.05 mm / 0.75°). A ray 15 mm off the axis turns
the tip over, 60° in 0.1 s: PyBullet 0.0000 mm / 0.000°, MuJoCo 0.0024 mm / 0.002° from AMBF; a
free block under a free tip, 10 mm off its axis, pushed down and turned over 0.2 s: PyBullet 0.0000
mm, MuJoCo 0.014 mm / 0.000°."""

from __future__ import annotations

import numpy as np
import pytest
from parity_scene import body, launch_with, parity

from adfkit.parity import ambf
from adfkit.runner.resistance import Body, RayState, ResistanceParams, missed, ray_force

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)

TIP = """\
bodies: [BODY block, BODY tip]
sensors: [SENSOR res]
namespace: /ambf/env/press/
BODY block:
  name: block
  shape: BOX
  geometry: {x: 0.3, y: 0.3, z: 0.1}
  collision shape: BOX
  collision geometry: {x: 0.3, y: 0.3, z: 0.1}
  location: {position: {x: 0.0, y: 0.0, z: 0.05}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  mass: 0.0
BODY tip:
  name: tip
  shape: BOX
  geometry: {x: 0.04, y: 0.04, z: 0.04}
  collision shape: BOX
  collision geometry: {x: 0.04, y: 0.04, z: 0.04}
  location: {position: {x: 0.0, y: 0.0, z: 0.121}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  mass: 0.1
  inertia: {ix: 0.0000266667, iy: 0.0000266667, iz: 0.0000266667}
SENSOR res:
  name: res
  type: resistance
  parent: BODY tip
  location: {position: {x: 0.0, y: 0.0, z: -0.01}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  range: 0.05
  array:
  - offset: {x: 0.0, y: 0.0, z: 0.0}
    direction: {x: 0.0, y: 0.0, z: -1.0}
  friction: {static: 0.5, damping: 0.1, dynamic: 0.5, variable: false}
  contact area: 0.01
  contact stiffness: 3.0
  contact damping: 0.1
"""

I3 = np.eye(3)
DOWN = np.array([0.0, 0.0, -1.0])


def _still(at=(0.0, 0.0, 0.0), v=(0.0, 0.0, 0.0)) -> Body:
    return Body(np.array(at, float), I3, np.array(v, float), np.zeros(3))


def test_the_normal_force_is_stiffness_times_depth_along_the_ray():
    p = ResistanceParams(stiffness=3.0, damping=0.0)
    st = RayState()
    hit = np.array([0.0, 0.0, 0.1])
    f = ray_force(p, st, DOWN, _still((0, 0, 0.13)), _still(), hit, np.array([0, 0, 1.0]), 0.6)
    # 3·0.6·(0, 0, -1): the sensed body pushed down, the parent (-F) up
    assert np.allclose(f, [0.0, 0.0, -1.8])
    # and no damping on the depth's change (AMBF's contact damping reads the depth it just wrote)
    f = ray_force(p, st, DOWN, _still((0, 0, 0.13)), _still(), hit, np.array([0, 0, 1.0]), 0.5)
    assert np.allclose(f, [0.0, 0.0, -1.5])


def test_static_friction_pulls_the_stored_points_together_and_dynamic_opposes_sliding():
    p = ResistanceParams(static=2.0, damping=0.0, dynamic=0.5, area=0.01)
    st = RayState()
    n, hit = np.array([0, 0, 1.0]), np.array([0.0, 0.0, 0.1])
    f = ray_force(p, st, DOWN, _still((0, 0, 0.13)), _still(), hit, n, 0.0)
    assert np.allclose(f, 0.0) and st.valid  # the first hit stores the point on both bodies
    # the parent 3 mm along x, sliding at 0.2 m/s (and 0.5 m/s along the normal: not friction)
    f = ray_force(p, st, DOWN, _still((0.003, 0, 0.13), (0.2, 0, 0.5)), _still(), hit, n, 0.0)
    assert np.allclose(f, [2.0 * 0.003 + 0.5 * 0.2, 0.0, 0.0])
    # 12 mm apart: past the contact area, the points dropped (stored again at the next hit)
    f = ray_force(p, st, DOWN, _still((0.012, 0, 0.13)), _still(), hit, n, 0.0)
    assert np.allclose(f, 0.0) and not st.valid
    ray_force(p, st, DOWN, _still((0.012, 0, 0.13)), _still(), hit, n, 0.0)
    assert st.valid  # stored again
    missed(st)
    assert not st.valid  # a miss drops them too


def test_the_sensor_keys_and_ambf_s_defaults():
    class F:
        static, damping, dynamic, variable = 0.5, None, None, True

    class S:
        friction, contact_area, contact_stiffness, contact_damping = F, None, 3.0, None

    p = ResistanceParams.of(S)
    assert (p.static, p.damping, p.dynamic, p.variable) == (0.5, 0.1, 0.0, True)
    assert (p.area, p.stiffness) == (0.1, 3.0)


#: the sensor 15 mm off the tip's axis and the tip 20 mm over the block: the ray turns it over
#: before it touches the block (lands on its side at 0.11 s)
OFF_AXIS = TIP.replace("position: {x: 0.0, y: 0.0, z: -0.01}", "position: {x: 0.015, y: 0.0, z: -0.01}").replace(
    "z: 0.121}", "z: 0.14}"
)

#: the block free too (0.3 kg), 10 mm off the tip's axis, both falling from 0.5 m: the ray pushes
#: the block down and the tip up, and turns both (the hit 10 mm off the block's COM)
PAIR = TIP.replace(
    "location: {position: {x: 0.0, y: 0.0, z: 0.05}, orientation: {r: 0.0, p: 0.0, y: 0.0}}\n  mass: 0.0",
    "location: {position: {x: 0.01, y: 0.0, z: 0.45}, orientation: {r: 0.0, p: 0.0, y: 0.0}}\n  mass: 0.3\n"
    "  inertia: {ix: 0.0025, iy: 0.0025, iz: 0.0045}",
).replace("z: 0.121}", "z: 0.521}")


def _tip_after(tmp_path, engine: str, seconds: float, text: str = TIP, bodies: str = "ambf"):
    """The tip's pose (4×4) after ``seconds`` and the world's diagnostics' rules."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    launch = launch_with(tmp_path, {"tip.yaml": text})
    world = open_world(load_scene(launch), Options(visuals=False, bodies=bodies), engine=engine)
    try:
        tip = next(b for b in world.bodies if b.name.endswith("tip"))
        world.run(seconds)
        return tip.world_matrix(), [d.rule for d in world.diagnostics]
    finally:
        world.close()


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_the_tip_is_pushed_off_the_block_as_ambf_pushes_it(tmp_path, engine):
    t, rules = _tip_after(tmp_path, engine, 0.02)
    # AMBF: 123.3527 mm at 20 ms (from 121 mm; without the sensor the tip falls 1 mm onto the block)
    assert t[2, 3] == pytest.approx(0.1233527, abs=1e-6)
    assert "runner-sensor" not in rules


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_contact_damping_does_nothing_as_in_ambf(tmp_path, engine):
    """AMBF reads the last depth after its ray tracer has overwritten it: 123.3527 mm at 20 ms with
    contact damping 20 as with 0.1 (its damping on the depth's change would make it 126.09 mm)."""
    t, _ = _tip_after(tmp_path, engine, 0.02, TIP.replace("contact damping: 0.1", "contact damping: 20.0"))
    assert t[2, 3] == pytest.approx(0.1233527, abs=1e-6)


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_only_ambf_s_bodies_play_the_sensor(tmp_path, engine):
    t, rules = _tip_after(tmp_path, engine, 0.02, bodies="pybullet")
    assert "runner-sensor" in rules  # skipped, and said so
    assert t[2, 3] == pytest.approx(0.12, abs=2e-4)  # fallen onto the block


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_ray_off_the_axis_turns_its_parent_as_in_ambf(tmp_path, engine):
    """-F at the hit point, 15 mm off the COM: a torque (MuJoCo: xfrc_applied about its COM)."""
    t, _ = _tip_after(tmp_path, engine, 0.06, OFF_AXIS)
    tilt = np.degrees(np.arccos(np.clip(t[2, 2], -1.0, 1.0)))
    # AMBF at 60 ms: 34.634° turned, 4.4761 mm along -x (PyBullet the same, MuJoCo 34.636°, 4.4766 mm)
    assert tilt == pytest.approx(34.634, abs=0.005)
    assert t[0, 3] == pytest.approx(-4.4761e-3, abs=1e-6)


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_the_body_hit_is_pushed_back_as_in_ambf(tmp_path, engine):
    """+F on the body hit, at the hit point: AMBF's block at 80 ms 401.8237 mm high (falling freely
    it would be 418.6 mm), 0.0287 mm along +x, turned 1.120°; PyBullet the same, MuJoCo 2.6 µm lower."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    launch = launch_with(tmp_path, {"tip.yaml": PAIR})
    world = open_world(load_scene(launch), Options(visuals=False, bodies="ambf"), engine=engine)
    try:
        block = next(b for b in world.bodies if b.name.endswith("block"))
        world.run(0.08)
        t = block.world_matrix()
    finally:
        world.close()
    assert t[2, 3] == pytest.approx(0.4018237, abs=5e-6)
    assert t[0, 3] == pytest.approx(0.0100287, abs=1e-6)
    assert np.degrees(np.arccos(np.clip(t[2, 2], -1.0, 1.0))) == pytest.approx(1.120, abs=0.005)


@needs_ambf
@pytest.mark.parametrize(
    "engine,seconds,within_m",
    [  # over 0.3 s: thrown, landed (tilted 0.11° by Bullet's contact solver, level in MuJoCo), thrown again
        ("pybullet", 0.3, 0.05e-3),
        ("mujoco", 0.3, 0.3e-3),
    ],
)
def test_the_tip_leaves_the_block_as_in_ambf(tmp_path, capsys, engine, seconds, within_m):
    launch = launch_with(tmp_path, {"tip.yaml": TIP})
    (doc,) = parity(capsys, launch, seconds, engine)
    tip = body(doc, "tip")
    assert tip["max_position_gap_m"] < within_m and tip["max_angle_gap_deg"] < 1.0
    assert not doc["only_in_ambf"]


@needs_ambf
@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_ray_off_the_axis_turns_the_tip_as_in_ambf(tmp_path, capsys, engine):
    launch = launch_with(tmp_path, {"tip.yaml": OFF_AXIS})
    (doc,) = parity(capsys, launch, 0.1, engine)
    tip = body(doc, "tip")
    assert tip["max_position_gap_m"] < 0.01e-3 and tip["max_angle_gap_deg"] < 0.01


@needs_ambf
@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_the_body_hit_moves_as_in_ambf(tmp_path, capsys, engine):
    launch = launch_with(tmp_path, {"tip.yaml": PAIR})
    (doc,) = parity(capsys, launch, 0.2, engine)
    for name in ("tip", "block"):
        row = body(doc, name)
        assert row["max_position_gap_m"] < 0.05e-3 and row["max_angle_gap_deg"] < 0.01, row
