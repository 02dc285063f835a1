"""Bytes a recorded camera frame takes on disk (RGB, depth, labels, colourised labels), against
the goal of 0.5 MB, on the bundled suturing scene at its cameras' own size.

    .venv/bin/python bench/dataset_size.py [FRAMES]

Asserts nothing; prints figures.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def main() -> int:
    frames = int(sys.argv[1]) if len(sys.argv) > 1 else 10
    from adfkit.adf import load_scene
    from adfkit.dataset import load
    from adfkit.dataset.writer import DatasetWriter
    from adfkit.runner import open_world
    from adfkit.runner.options import Options

    world = open_world(load_scene(ROOT / "sample_scenes" / "suturing" / "launch.yaml"), Options(renderer="auto"))
    with tempfile.TemporaryDirectory() as tmp:
        try:
            writer = DatasetWriter(world, Path(tmp) / "ds")
            t = time.perf_counter()
            for k in range(frames):
                world.step(8)
                writer.write(k, {"needle": world.body("Needle").world_matrix(), "psms": {}})
            elapsed = time.perf_counter() - t
            writer.close()
        finally:
            world.close()
        loaded = load(Path(tmp) / "ds")
        kinds = ("rgb", "depth", "seg", "seg_color")
        size = {k: sum((Path(tmp) / "ds" / f.paths[k]).stat().st_size for f in loaded) / len(loaded) for k in kinds}
        cam = world.cameras[0]
        print(
            f"{len(loaded)} camera frames ({len(world.cameras)} cameras, {cam.width}x{cam.height}), "
            f"renderer {world.renderer}, {len(loaded) / elapsed:.1f} camera frames a second written"
        )
        for k in kinds:
            print(f"  {k:10s} {size[k] / 1e3:8.1f} kB")
        total = sum(size.values())
        print(
            f"  {'total':10s} {total / 1e3:8.1f} kB a camera frame   goal <= 500 kB   "
            f"(float32 .npy depth alone was {cam.width * cam.height * 4 / 1e3:.0f} kB)"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
