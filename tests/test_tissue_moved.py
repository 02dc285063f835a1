"""adfkit/tasks/tissue_moved.py: the tissue bodies that moved or turned during a suture, read from
the engine's poses (the slow phantom "free on a table" in test_suture_phantom.py plays one)."""

from __future__ import annotations

import pytest

from adfkit.adf import load_scene
from adfkit.runner import Options, open_world
from adfkit.tasks.tissue_moved import TissueStart, said

SCENE = """bodies: [BODY slab, BODY block, BODY bob]
joints: [JOINT slab-bob]
BODY slab:
  name: slab
  mass: 0.0
  inertia: {ix: 1.0, iy: 1.0, iz: 1.0}  # AMBF holds a joint on a static body with no collision shape only with one
  shape: Box
  geometry: {x: 0.2, y: 0.2, z: 0.02}
  location:
    position: {x: 0.0, y: 0.0, z: 0.1}
    orientation: {r: 0.0, p: 0.0, y: 0.0}
BODY block:
  name: block
  mass: 0.3
  shape: Box
  geometry: {x: 0.05, y: 0.05, z: 0.02}
  location:
    position: {x: 0.0, y: 0.0, z: 0.5}
    orientation: {r: 0.0, p: 0.0, y: 0.0}
BODY bob:
  name: bob
  mass: 0.2
  shape: Sphere
  geometry: {radius: 0.01}
  location:
    position: {x: 0.3, y: 0.0, z: 0.1}
    orientation: {r: 0.0, p: 0.0, y: 0.0}
JOINT slab-bob:
  name: slab-bob
  parent: BODY slab
  child: BODY bob
  type: revolute
  parent pivot: {x: 0.2, y: 0.0, z: 0.0}
  child pivot: {x: -0.1, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 1.0, z: 0.0}
  child axis: {x: 0.0, y: 1.0, z: 0.0}
"""


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_falling_tissue_body_is_named_free_a_swinging_one_held_and_a_static_one_not(tmp_path, engine):
    path = tmp_path / "tissue.yaml"
    path.write_text(SCENE)
    w = open_world(load_scene(path), Options(visuals=False, ground=False), engine=engine)
    try:
        start = TissueStart([w.body("slab"), w.body("block"), w.body("bob")])
        assert start.moved() == []  # nothing stepped yet
        w.step(int(round(0.2 / (w.dt * w.opt.control_substeps))))
        moved = start.moved()
    finally:
        w.close()
    # free fall for 0.2 s: g t² / 2 = 196 mm, straight down, not turned; the bob swings on its
    # hinge (a hole body on a spring moves so): listed, not free
    assert [(d["body"], d["free"]) for d in moved] == [("block", True), ("bob", False)]
    assert moved[0]["moved_m"] == pytest.approx(0.196, abs=0.005) and moved[0]["turned_deg"] < 0.1


def test_said_names_the_farthest_three_and_counts_the_rest():
    moved = [{"body": f"b{i}", "moved_m": 0.01 - i * 0.001, "turned_deg": float(i), "free": True} for i in range(5)]
    assert said(moved) == "b0 10.0 mm, 0.0°; b1 9.0 mm, 1.0°; b2 8.0 mm, 2.0°; and 2 more"
    assert said(moved[:1]) == "b0 10.0 mm, 0.0°"
