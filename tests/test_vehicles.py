"""AMBF's vehicles (adf-format.md §11.3): Bullet's raycast vehicle, played by both engines
(runner/vehicles.py). Before, the runner skipped them: a 10 kg chassis on four raycast wheels
fell onto the floor where AMBF's stood on its suspension (`adfkit parity` on a hand-made car:
379 mm apart; now 0.006 mm in PyBullet, 0.013 mm in MuJoCo)."""

from __future__ import annotations

import numpy as np
import pytest
from parity_scene import body, launch_with, parity

from adfkit.cli import main
from adfkit.parity import ambf

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)

G, STIFFNESS, REST, RADIUS, BELOW = 9.81, 20.0, 0.3, 0.15, 0.15
#: where the chassis's COM settles on the floor's top (z 0): each wheel's spring carries a
#: quarter of the weight, k (rest - length) m = m g / 4 (Bullet's suspension force is per kg
#: of chassis), and the COM stands the hard point's depth above the ray's reach
SETTLED_Z = BELOW + RADIUS + REST - G / (4 * STIFFNESS)

FLOOR = """\
bodies: [BODY Floor]
namespace: /ambf/env/
BODY Floor:
  name: Floor
  mass: 0.0
  collision shape: BOX
  collision geometry: {x: 4.0, y: 4.0, z: 0.02}
  location: {position: {x: 0.0, y: 0.0, z: -0.01}, orientation: {r: SLOPE_R, p: SLOPE_P, y: 0.0}}
  friction: {static: 0.8, rolling: 0.01}
"""

PARTS = """\
bodies: [BODY Chassis, BODY Wheel1, BODY Wheel2, BODY Wheel3, BODY Wheel4]
namespace: /ambf/env/
BODY Chassis:
  name: Chassis
  mass: 10.0
  collision shape: BOX
  collision geometry: {x: 1.0, y: 0.6, z: 0.2}
  location: {position: {x: 0.0, y: 0.0, z: 0.8}, orientation: {r: SLOPE_R, p: SLOPE_P, y: 0.0}}
"""
for _i, (_x, _y) in enumerate([(0.4, 0.35), (0.4, -0.35), (-0.4, 0.35), (-0.4, -0.35)], 1):
    # each wheel's body kept clear of the rays (one around a ray carries the chassis on its top:
    # the ray meets the static body before the floor, in AMBF as here)
    PARTS += f"""\
BODY Wheel{_i}:
  name: Wheel{_i}
  mass: 1.0
  collision shape: CYLINDER
  collision geometry: {{radius: {RADIUS}, height: 0.1, axis: y}}
  location: {{position: {{x: {_x}, y: {_y * 4}, z: 0.35}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
"""

CAR = """\
vehicles: [VEHICLE Car]
namespace: /ambf/env/
VEHICLE Car:
  name: Car
  chassis: BODY Chassis
  wheels:
"""
for _i, (_x, _y) in enumerate([(0.4, 0.35), (0.4, -0.35), (-0.4, 0.35), (-0.4, -0.35)], 1):
    CAR += f"""\
  - body: BODY Wheel{_i}
    radius: {RADIUS}
    width: 0.1
    friction: FRICTION
    suspension: {{stiffness: {STIFFNESS}, damping: 2.3, compression: 4.4, rest length: {REST}}}
    roll influence: 0.1
    down direction: {{x: 0.0, y: 0.0, z: -1.0}}
    axel direction: {{x: 0.0, y: -1.0, z: 0.0}}
    offset: {{x: {_x}, y: {_y}, z: -{BELOW}}}
    front: {str(_x > 0).lower()}
"""


def _scene(tmp_path, friction=10.0, slope_r=0.0, slope_p=0.0, same_file=False):
    """A launch file: world and floor, the car's bodies, then its vehicle (its own file, loaded
    after the bodies, as AMBF needs; ``same_file`` puts it in the bodies' file)."""
    parts = PARTS.replace("SLOPE_R", str(slope_r)).replace("SLOPE_P", str(slope_p))
    car = CAR.replace("FRICTION", str(friction))
    models = {"parts.yaml": parts, "car.yaml": car}
    if same_file:
        parts = parts.replace("namespace: /ambf/env/\n", "vehicles: [VEHICLE Car]\nnamespace: /ambf/env/\n", 1)
        models = {"parts.yaml": parts + car.split("namespace: /ambf/env/\n", 1)[1]}
    launch = launch_with(tmp_path, models, "car_launch.yaml")
    (tmp_path / "floor.yaml").write_text(FLOOR.replace("SLOPE_R", str(slope_r)).replace("SLOPE_P", str(slope_p)))
    return launch


