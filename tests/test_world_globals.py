"""Bullet's contact breaking threshold is one value for the whole process (gContactBreakingThreshold),
not one per PyBullet client: a world plays with its own (runner/pybullet/bullet_globals.py) whatever
another world in the process set, made before it or stepped between its steps. Real PyBullet."""

from __future__ import annotations

import pytest

pb = pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402

# a tilted box dropped on a static slab: where it comes to rest depends on the contact threshold
SCENE = """
bodies: [BODY slab, BODY box]
BODY slab:
  name: slab
  mass: 0.0
  location: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 1.0, y: 1.0, z: 0.1}
BODY box:
  name: box
  mass: 1.0
  inertia: {ix: 1.0e-3, iy: 1.0e-3, iz: 1.0e-3}
  location: {position: {x: 0.0, y: 0.0, z: 0.3}, orientation: {r: 0.3, p: 0.2, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 0.1, y: 0.1, z: 0.1}
"""
STEPS = 100


@pytest.fixture
def scene(tmp_path):
    path = tmp_path / "drop.yaml"
    path.write_text(SCENE)
    return load_scene(path)


def _world(scene, threshold=None):
    return open_world(scene, Options(visuals=False, ground=False, contact_threshold=threshold))


def _drop(world, between=None) -> list:
    """The box's state after each control step (``between``: called after each)."""
    out = []
    for _ in range(STEPS):
        world.step(1)
        out.append(world.body("box").state())
        if between is not None:
            between()
    return out


def test_a_world_plays_with_its_own_contact_threshold_after_another_set_its_own(scene):
    alone = _world(scene)
    try:
        first = _drop(alone)
    finally:
        alone.close()
    fine = _world(scene, 0.001)  # sets Bullet's threshold for the process as it is made
    try:
        millimetre = _drop(fine)
        again = _world(scene)
        try:
            second = _drop(again, between=lambda: fine.step(1))  # the 1 mm world steps in between
        finally:
            again.close()
    finally:
        fine.close()
    assert second == first
    # control: the threshold moves the box here (1.1 mm when a default world played with 1 mm)
    assert max(abs(a - b) for a, b in zip(first[-1][0], millimetre[-1][0])) > 1e-4
