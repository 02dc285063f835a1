"""Render docs/drilling-skull.png: the skull scene (`adfkit build-scene skull`, 192 voxels a
side) drilled with a 4 mm burr (the drill's mesh tip, --burr-radius 0.002) down onto the
mastoid and back and forth over it in three layers, opening the air cells under the cortex. Left: the drilled volume and the
drill where the path ends, seen by main_camera (MuJoCo's renderer); right: the last frame of
drilling.gif (top view; section through the burr, tissues by colour, removed voxels dark).

    python docs/drilling_skull_png.py
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

from adfkit.adf import load_scene
from adfkit.cli import main as adfkit
from adfkit.runner import open_world
from adfkit.runner.options import Options
from adfkit.scenes.skull import SkullParams, write_skull

ROOT = Path(__file__).resolve().parents[1]


def raster() -> str:
    """Down onto the mastoid, then back and forth over it in three layers (the last one opens
    the air cells under the cortex), as a mastoidectomy saucerises the bone."""
    pts = [(0.004, 0.002, 0.024)]
    for z in (0.0145, 0.0120, 0.0100):
        for k, y in enumerate(np.arange(-0.004, 0.0041, 0.002)):
            xs = (-0.005, 0.006) if k % 2 == 0 else (0.006, -0.005)
            pts += [(xs[0], y, z), (xs[1], y, z)]
    return "".join(f"{x:.4f} {y:.4f} {z:.4f}\n" for x, y, z in pts)


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        launch = write_skull(tmp, SkullParams(voxels=192))
        (tmp / "path.txt").write_text(raster())
        out = tmp / "out"
        args = ["drill", str(launch), "--path", str(tmp / "path.txt"), "--burr-radius", "0.002", "--out", str(out)]
        assert adfkit([*args, "--frames", "20", "--speed", "0.01", "--removal-rate", "150"]) in (0, 1)
        end = np.array(json.loads((out / "metrics.json").read_text())["final_burr_m"])
        # the drill where the path ends: the 2 mm burr's centre there, 1 mm up the shaft from the
        # mesh's 1 mm tip ball at the body's origin (the shaft along x, pitched -1.2 rad)
        axis = np.array([np.cos(1.2), 0.0, np.sin(1.2)])
        x, y, z = end - 0.001 * axis
        drills = (tmp / "ADF" / "drills.yaml").read_text()
        start = drills.split("position: {", 1)[1].split("}", 1)[0]
        drills = drills.replace(start, f"x: {x:.6f}, y: {y:.6f}, z: {z:.6f}")
        (tmp / "ADF" / "drills_end.yaml").write_text(drills)
        volume = (out / "volume.yaml").read_text().replace("path: slices/", f"path: {out / 'slices'}/")
        (tmp / "ADF" / "drilled.yaml").write_text(volume)
        (tmp / "picture.yaml").write_text(
            launch.read_text().split("multibody configs:")[0]
            + "multibody configs:\n- ADF/drills_end.yaml\n- ADF/drilled.yaml\n"
        )
        world_file = tmp / "ADF" / "world.yaml"  # main_camera nearer, for the picture
        world_file.write_text(
            world_file.read_text().replace("{x: 0.09, y: -0.06, z: 0.08}", "{x: 0.054, y: -0.036, z: 0.052}")
        )
        world = open_world(load_scene(tmp / "picture.yaml"), Options(), engine="mujoco")
        try:
            cam = next(c for c in world.cameras if c.name == "main_camera")
            rgb = world.render_camera(cam, True)["rgb"]
        finally:
            world.close()
        gif = Image.open(out / "drilling.gif")
        gif.seek(gif.n_frames - 1)
        right = gif.convert("RGB")
        right = right.resize((right.width * 480 // right.height, 480), Image.NEAREST)
        left = Image.fromarray(rgb[:, 40:600])
        pic = Image.new("RGB", (left.width + 8 + right.width, 480), (255, 255, 255))
        pic.paste(left, (0, 0))
        pic.paste(right, (left.width + 8, 0))
        pic.save(ROOT / "docs" / "drilling-skull.png", optimize=True)


if __name__ == "__main__":
    main()