def _play(launch, seconds, engine="pybullet"):
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    world = open_world(load_scene(launch), Options(visuals=False), engine=engine)
    try:
        start = {b.name: np.array(b.world_matrix()) for b in world.bodies}
        world.run(seconds)
        end = {b.name: np.array(b.world_matrix()) for b in world.bodies}
        made = len(world.vehicles.vehicles)
        said = [str(d) for d in world.diagnostics]
    finally:
        world.close()
    return start, end, made, said


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_car_stands_on_its_suspension_and_its_wheel_bodies_are_static(tmp_path, engine):
    start, end, made, _ = _play(_scene(tmp_path), 2.0, engine)
    assert made == 1
    assert end["Chassis"][2, 3] == pytest.approx(SETTLED_Z, abs=5e-4)  # 0.4774 m
    for i in range(1, 5):  # AMBF makes each wheel's body static where it stands
        assert np.array_equal(end[f"Wheel{i}"], start[f"Wheel{i}"])


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_the_wheels_grip_sideways_and_roll_forward(tmp_path, engine):
    """On a floor tilted 0.1 rad about the car's forward axis the wheels' side friction holds the
    car; with no grip (friction 0) it slides downhill. Tilted about its sideways axis it rolls
    downhill: a wheel without a brake rolls freely (Bullet's rolling impulse is 0)."""
    sideways = _play(_scene(tmp_path / "a", slope_r=0.1), 1.0, engine)[1]["Chassis"][:3, 3]
    slipping = _play(_scene(tmp_path / "b", friction=0.0, slope_r=0.1), 1.0, engine)[1]["Chassis"][:3, 3]
    rolling = _play(_scene(tmp_path / "c", slope_p=0.1), 1.0, engine)[1]["Chassis"][:3, 3]
    assert abs(sideways[1]) < 0.01  # held: about 3 mm of creep as it lands
    assert slipping[1] < -0.1  # downhill is -y for a roll of +0.1
    assert rolling[0] > 0.1  # downhill is +x for a pitch of +0.1


def test_a_vehicle_in_its_chassis_s_own_file_is_not_made(tmp_path):
    """AMBF finds a vehicle's bodies among the models loaded before its own (adf-format.md §12.2):
    a chassis of the same file is not found, no vehicle is made, and the chassis falls."""
    _start, end, made, said = _play(_scene(tmp_path, same_file=True), 1.0)
    assert made == 0
    assert end["Chassis"][2, 3] < 0.2
    assert any(
        "chassis 'BODY Chassis' is not among the bodies made by the models loaded before this one" in d for d in said
    )


@needs_ambf
@pytest.mark.parametrize("slope", [0.0, 0.1])
def test_a_car_lands_on_its_suspension_as_in_ambf(tmp_path, capsys, slope):
    for doc in parity(capsys, _scene(tmp_path, slope_r=slope), 2.0):
        chassis = body(doc, "Chassis")
        assert chassis["max_position_gap_m"] < 1e-4 and chassis["max_angle_gap_deg"] < 0.01, doc["engine"]


def test_validate_says_a_vehicle_must_follow_its_bodies_file(tmp_path, capsys):
    """`adfkit validate` of the launch: a vehicle in its chassis's own file names bodies AMBF does
    not find (it searches the models loaded before the vehicle's only), with the fix as the hint."""
    launch = _scene(tmp_path, same_file=True)
    capsys.readouterr()
    main(["validate", str(launch)])
    err = capsys.readouterr()
    text = err.out + err.err
    assert (
        "'chassis' of 'VEHICLE Car' is 'BODY Chassis', which names no body in the models loaded before this one" in text
    )
    assert "move the vehicle to a file listed after its bodies' file" in text
    capsys.readouterr()
    main(["validate", str(_scene(tmp_path / "ok"))])
    assert "dangling-reference" not in "".join(capsys.readouterr())


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_wheel_pointing_nowhere_meets_nothing(tmp_path, engine):
    """A `down direction` of zero length: a ray of no length, which meets nothing (MuJoCo's mj_ray
    refused it with a fatal error); the chassis falls onto the floor."""
    launch = _scene(tmp_path)
    car = tmp_path / "car.yaml"
    car.write_text(
        car.read_text().replace("down direction: {x: 0.0, y: 0.0, z: -1.0}", "down direction: {x: 0.0, y: 0.0, z: 0.0}")
    )
    _start, end, made, _said = _play(launch, 1.0, engine)
    assert made == 1 and end["Chassis"][2, 3] < 0.15
