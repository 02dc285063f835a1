"""The floor a model played alone gets (Options.ground, Options.ground_z): real PyBullet and
MuJoCo, no mocks."""

from __future__ import annotations

import pytest

from adfkit.adf import load_scene
from adfkit.runner import Options, open_world

pytest.importorskip("mujoco")

# a box resting 0.5 m up and a body without a shape at the origin (the corpus PSMs' `tool id`)
MODEL = """\
bodies: [BODY box, BODY tag]
BODY box:
  name: box
  collision shape: BOX
  collision geometry: {x: 0.1, y: 0.1, z: 0.1}
  location: {position: {x: 0.0, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  mass: 0.0
BODY tag:
  name: tag
  mesh: ''
  collision mesh: ''
"""


def _ground(tmp_path, engine: str, **kw) -> float | None:
    path = tmp_path / "model.yaml"
    path.write_text(MODEL)
    w = open_world(load_scene(path, None), Options(visuals=False, **kw), engine=engine)
    try:
        return w.ground_z
    finally:
        w.close()


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_the_floor_is_under_the_lowest_body_with_a_shape(tmp_path, engine):
    """1 mm under the box's bottom (0.45 m) in both engines: a body without a collision shape has
    no extent, and PyBullet's bounds of it (its origin, 0) put the floor 0.45 m too low. An
    explicit height is taken as it is (`adfkit parity --engine both` gives every engine the
    first's floor, which AMBF gets too)."""
    assert _ground(tmp_path, engine) == pytest.approx(0.449, abs=1e-6)
    assert _ground(tmp_path, engine, ground_z=0.25) == 0.25
    assert _ground(tmp_path, engine, ground=False) is None
