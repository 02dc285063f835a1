"""Joints between bodies of different model files (adf-format.md §12.2: a joint's ends are looked
up in its own model, then in every body loaded before it). AMBF and the PyBullet runner make them;
the MuJoCo engine closes each as a loop is closed (cross_joints.py). Measured against AMBF (adfkit
parity, 1 s): a body hung from another model's post by a p2p joint 0.36 mm from AMBF's in MuJoCo,
where it fell (300 mm) and parity said "only in AMBF: joint cross"."""

from __future__ import annotations

import numpy as np
import pytest

from adfkit.adf import load_scene
from adfkit.parity.traces import made_by
from adfkit.runner import Options, open_world

POST = """\
bodies: [BODY post]
namespace: /ambf/env/shared/
BODY post:
  name: post
  mass: 0.0
  collision shape: BOX
  collision geometry: {x: 0.05, y: 0.05, z: 0.05}
  location: {position: {x: 0.0, y: 0.0, z: 0.4}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
"""

HUNG = """\
bodies: [BODY weight, BODY plate]
joints: [JOINT cross, JOINT welded]
namespace: /ambf/env/shared/
BODY weight:
  name: weight
  mass: 0.2
  collision shape: BOX
  collision geometry: {x: 0.04, y: 0.04, z: 0.04}
  location: {position: {x: 0.0, y: -0.3, z: 0.35}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY plate:
  name: plate
  mass: 0.1
  collision shape: BOX
  collision geometry: {x: 0.04, y: 0.04, z: 0.01}
  location: {position: {x: 0.2, y: 0.0, z: 0.4}, orientation: {r: 0.0, p: 0.0, y: 0.3}}
JOINT cross:
  name: cross
  parent: BODY post
  child: BODY weight
  type: p2p
  parent pivot: {x: 0.0, y: -0.3, z: 0.0}
  child pivot: {x: 0.0, y: 0.0, z: 0.05}
  parent axis: {x: 0.0, y: 0.0, z: 1.0}
  child axis: {x: 0.0, y: 0.0, z: 1.0}
JOINT welded:
  name: welded
  parent: BODY post
  child: BODY plate
  type: fixed
  parent pivot: {x: 0.2, y: 0.0, z: 0.0}
  child pivot: {x: 0.0, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 0.0, z: 1.0}
  child axis: {x: 0.0, y: 0.0, z: 1.0}
  offset: 0.3
"""


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_model_hangs_its_bodies_on_another_models_post(tmp_path, engine):
    (tmp_path / "post.yaml").write_text(POST)
    (tmp_path / "hung.yaml").write_text(HUNG)
    (tmp_path / "launch.yaml").write_text("multibody configs:\n- post.yaml\n- hung.yaml\n")
    world = open_world(load_scene(tmp_path / "launch.yaml"), Options(visuals=False, ground=False), engine=engine)
    try:
        assert made_by(world)["joint"] == ["/ambf/env/shared/cross", "/ambf/env/shared/welded"]
        start = {n: world.body(n).world_matrix() for n in ("weight", "plate")}
        world.run(0.5)
        weight, plate = world.body("weight").world_matrix(), world.body("plate").world_matrix()
    finally:
        world.close()
    # the weight hangs 5 cm under its pivot (0.4 - 0.05 m), the plate stays welded where it was
    assert np.linalg.norm(weight[:3, 3] - start["weight"][:3, 3]) < 2e-3
    assert np.linalg.norm(plate[:3, 3] - start["plate"][:3, 3]) < 1e-3
    assert np.allclose(plate[:3, :3], start["plate"][:3, :3], atol=2e-3)
