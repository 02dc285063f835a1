"""Proximity sensors given a `parametric` fan of rays (adf-format.md §11.1), as AMBF's loader
makes them: AMBF creates such a sensor and the runner skipped it (`adfkit parity` said
"only in AMBF: sensor ..." of a hand-made model)."""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

from adfkit.cli import main
from adfkit.model.pose import Pose
from adfkit.parity import ambf
from adfkit.runner.plan import parametric_rays

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)


def _sensor(resolution=3, h=math.pi / 2, v=0.4, off=0.01, rng=0.5, location=None):
    p = SimpleNamespace(resolution=resolution, horizontal_angle=h, vertical_angle=v, start_offset=off)
    return SimpleNamespace(parametric=p, range=rng, location=location)


def test_a_parametric_fan_turns_about_z_then_y_from_plus_x():
    starts, ends = parametric_rays(_sensor())
    assert starts.shape == ends.shape == (9, 3)
    dirs = (ends - starts) / 0.5
    # ray n·i + j: h_i = -pi/4, 0, pi/4; v_j = -0.2, 0, 0.2 (AMBF's afMatrix3d(0, v, h) = Rz(h)·Ry(v))
    assert dirs[4] == pytest.approx([1.0, 0.0, 0.0])
    assert dirs[7] == pytest.approx([math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0])
    assert dirs[5] == pytest.approx([math.cos(0.2), 0.0, -math.sin(0.2)])
    assert starts[1] == pytest.approx(0.01 * dirs[1])
    assert np.linalg.norm(dirs, axis=1) == pytest.approx(np.ones(9))


def test_a_parametric_fan_carries_the_sensors_location_as_ambf_does():
    """AMBF's loader puts the fan through the sensor's `location`, and the sensor is placed at
    that location again: the rays come back in the location's frame."""
    loc = Pose(position=(0.1, 0.0, 0.0), orientation=(0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)))
    starts, ends = parametric_rays(_sensor(location=loc))
    plain_starts, plain_ends = parametric_rays(_sensor())
    assert starts[4] == pytest.approx([0.1, 0.01, 0.0])  # +x turned to +y, moved 0.1 along x
    assert (ends - starts)[4] == pytest.approx([0.0, 0.5, 0.0])
    assert not np.allclose(starts, plain_starts)


def test_a_parametric_fan_ambf_refuses_is_not_made():
    assert parametric_rays(_sensor(resolution=1)) is None
    s = _sensor()
    s.parametric.start_offset = None
    assert parametric_rays(s) is None


FAN = """\
bodies: [BODY eye, BODY side, BODY behind]
sensors: [SENSOR fan]
namespace: /ambf/env/fan/
BODY eye:
  name: eye
  mass: 0.0
  collision shape: SPHERE
  collision geometry: {radius: 0.005}
  location: {position: {x: 0.0, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY side:
  name: side
  mass: 0.0
  collision shape: BOX
  collision geometry: {x: 0.04, y: 0.04, z: 0.04}
  location: {position: {x: 0.1, y: 0.1, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY behind:
  name: behind
  mass: 0.0
  collision shape: BOX
  collision geometry: {x: 0.04, y: 0.04, z: 0.04}
  location: {position: {x: -0.1, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
SENSOR fan:
  name: fan
  type: Proximity
  parent: BODY eye
  range: 0.3
  parametric: {resolution: 3, horizontal angle: 1.5707963, vertical angle: 0.2, start offset: 0.01}
"""


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_parametric_sensor_is_made_and_sees_along_its_fan(tmp_path, engine):
    """The fan's +45° rays meet the box at 45° to the side; nothing looks behind. Control: the
    same fan 0.2 rad wide sees straight ahead only, and misses it."""
    from adfkit.adf import load_scene
    from adfkit.parity.traces import made_by
    from adfkit.runner import Options, open_world

    for width, seen in (("1.5707963", ["side"]), ("0.2", [])):
        path = tmp_path / f"fan{width}.yaml"
        path.write_text(FAN.replace("horizontal angle: 1.5707963", f"horizontal angle: {width}"))
        world = open_world(load_scene(path), Options(visuals=False, gravity=(0, 0, 0)), engine=engine)
        try:
            assert made_by(world)["sensor"] == ["/ambf/env/fan/fan"]
            world.step(1)
            assert [b.name for b in world.sensors[0].sensed] == seen
        finally:
            world.close()


@needs_ambf
def test_ambf_and_adfkit_both_make_a_parametric_sensor(tmp_path, capsys):
    path = tmp_path / "fan.yaml"
    path.write_text(FAN)
    main(["parity", str(path), "--seconds", "0.1", "--engine", "both", "--json"])
    docs = json.loads(capsys.readouterr().out)
    for doc in docs:
        assert doc["only_in_ambf"] == doc["only_in_adfkit"] == [], doc
