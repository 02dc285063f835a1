"""A `fixed` joint between two maximal-coordinate bodies keeps the relative pose the file
gives them, whatever their inertial frames (PyBullet's own fixed constraint does not: it holds
the two inertial frames parallel, which turned the suturing thread 90 degrees off its needle)."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import open_world  # noqa: E402

MODEL = """
bodies: [BODY a, BODY b]
joints: [JOINT a-b]
gravity: {x: 0.0, y: 0.0, z: 0.0}
BODY a:
  name: a
  mass: 0.5
  inertia: {ix: 1.0e-4, iy: 2.0e-4, iz: 3.0e-4}
  inertial offset: {position: {x: 0.01, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 1.2}}
  location: {position: {x: 0.0, y: 0.0, z: 1.0}, orientation: {r: 0.3, p: 0.0, y: 0.0}}
  collision shape: SPHERE
  collision geometry: {radius: 0.01}
BODY b:
  name: b
  mass: 0.03
  inertia: {ix: 1.0e-6, iy: 1.0e-6, iz: 2.0e-6}
  inertial offset: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  location: {position: {x: -0.01, y: 0.0, z: 1.0}, orientation: {r: 0.3, p: 0.0, y: 0.0}}
  collision shape: SPHERE
  collision geometry: {radius: 0.002}
JOINT a-b:
  name: a-b
  parent: BODY a
  child: BODY b
  parent pivot: {x: -0.01, y: 0.0, z: 0.0}
  child pivot: {x: 0.0, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 0.0, z: 1.0}
  child axis: {x: 0.0, y: 0.0, z: 1.0}
  type: fixed
"""


def test_fixed_joint_keeps_the_relative_pose(tmp_path):
    p = tmp_path / "model.yaml"
    p.write_text(textwrap.dedent(MODEL))
    world = open_world(load_scene(p, None, []))
    try:
        a, b = world.body("BODY a"), world.body("BODY b")
        rel0 = np.linalg.inv(a.world_matrix()) @ b.world_matrix()  # the file's pose: the joint's own
        b.force([0.0, 0.05, 0.0], list(b.com_position()))  # a jolt on the light body
        world.run(0.5)
        rel = np.linalg.inv(a.world_matrix()) @ b.world_matrix()
        turn = np.degrees(np.arccos(np.clip((np.trace(rel0[:3, :3].T @ rel[:3, :3]) - 1) / 2, -1, 1)))
        assert turn < 1.0, turn
        assert np.linalg.norm(rel[:3, 3] - rel0[:3, 3]) < 1e-4
    finally:
        world.close()
