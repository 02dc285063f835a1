"""Render docs/suturing-scene.png: the bundled suturing scene seen by cameraL after psm1 has
picked the needle up (IK from above, grasp through the constraint actuator, lift 2 cm).

    python docs/suturing_scene_png.py
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
from PIL import Image

from adfkit.adf import load_scene
from adfkit.runner import open_world
from adfkit.runner.psm import PSM
from adfkit.scenes.suturing import layout

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    world = open_world(load_scene(ROOT / "sample_scenes" / "suturing" / "launch.yaml", None, []))
    try:
        psm = PSM(world, "psm1")
        needle = world.body("Needle").world_matrix()
        to_base = np.linalg.inv(psm.base_in_world())
        angle = layout.NEEDLE_GRASP_ANGLE
        grasp = to_base @ layout.grasp_ee_pose(needle, angle, layout.shaft_direction("psm1", needle, angle))
        above = grasp.copy()
        above[:3, 3] += to_base[:3, :3] @ np.array([0.0, 0.0, 0.02])
        psm.servo_jaw(0.8)
        psm.move_cp(above, 0.4)
        psm.move_cp(grasp, 0.3)
        world.step(10)
        psm.grasp(True)
        world.step(10)
        psm.move_cp(above, 0.5)
        world.step(50)
        cam = next(c for c in world.cameras if c.name == "cameraL")
        rgb = cam.render(world)["rgb"]
    finally:
        world.close()
    buf = io.BytesIO()
    Image.fromarray(rgb).save(buf, format="PNG", optimize=True)
    out = ROOT / "docs" / "suturing-scene.png"
    out.write_bytes(buf.getvalue())
    print(f"{out}: {len(buf.getvalue()) // 1024} KB")


if __name__ == "__main__":
    main()
