"""ADF volumes (§11.4): a voxel volume given as a stack of image slices, read into one array,
and its iso-surface as a triangle mesh.

The slices are ``images: {path, prefix, format, count}``: the files ``path/prefix<i>.format``
for i = 0 .. count-1, relative to the ADF file, read through the project's one input policy
(regular files inside the scene's tree, under the size cap) by Pillow. Voxel values are read
as Pillow gives them (8 or 16 bit, colour slices as their luminance) and normalised to 0..1 by
the format's maximum, so ``iso-surface value`` (default 0.5) is a fraction of full scale, as
AMBF's volume shader compares it. The volume fills a box of ``dimensions`` (times ``scale``)
centred on its ``location``: slice i lies at z = -d_z/2 + (i + 1/2)·d_z/count.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import inputs
from ..adf.paths import relative_to_file
from ..diagnostics import AdfError, SourceLocation, error

#: More slices than this, or more voxels than MAX_VOXELS, is refused before a file is opened.
MAX_SLICES = 4096
MAX_VOXELS = 512**3
DEFAULT_ISO = 0.5


@dataclass
class VolumeData:
    voxels: np.ndarray  # (count, height, width) float32 in 0..1: slice, row, column
    dimensions: np.ndarray  # (3,) metres along x (columns), y (rows), z (slices), scale applied
    files: list[Path]
    full_scale: float = 1.0  # the slice value that reads as 1.0 (255 for 8-bit slices)


def _where(vol, key: str | None = None) -> SourceLocation:
    loc = vol.where(key) if key else None
    return loc or vol.source or SourceLocation("<volume>")


def _fail(vol, rule: str, message: str, hint: str, key: str = "images") -> AdfError:
    return AdfError(error(rule, f"volume '{vol.identifier}': {message}", _where(vol, key), hint))


def slice_paths(model, vol) -> list[Path]:
    """The slice files a volume names, in order; a missing or impossible `images` entry is a
    located error (AMBF skips such a volume with an error message)."""
    im = vol.images
    missing = [k for k in ("path", "prefix", "format", "count") if im is None or getattr(im, k) is None]
    if missing:
        raise _fail(
            vol,
            "volume-images",
            f"`images` lacks {', '.join(missing)}; AMBF skips the volume",
            "give images: {path: slices/, prefix: slice_, format: png, count: N}",
        )
    if im.count <= 0 or im.count > MAX_SLICES:
        raise _fail(
            vol,
            "volume-images",
            f"`images: count` is {im.count}; a volume has 1 to {MAX_SLICES} slices",
            "count the slice files",
            "images",
        )
    fmt = str(im.format).lstrip(".")
    base = relative_to_file(model.path, str(im.path))
    return [base / f"{im.prefix}{i}.{fmt}" for i in range(im.count)]


def load_volume(model, vol) -> VolumeData:
    """Every slice of ``vol`` as one array, each read through the input policy; the first slice
    that is missing, outside the tree, not an image or of another size is a located error."""
    from PIL import Image, UnidentifiedImageError

    files = slice_paths(model, vol)
    tree = getattr(model, "tree", None)
    where = _where(vol, "images")
    slices, size, peak = [], None, 1.0
    for i, f in enumerate(files):
        inputs.check_file(f, "image", tree=tree, referrer=where, what=f"slice {i}")
        try:
            with Image.open(f) as img:
                img.load()
                mode = img.mode
                arr = np.asarray(img.convert("L") if mode in ("RGB", "RGBA", "P", "LA", "CMYK") else img)
        except (UnidentifiedImageError, OSError, ValueError) as exc:
            raise _fail(
                vol,
                "volume-slice-unreadable",
                f"slice {i} ({inputs.shown(f.name)}) is not an image Pillow reads ({type(exc).__name__})",
                "write the slices as PNG, TIFF or another Pillow format",
            ) from None
        if arr.ndim != 2:
            raise _fail(
                vol,
                "volume-slice-unreadable",
                f"slice {i} ({inputs.shown(f.name)}) is not a single-channel image",
                "write grey slices",
            )
        if size is None:
            size = arr.shape
            if len(files) * size[0] * size[1] > MAX_VOXELS:
                raise _fail(
                    vol,
                    "volume-too-large",
                    f"{len(files)} slices of {size[1]}x{size[0]} are more than {MAX_VOXELS:,} voxels",
                    "downsample the slices",
                )
        elif arr.shape != size:
            raise _fail(
                vol,
                "volume-slice-size",
                f"slice {i} ({inputs.shown(f.name)}) is {arr.shape[1]}x{arr.shape[0]}, slice 0 is {size[1]}x{size[0]}",
                "every slice of a volume has the same size",
            )
        peak = (
            65535.0 if arr.dtype == np.uint16 or mode.startswith("I;16") else 255.0 if arr.dtype == np.uint8 else peak
        )
        slices.append(arr)
    voxels = np.stack(slices).astype(np.float32)
    if peak == 1.0 and voxels.size and voxels.max() > 1.0:  # 32-bit integer or float slices: their own maximum
        peak = float(voxels.max())
    voxels /= peak
    d = vol.dimensions
    dims = np.array(
        [
            d.x if d and d.x is not None else 1.0,
            d.y if d and d.y is not None else 1.0,
            d.z if d and d.z is not None else 1.0,
        ],
        dtype=float,
    ) * (vol.scale if vol.scale is not None else 1.0)
    if not np.all(dims > 0):
        raise _fail(
            vol,
            "volume-dimensions",
            f"`dimensions` {dims.tolist()} must be positive",
            "give a size in metres",
            "dimensions",
        )
    return VolumeData(voxels, dims, files, peak)


def iso_surface(data: VolumeData, level: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The iso-surface at ``level`` (0..1 of full scale; None: 0.5) as (vertices (n, 3) metres
    in the volume's frame, faces (m, 3)), closed at the volume's faces (the array is padded
    with empty voxels). Empty when no voxel reaches the level."""
    from skimage.measure import marching_cubes

    level = DEFAULT_ISO if level is None else float(level)
    vox = np.pad(data.voxels, 1, mode="constant", constant_values=0.0)
    if not (vox.max() >= level > vox.min()):
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    count, rows, cols = data.voxels.shape
    spacing = (data.dimensions[2] / count, data.dimensions[1] / rows, data.dimensions[0] / cols)
    verts, faces, _, _ = marching_cubes(vox, level=level, spacing=spacing)
    # (slice, row, column) -> (x, y, z); the padding shifts by one voxel; centre the box
    step = np.array([spacing[2], spacing[1], spacing[0]])
    xyz = verts[:, ::-1] - 0.5 * step - data.dimensions / 2  # padded index p is voxel p-1, centred at (p-1/2)·step
    return xyz, faces.astype(np.int64)
