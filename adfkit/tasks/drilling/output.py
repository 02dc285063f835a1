"""What `adfkit drill` writes, every file atomically (beside its target, then renamed):

- ``slices/<prefix><i>.png``: the drilled volume: the input slices with every removed voxel
  set to 0 (grey, 16-bit and RGBA slices keep their kind and colours), written as a whole
  folder that replaces any earlier one only once complete;
- ``volume.yaml``: an ADF model file holding the volume, pointing at those slices, so the
  result validates and plays like the input;
- ``surface.stl``: the iso-surface at the end (the blocks re-meshed as they were drilled);
- ``metrics.json`` and ``drilling.gif`` (a top view and a section through the burr per frame).
"""

from __future__ import annotations

import io
import json
import os
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np

from ...adf import atomic_write_bytes, atomic_write_text, write_file
from ...model import ModelFile
from ...model.objects import VolumeImages
from ...scratch import temp_dir_beside

PALETTE = [
    (236, 226, 198),  # first tissue (bone)
    (120, 170, 230),
    (120, 200, 120),
    (200, 140, 220),
    (230, 180, 90),
]
PROTECTED = (230, 60, 60)
REMOVED = (70, 35, 35)
BURR = (255, 200, 40)


def write_slices(sources: list[Path], removed: np.ndarray, folder: Path, prefix: str) -> list[Path]:
    """The input slices ``sources`` with the voxels ``removed`` ((slices, rows, columns) bool,
    row 0 the picture's bottom row, as geometry.volume reads them) set to 0 in every channel, as
    AMBF's drilling empties a voxel, as PNG slices ``<prefix><i>.png`` (i from 0) into
    ``folder``, all or nothing: grey, 16-bit and RGBA slices keep their kind and colours."""
    from PIL import Image

    folder = Path(folder)
    folder.parent.mkdir(parents=True, exist_ok=True)
    tmp = temp_dir_beside(folder)  # .<name>.<pid>.*: a later write removes it if this one is killed
    try:
        files = []
        for i, src in enumerate(sources):
            with Image.open(src) as img:
                img.load()
                if img.mode == "P" or (img.mode not in ("1", "L", "LA", "RGB", "RGBA", "I;16") and img.mode[0] != "I"):
                    img = img.convert("RGBA")
                arr = np.array(img)
            arr[removed[i][::-1]] = 0
            name = f"{prefix}{i}.png"
            Image.fromarray(arr).save(tmp / name)  # the mode follows the array: L, LA, RGB, RGBA, I;16
            files.append(folder / name)
        os.chmod(tmp, 0o755)
        old = None
        if folder.exists():
            old = temp_dir_beside(folder)
            os.replace(folder, old / "slices")
        os.replace(tmp, folder)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        return files
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def write_volume_model(volume, model, count: int, prefix: str, path: Path) -> Path:
    """An ADF model file with ``volume`` alone, its slices the ones just written beside it."""
    vol = replace(volume, images=VolumeImages(path="slices/", prefix=prefix, format="png", count=count))
    return write_file(ModelFile(namespace=model.namespace, volumes=[vol]), path)


def write_metrics(metrics: dict, path: Path) -> None:
    atomic_write_text(path, json.dumps(metrics, indent=2, allow_nan=False) + "\n")


def _colours(n_labels: int, protected_ids, own=None) -> np.ndarray:
    """Label id -> picture colour: a colour tissue's own colour (``own[i]``, "#rrggbb"), else
    the palette's; protected ones red."""
    lut = np.zeros((n_labels, 3), dtype=np.uint8)
    for i in range(1, n_labels):
        mine = own[i] if own is not None and i < len(own) else None
        lut[i] = tuple(int(mine[k : k + 2], 16) for k in (1, 3, 5)) if mine else PALETTE[(i - 1) % len(PALETTE)]
    for i in protected_ids:
        lut[i] = PROTECTED
    return lut


def render_frame(vol, burr_local: np.ndarray, radius: float, protected_ids, size: int = 240, colours=None):
    """A picture of the volume now: left, the top view (looking down z) shaded by height;
    right, the section through the burr's row (x across, z up), tissues by colour, removed
    voxels dark, the burr as a ring."""
    from PIL import Image, ImageDraw

    lut = _colours(len(vol.label_names), protected_ids, colours)
    tissue = vol.values > 0
    nz = tissue.shape[0]
    has = tissue.any(axis=0)
    top = nz - 1 - np.argmax(tissue[::-1], axis=0)  # highest tissue voxel per column
    gy, gx = np.gradient(top.astype(float))
    shade = np.clip(0.75 + 0.25 * (gx - gy) / np.sqrt(1 + gx * gx + gy * gy), 0.3, 1.0) * (0.55 + 0.45 * top / nz)
    rows, cols = np.indices(top.shape)
    lab = vol.labels[top, rows, cols]
    img_top = (lut[lab] * shade[..., None]).astype(np.uint8)
    img_top[~has] = 0
    idx = vol.index_of(burr_local)
    row = int(np.clip(round(idx[1]), 0, vol.values.shape[1] - 1))
    sec_lab = np.where(tissue[:, row, :], vol.labels[:, row, :], 0)
    img_sec = lut[sec_lab]
    img_sec[vol.removed_mask[:, row, :]] = REMOVED
    panels = []
    for arr, centre_xy in ((img_top[::-1], (idx[0], vol.values.shape[1] - 1 - idx[1])), (img_sec[::-1], None)):
        h, w = arr.shape[:2]
        k = size / max(h, w)
        im = Image.fromarray(np.ascontiguousarray(arr)).resize((max(1, round(w * k)), max(1, round(h * k))), 0)
        draw = ImageDraw.Draw(im)
        cx, cy = centre_xy if centre_xy else (idx[0], nz - 1 - idx[2])
        r = radius / vol.step[0] * k
        px, py = (cx + 0.5) * k, (cy + 0.5) * k
        draw.ellipse([px - r, py - r, px + r, py + r], outline=BURR, width=2)
        panels.append(im)
    out = Image.new("RGB", (panels[0].width + panels[1].width + 6, max(p.height for p in panels)), (20, 20, 20))
    out.paste(panels[0], (0, 0))
    out.paste(panels[1], (panels[0].width + 6, 0))
    return out


def write_gif(frames: list, path: Path, fps: float = 10.0) -> None:
    if not frames:
        return
    buf = io.BytesIO()
    frames[0].save(buf, format="GIF", save_all=True, append_images=frames[1:], duration=int(1000 / fps), loop=0)
    atomic_write_bytes(path, buf.getvalue())


__all__ = ["render_frame", "write_gif", "write_metrics", "write_slices", "write_volume_model"]
