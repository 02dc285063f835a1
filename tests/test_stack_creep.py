"""Five 5 cm boxes stacked on a floor, each 3 mm off the one under it (0, 3, 6 mm in x, again),
played for 2 s with AMBF's bodies: the bottom box stays where it is, as AMBF's does (0.37 mm,
measured with `adfkit parity`). Bullet's solver takes the contacts in the order its broadphase
hands them over, 10 iterations a step; with the pairs sorted (PyBullet's setting) the same order
leaves a sideways push every step, and the stack walked 10.0 mm along the floor in 2 s (17.8 mm
with nine boxes). AMBF's world leaves them unsorted, and so does the runner with AMBF's bodies.
A state saved mid-settle replays with the pairs unsorted as a restored state must."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pybullet")

from adfkit.adf.scene import load_scene  # noqa: E402
from adfkit.runner.engines import open_world  # noqa: E402
from adfkit.runner.options import Options  # noqa: E402

N = 5


def _scene() -> str:
    names = ", ".join(["BODY floor"] + [f"BODY b{i}" for i in range(N)])
    text = f"bodies: [{names}]\nnamespace: /ambf/env/stack/\n"
    text += """BODY floor:
  name: floor
  mass: 0
  collision shape: BOX
  collision geometry: {x: 3.0, y: 3.0, z: 0.1}
  location: {position: {x: 0, y: 0, z: -0.05}, orientation: {r: 0, p: 0, y: 0}}
  friction: {static: 0.5}
"""
    for i in range(N):
        x, z = (0.0, 0.003, 0.006)[i % 3], 0.025 + 0.0501 * i
        text += f"""BODY b{i}:
  name: b{i}
  mass: 0.2
  collision shape: BOX
  collision geometry: {{x: 0.05, y: 0.05, z: 0.05}}
  location: {{position: {{x: {x}, y: 0, z: {z:.4f}}}, orientation: {{r: 0, p: 0, y: 0}}}}
  friction: {{static: 0.5}}
"""
    return text


def _world(tmp_path):
    path = tmp_path / "stack.yaml"
    if not path.exists():
        path.write_text(_scene())
    opt = Options(visuals=False, ground=False, ghosts="ambf", springs="ambf", link_shapes="body", bodies="ambf")
    return open_world(load_scene(path), opt, engine="pybullet")


def _play(world, steps: int) -> np.ndarray:
    """Every box's position after each of ``steps`` control steps."""
    out = []
    for _ in range(steps):
        world.step(1)
        out.append([sb.state()[0] for sb in world.bodies if not sb.static])
    return np.array(out)


def test_bottom_box_of_a_stack_stays_put(tmp_path):
    world = _world(tmp_path)
    try:
        bottom = next(sb for sb in world.bodies if sb.key.endswith("b0"))
        start = np.array(bottom.state()[0])
        world.step(500)  # 2 s at 4 ms control steps
        moved = np.linalg.norm(np.array(bottom.state()[0])[:2] - start[:2])
    finally:
        world.close()
    assert moved < 1e-3, f"the bottom box crept {moved * 1000:.2f} mm along the floor"


def test_a_state_saved_while_the_stack_settles_replays(tmp_path):
    """Saved 0.5 s in (the top box moves 0.48 mm in x over the next second), that second played again after a restore
    in the same world keeps to the first play within 1e-9 m (measured 3.5e-16 m; with the pairs
    sorted, as before, 5.8e-5 m), and two fresh worlds given the snapshot play it bit for bit."""
    world = _world(tmp_path)
    fresh = []
    try:
        world.step(125)
        snap = world.save_state()
        first = _play(world, 250)
        world.restore_state(snap)
        again = _play(world, 250)
        for _ in range(2):
            fresh.append(_world(tmp_path))
            fresh[-1].restore_state(snap)
        a, b = (_play(w, 250) for w in fresh)
    finally:
        for w in [world, *fresh]:
            w.close()
    assert np.abs(first - first[0]).max() > 1e-4  # the boxes move over that second: a motion to replay
    assert np.abs(again - first).max() < 1e-9
    assert np.array_equal(a, b)
