"""Where a multibody's links are and what they collide with, as AMBF places the bodies: real
PyBullet and real MuJoCo, no mocks."""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest

pb = pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402

# a free 4 cm cube with a 20 cm arm hinged about y at its +x face, the arm's pivot at its own end
# (10 cm from its centre), the arm turned 45 degrees down about the hinge
_C = math.sqrt(0.5) * 0.1
ARM = textwrap.dedent(
    f"""\
    bodies: [BODY base, BODY arm]
    joints: [JOINT base-arm]
    BODY base:
      name: base
      mass: 1.0
      inertia: {{ix: 1.0e-3, iy: 1.0e-3, iz: 1.0e-3}}
      location: {{position: {{x: 0.0, y: 0.0, z: 0.0}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
      collision shape: BOX
      collision geometry: {{x: 0.04, y: 0.04, z: 0.04}}
    BODY arm:
      name: arm
      mass: 0.1
      inertia: {{ix: 1.0e-4, iy: 1.0e-4, iz: 1.0e-4}}
      location: {{position: {{x: {0.02 + _C}, y: 0.0, z: {-_C}}}, orientation: {{r: 0.0, p: {math.pi / 4}, y: 0.0}}}}
      collision shape: BOX
      collision geometry: {{x: 0.2, y: 0.02, z: 0.02}}
    JOINT base-arm:
      name: base-arm
      parent: BODY base
      child: BODY arm
      type: revolute
      parent pivot: {{x: 0.02, y: 0.0, z: 0.0}}
      child pivot: {{x: -0.1, y: 0.0, z: 0.0}}
      parent axis: {{x: 0.0, y: 1.0, z: 0.0}}
      child axis: {{x: 0.0, y: 1.0, z: 0.0}}
    """
)


def _centre(world, name: str) -> np.ndarray:
    sb = world.body(name)
    lo, hi = pb.getAABB(sb.uid, sb.link, physicsClientId=world.cid)
    return (np.array(lo) + np.array(hi)) / 2


def test_a_links_shapes_sit_where_the_file_puts_its_body(tmp_path):
    """A link's frame is its joint's frame, 10 cm from the arm's centre here: its box is made in
    that frame and collides where the file puts the arm (the corpus gripper3's jaws collided
    0.1-0.3 m off, inside its base, and the gripper slid 337 mm over the floor and turned over),
    and the floor a model played alone gets is 1 mm under the arm's lowest corner. Control: the
    shapes made in the arm's centre-of-mass frame (Options.link_shapes "com", the tasks' default)
    sit on the hinge instead."""
    path = tmp_path / "arm.yaml"
    path.write_text(ARM)
    low = -_C - (0.1 * math.sqrt(0.5) + 0.01 * math.sqrt(0.5))  # the arm's lowest edge
    for shapes, off in (("body", 0.0), ("com", 0.1)):
        world = open_world(load_scene(path), Options(visuals=False, link_shapes=shapes))
        try:
            arm = world.body("BODY arm")
            assert arm.link >= 0  # a link of the cube's multibody
            gap = float(np.linalg.norm(_centre(world, "BODY arm") - np.array([0.02 + _C, 0.0, -_C])))
            assert gap == pytest.approx(off, abs=2e-3), shapes
            if shapes == "body":
                assert world.ground_z == pytest.approx(low - 1e-3, abs=2e-4)
            else:
                assert world.ground_z > low + 0.02  # the hinged box reaches no lower than the cube
        finally:
            world.close()
