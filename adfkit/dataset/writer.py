"""Writes the dataset of a played scene. Layout (DIR is the dataset folder):

    DIR/labels.json                 {"0": "body key", ...}: segmentation label k+1 is body k
    DIR/cameras.json                {camera: {"width", "height", "K" 3x3, "near", "far"}}
    DIR/index.jsonl                 one JSON line per frame (below)
    DIR/<camera>/<step>_rgb.png     RGB, 8 bit
    DIR/<camera>/<step>_depth.png   uint16 H×W, depth along the optical axis in 0.1 mm (0: nothing),
                                    lossless at that quantum; a frame with depths beyond 6.5534 m is
                                    <step>_depth.npz instead (float32 metres, inf: nothing, deflated)
    DIR/<camera>/<step>_seg.png     uint16 labels: 0 nothing, k+1 body k of labels.json
    DIR/<camera>/<step>_seg_color.png  the labels colourised for a person

A frame line: {"step", "time_s", "camera", "rgb", "depth", "seg", "seg_color" (paths relative to
DIR), "K" (3x3 pinhole intrinsics, pixels), "T_world_camera" (4x4, OpenCV camera frame: x right,
y down, z forward), "needle" (4x4 world pose of the needle body), "psms" ({name: {"T_world_ee"
4x4, "jp" [q1..q6], "jaw" rad}}), "phase"}.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .colors import colourise


def camera_to_world(eye, target, up) -> np.ndarray:
    """4x4 pose of an OpenCV camera (x right, y down, z forward) at eye looking at target."""
    eye, target, up = (np.asarray(v, dtype=float) for v in (eye, target, up))
    z = target - eye
    z /= np.linalg.norm(z)
    x = np.cross(z, up)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    t = np.eye(4)
    t[:3, :3] = np.c_[x, y, z]
    t[:3, 3] = eye
    return t


#: Depth PNGs count in this unit (0.1 mm): 16 bits reach 6.5534 m, 0 is "nothing".
DEPTH_UNIT_M = 1e-4


def depth_to_png16(depth: np.ndarray) -> np.ndarray | None:
    """Depth in metres (inf or NaN where nothing) as uint16 counts of DEPTH_UNIT_M, 0 where
    nothing; a hit nearer than half a unit still counts 1. None when a finite depth is beyond
    what 16 bits hold (the caller keeps float32 then)."""
    hit = np.isfinite(depth)
    counts = np.rint(np.where(hit, depth, 0.0) / DEPTH_UNIT_M)
    if hit.any() and (counts[hit].max() > 65535 or depth[hit].min() < 0):
        return None
    return np.where(hit, np.maximum(counts, 1), 0).astype(np.uint16)


class DatasetWriter:
    def __init__(self, world, root, cameras=None) -> None:
        self.world, self.root = world, Path(root)
        self.root.mkdir(parents=True, exist_ok=True)
        self.cameras = [c for c in world.cameras if cameras is None or c.name in cameras]
        keys = [sb.key for sb in world.bodies]
        keys += [s.key for s in getattr(getattr(world, "soft", None), "items", []) or []]  # after the bodies
        (self.root / "labels.json").write_text(json.dumps({str(i): k for i, k in enumerate(keys)}, indent=1))
        (self.root / "cameras.json").write_text(
            json.dumps(
                {
                    c.name: {
                        "width": c.width,
                        "height": c.height,
                        "K": c.intrinsics().tolist(),
                        "near": c.near,
                        "far": c.far,
                    }
                    for c in self.cameras
                },
                indent=1,
            )
        )
        self.index = open(self.root / "index.jsonl", "w", encoding="utf-8")
        self.frames = 0

    def write(self, step: int, poses: dict, phase: str = "") -> list:
        """Render every camera now and write its frame; ``poses``: {"needle": 4x4, "psms": {...}}."""
        from PIL import Image

        lines = []
        for cam in self.cameras:
            frame = cam.render(self.world)
            d = self.root / cam.name
            d.mkdir(exist_ok=True)
            stem = f"{step:07d}"
            depth = np.asarray(frame["depth"], dtype=np.float32)
            quantised = depth_to_png16(depth)
            names = {
                k: f"{cam.name}/{stem}_{k}{ext}"
                for k, ext in (
                    ("rgb", ".png"),
                    ("depth", ".png" if quantised is not None else ".npz"),
                    ("seg", ".png"),
                    ("seg_color", ".png"),
                )
            }
            Image.fromarray(frame["rgb"]).save(self.root / names["rgb"])
            if quantised is not None:
                Image.fromarray(quantised).save(self.root / names["depth"])
            else:
                np.savez_compressed(self.root / names["depth"], depth=depth)
            seg = frame["segmentation"]
            Image.fromarray((seg.astype(np.int64) + 1).clip(0, 65535).astype(np.uint16)).save(self.root / names["seg"])
            Image.fromarray(colourise(seg)).save(self.root / names["seg_color"])
            line = {
                "step": step,
                "time_s": self.world.sim_time,
                "camera": cam.name,
                **names,
                "K": cam.intrinsics().tolist(),
                "T_world_camera": camera_to_world(*cam.view(self.world)).tolist(),
                "needle": np.asarray(poses.get("needle")).tolist() if poses.get("needle") is not None else None,
                "psms": poses.get("psms", {}),
                "phase": phase,
            }
            self.index.write(json.dumps(line, allow_nan=False) + "\n")
            lines.append(line)
            self.frames += 1
        self.index.flush()
        return lines

    def close(self) -> None:
        self.index.close()
