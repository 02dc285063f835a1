"""A joint MuJoCo closes with a connect equality holds the child's pivot the file gives
(cross_joints.file_anchors), as AMBF's btPoint2PointConstraint does: MuJoCo computes a connect's
second anchor from where the bodies start, so a child placed off its joint stayed that far off
(measured against AMBF, `adfkit parity`, 1 s: a p2p from a free box to a static one whose pivot
is 100 mm away, 100.4 mm open at the end in MuJoCo, 0.36 mm now, AMBF's 0.010 mm)."""

from __future__ import annotations

import pytest

from adfkit.adf import load_scene
from adfkit.runner import Options, open_world

P2P = """bodies: [BODY a, BODY b]
joints: [JOINT j]
BODY a:
  name: a
  mass: 0.2
  collision shape: Box
  collision geometry: {x: 0.05, y: 0.05, z: 0.05}
  location: {position: {x: 0.0, y: 0.0, z: 0.3}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY b:
  name: b
  mass: 0.0
  collision shape: Box
  collision geometry: {x: 0.05, y: 0.05, z: 0.05}
  location: {position: {x: 0.0, y: 0.0, z: 0.3}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
JOINT j:
  name: j
  parent: BODY a
  child: BODY b
  type: p2p
  parent pivot: {x: 0.0, y: 0.0, z: 0.0}
  child pivot: {x: 0.0, y: 0.0, z: 0.1}
  parent axis: {x: 0.0, y: 1.0, z: 0.0}
  child axis: {x: 0.0, y: 1.0, z: 0.0}
"""


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_p2p_pulls_its_body_onto_the_childs_pivot(tmp_path, engine):
    """The free box's pivot (its centre) is pulled 0.1 m up onto the static box's, where the file
    puts it, and hangs there."""
    pytest.importorskip(engine)
    (tmp_path / "m.yaml").write_text(P2P)
    opt = Options(visuals=False, ground=False, bodies="ambf")
    world = open_world(load_scene(tmp_path / "m.yaml", None, []), opt, engine=engine)
    try:
        world.run(1.0)
        z = float(world.body("BODY a").world_matrix()[2, 3])
        err = world.constraint_error()
    finally:
        world.close()
    assert z == pytest.approx(0.4, abs=1e-3)
    assert err < 1e-3
