"""Soft bodies in the PyBullet runner: real-time factor of the corpus cloth alone (hanging
from its pinned corner), the cloth draped over a box, and the soft phantom with the needle and with the probe;
node counts, and the phantom's indentation. Prints figures, asserts nothing."""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT.parent / "shared" / "corpus"
CLOTH = CORPUS / "ambf/ambf_models/descriptions/multi-bodies/sb/cloth.yaml"
BOX = """bodies: [BODY table]
BODY table:
  name: table
  mass: 0.0
  location: {position: {x: 0.0, y: 2.0, z: -0.35}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 0.4, y: 0.4, z: 0.5}
"""


def play(path: Path, seconds: float, ground: bool = True):
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    t0 = time.perf_counter()
    world = open_world(load_scene(path, None, []), Options(visuals=False, ground=ground))
    build = time.perf_counter() - t0
    world.run(seconds)
    rep = world.report()
    nodes = world.soft.items[0].nodes(world.cid)
    world.close()
    return rep, build, nodes


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=2.0)
    args = ap.parse_args()
    from adfkit.scenes.soft_phantom import SoftPhantomParams, write_soft_phantom

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        if CLOTH.is_file():
            rows.append(("corpus cloth, hanging (no floor)", *play(CLOTH, args.seconds, ground=False)))
            (tmp / "box.yaml").write_text(BOX)
            (tmp / "launch.yaml").write_text(f"multibody configs:\n  - {CLOTH}\n  - box.yaml\n")
            rows.append(("corpus cloth draped on a box", *play(tmp / "launch.yaml", args.seconds)))
        else:
            print(f"corpus not found at {CORPUS}: cloth figures skipped", file=sys.stderr)
        tools = {}
        for tool in ("needle", "sphere"):
            p = SoftPhantomParams(tool=tool)
            rows.append((f"soft phantom, {tool}", *play(write_soft_phantom(tmp / tool, p), args.seconds)))
            tools[tool] = rows[-1][3]
        alone = play(write_soft_phantom(tmp / "alone", SoftPhantomParams(with_probe=False)), args.seconds)[2]
    for label, rep, build, _nodes in rows:
        sb = rep["soft_bodies"][0]
        print(
            f"{label:36s} {sb['nodes']:4d} nodes  build {build:5.2f} s  "
            f"{rep['simulated_time_s']:.1f} s in {rep['wall_time_s']:6.2f} s = {rep['real_time_factor']:.2f}x real time"
        )
    h = SoftPhantomParams().height
    sag = h - alone[np.linalg.norm(alone[:, :2], axis=1) < 0.006, 2].min()
    for tool, nodes in tools.items():
        under = np.linalg.norm(nodes[:, :2], axis=1) < (0.015 if tool == "needle" else 0.006)
        depth = h - nodes[under, 2].min()
        print(
            f"phantom, {tool}: skin {depth * 1000:.1f} mm below rest, {sag * 1000:.1f} mm of it its own sag: "
            f"indentation {(depth - sag) * 1000:.1f} mm"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
