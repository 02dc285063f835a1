"""Five 5 cm boxes stacked on a floor, each 3 mm off the one under it (0, 3, 6 mm in x, again),
played for 2 s with AMBF's bodies: the bottom box stays where it is, as AMBF's does (0.37 mm,
measured with `adfkit parity`). Bullet's solver takes the contacts in the order its broadphase
hands them over, 10 iterations a step; with the pairs sorted (PyBullet's setting) the same order
leaves a sideways push every step, and the stack walked 10.0 mm along the floor in 2 s (17.8 mm
with nine boxes). AMBF's world leaves them unsorted, and so does the runner with AMBF's bodies."""

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


def test_bottom_box_of_a_stack_stays_put(tmp_path):
    path = tmp_path / "stack.yaml"
    path.write_text(_scene())
    opt = Options(visuals=False, ground=False, ghosts="ambf", springs="ambf", link_shapes="body", bodies="ambf")
    world = open_world(load_scene(path), opt, engine="pybullet")
    try:
        bottom = next(sb for sb in world.bodies if sb.key.endswith("b0"))
        start = np.array(bottom.state()[0])
        world.step(500)  # 2 s at 4 ms control steps
        moved = np.linalg.norm(np.array(bottom.state()[0])[:2] - start[:2])
    finally:
        world.close()
    assert moved < 1e-3, f"the bottom box crept {moved * 1000:.2f} mm along the floor"
