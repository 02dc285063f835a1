"""Reads a dataset written by writer.py: ``load(DIR)`` -> frames in order."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass
class Frame:
    root: Path
    step: int
    time_s: float
    camera: str
    paths: dict
    K: np.ndarray
    T_world_camera: np.ndarray
    needle: np.ndarray | None
    psms: dict
    phase: str

    def rgb(self) -> np.ndarray:
        from PIL import Image

        return np.asarray(Image.open(self.root / self.paths["rgb"]).convert("RGB"))

    def depth(self) -> np.ndarray:
        """float32 H×W metres along the optical axis, inf where nothing (whichever way the frame
        stored it: 16-bit PNG in 0.1 mm, deflated npz, or the float32 npy of older datasets)."""
        path = self.root / self.paths["depth"]
        if path.suffix == ".png":
            from PIL import Image

            from .writer import DEPTH_UNIT_M

            counts = np.asarray(Image.open(path)).astype(np.float64)
            return np.where(counts > 0, counts * DEPTH_UNIT_M, np.inf).astype(np.float32)
        if path.suffix == ".npz":
            with np.load(path) as data:
                return data["depth"]
        return np.load(path)

    def labels(self) -> np.ndarray:
        """int32 H×W: body index of labels.json, -1 nothing."""
        from PIL import Image

        return np.asarray(Image.open(self.root / self.paths["seg"])).astype(np.int32) - 1

    def seg_color(self) -> np.ndarray:
        from PIL import Image

        return np.asarray(Image.open(self.root / self.paths["seg_color"]).convert("RGB"))


def load(root) -> list[Frame]:
    root = Path(root)
    index = root / "index.jsonl"
    if not index.is_file():
        raise FileNotFoundError(f"{index} does not exist: not a dataset folder")
    out = []
    for _n, line in enumerate(index.read_text(encoding="utf-8").splitlines(), 1):
        if not line.strip():
            continue
        d = json.loads(line)
        out.append(
            Frame(
                root,
                d["step"],
                d["time_s"],
                d["camera"],
                {k: d[k] for k in ("rgb", "depth", "seg", "seg_color")},
                np.array(d["K"]),
                np.array(d["T_world_camera"]),
                np.array(d["needle"]) if d.get("needle") is not None else None,
                d.get("psms", {}),
                d.get("phase", ""),
            )
        )
    return out


def labels(root) -> dict[int, str]:
    return {int(k): v for k, v in json.loads((Path(root) / "labels.json").read_text()).items()}
