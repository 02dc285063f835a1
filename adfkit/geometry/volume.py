"""ADF volumes (§11.4): a voxel volume given as a stack of image slices, read into one array,
and its iso-surface as a triangle mesh.

The slices are the files AMBF stacks for ``images: {path, prefix, format, count}``
(:mod:`adfkit.geometry.volume_slices`: ``count`` is the most it searches for; the slices found
are stacked in index order), relative to the ADF file, each read through the project's one
input policy (regular files inside the scene's tree, under the size cap) by Pillow. A voxel's
value is what AMBF draws and collides by: the grey level of a grey slice, the alpha of a slice
with alpha, 1 for a colour slice without alpha; normalised to 0..1 by the format's maximum, so
``iso-surface value`` (default 0.5) is a fraction of full scale, as AMBF's volume shader
compares it. The volume fills a box of ``dimensions`` (times ``scale``) centred on its
``location``: of n slices found, slice i lies at z = -d_z/2 + (i + 1/2)·d_z/n; a slice's
bottom row at -y.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import inputs
from ..adf.paths import relative_to_file
from ..diagnostics import AdfError, Diagnostic, SourceLocation, error, info, warning
from .volume_slices import AMBF_FORMATS, READ_FORMATS, SliceFiles, find_slice_files, slice_values

#: A count above this, or more voxels than MAX_VOXELS, is refused before a file is opened.
MAX_SLICES = 4096
MAX_VOXELS = 512**3
DEFAULT_ISO = 0.5


@dataclass
class VolumeData:
    voxels: np.ndarray  # (slices, rows, columns) float32 in 0..1 (raw: the slices' own values); row 0 the bottom row
    dimensions: np.ndarray  # (3,) metres along x (columns), y (rows), z (slices), scale applied
    files: list[Path]
    full_scale: float = 1.0  # the slice value that reads as 1.0 (255 for 8-bit slices)
    findings: list[Diagnostic] = field(default_factory=list)  # what is odd but AMBF loads (notes, warnings)
    count: int = 0  # `images: count` as written

    @property
    def unit(self) -> float:
        """Full scale in the array's units: ``full_scale`` for raw integer values, else 1."""
        return self.full_scale if self.voxels.dtype.kind in "ui" else 1.0


def _where(vol, key: str | None = None) -> SourceLocation:
    loc = vol.where(key) if key else None
    return loc or vol.source or SourceLocation("<volume>")


def _fail(vol, rule: str, message: str, hint: str, key: str = "images") -> AdfError:
    return AdfError(error(rule, f"volume '{vol.identifier}': {message}", _where(vol, key), hint))


def _listed(items: list, most: int = 6) -> str:
    shown = ", ".join(str(x) for x in items[:most])
    return shown + (f" and {len(items) - most} more" if len(items) > most else "")


def slice_files(model, vol) -> SliceFiles:
    """The slice files AMBF stacks for ``vol``, in order; an impossible ``images`` entry, a
    format AMBF cannot read or no slice at all is a located error (AMBF skips such a volume)."""
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
        )
    fmt = str(im.format)
    if fmt.lower() not in AMBF_FORMATS:
        raise _fail(
            vol,
            "volume-format",
            f"`images: format` is {fmt!r}: AMBF reads slices in {', '.join(AMBF_FORMATS)} only"
            + (" (without the dot)" if fmt.lstrip(".").lower() in AMBF_FORMATS else "")
            + "; it skips the volume",
            "write the slices as PNG and give format: png",
        )
    if fmt.lower() not in READ_FORMATS:
        raise _fail(vol, "volume-format", "raw slices have no header to read", "write the slices as PNG")
    base = relative_to_file(model.path, str(im.path))
    inputs.check_path_text(base, _where(vol, "images"))
    found = find_slice_files(base, str(im.prefix), fmt, im.count)
    if not found.files:
        where = inputs.shown(found.folder)
        if not found.folder.is_dir():
            message = f"the slice folder {where} does not exist"
        else:
            message = f"no slice {found.stem}<0..{im.count}>.{fmt} in {where}"
            if found.others:
                message += f" (it holds {_listed(found.others, 3)})"
        raise _fail(
            vol,
            "volume-slice-missing",
            message + "; AMBF skips the volume",
            "check images: path (relative to this file), prefix and format; slices are numbered from 0",
        )
    return found


def _findings(vol, found: SliceFiles, count: int, opaque: list[int]) -> list[Diagnostic]:
    where = _where(vol, "images")
    name = f"volume '{vol.identifier}'"
    out = []
    n = len(found.files)
    if found.gaps:
        out.append(
            warning(
                "volume-slice-gap",
                f"{name}: slice {_listed(found.gaps)} of 0..{max(found.indices)} is missing; AMBF stacks the "
                f"{n} it finds, so the slices after a gap move down and the volume is stretched",
                where,
                "restore the missing slices, or renumber the stack from 0 without gaps",
            )
        )
    if found.twice:
        out.append(
            warning(
                "volume-slice-names",
                f"{name}: slice {_listed(found.twice)} is there under two names (with and without leading "
                "zeros); AMBF stacks both",
                where,
                "keep one file per index",
            )
        )
    if opaque:
        out.append(
            warning(
                "volume-slice-opaque",
                f"{name}: slice {_listed(opaque)} is a colour image without alpha; AMBF draws and collides a "
                "colour volume by its alpha, so every voxel of it is solid",
                where,
                "write grey slices, or RGBA slices whose alpha is 0 outside the tissue",
            )
        )
    if n < count and not found.gaps:  # a gap's warning says it already
        out.append(
            info(
                "volume-slice-count",
                f"{name}: `images: count` is {count} and {n} slices are found; AMBF reads count as the most "
                f"to search for and stacks the {n} it finds",
                where,
                f"count: {n} says what the folder holds",
            )
        )
    elif found.indices and found.indices[-1] == count:
        out.append(
            info(
                "volume-slice-count",
                f"{name}: AMBF also stacks slice {count}: it searches indices 0 to count inclusive",
                where,
                f"give count: {count + 1}, or remove the slice numbered {count}",
            )
        )
    return out


def volume_facts(model, vol) -> dict:
    """What `adfkit info` says of a volume without reading every slice: its name, the voxels
    (the first slice's size, the slices found), ``count`` as written and its size in metres;
    ``problem`` instead of the voxels when AMBF would skip it."""
    from PIL import Image, UnidentifiedImageError

    d = vol.dimensions
    size = [
        (getattr(d, k, None) if d is not None and getattr(d, k, None) is not None else 1.0)
        * (vol.scale if vol.scale is not None else 1.0)
        for k in "xyz"
    ]
    out: dict = {"name": vol.name or vol.identifier.removeprefix("VOLUME ")}
    try:
        found = slice_files(model, vol)
        first = inputs.check_file(
            found.files[0], "image", tree=getattr(model, "tree", None), referrer=_where(vol, "images")
        )
        with Image.open(first) as img:
            w, h = img.size
        n = len(found.files)
        out["voxels"] = f"{w}x{h}x{n}"
        out["slices found"] = n
        out["count"] = int(vol.images.count)
        out["size m"] = "x".join(f"{v:.6g}" for v in size)
        out["voxel mm"] = "x".join(f"{1000 * v / k:.4g}" for v, k in zip(size, (w, h, n)))
    except AdfError as exc:
        out["problem"] = exc.diagnostics[0].message
    except (UnidentifiedImageError, OSError, ValueError) as exc:
        out["problem"] = f"the first slice is not an image Pillow reads ({type(exc).__name__})"
    if vol.parent:
        out["parent"] = vol.parent
    return out


def load_volume(model, vol, raw: bool = False) -> VolumeData:
    """Every slice of ``vol`` as one array, each read through the input policy; a slice outside
    the tree, not an image or of another size is a located error. What AMBF loads but a modeller
    should hear about (a gap, opaque colour slices, count above the slices found) is in
    ``findings``. ``raw``: the values as the slices hold them (uint8 for 8-bit slices, uint16 for
    16-bit ones, a quarter or half the memory of float32: the drill's 512³ volume), to be read
    against ``full_scale``."""
    from PIL import Image, UnidentifiedImageError

    found = slice_files(model, vol)
    files = found.files
    tree = getattr(model, "tree", None)
    where = _where(vol, "images")
    voxels = None
    size, peak, opaque = None, 1.0, []
    for i, f in enumerate(files):
        inputs.check_file(f, "image", tree=tree, referrer=where, what=f"slice {i}")
        try:
            with Image.open(f) as img:
                img.load()
                arr, peak_i, flat = slice_values(img)
        except (UnidentifiedImageError, OSError, ValueError) as exc:
            raise _fail(
                vol,
                "volume-slice-unreadable",
                f"slice {i} ({inputs.shown(f.name)}) is not an image Pillow reads ({type(exc).__name__})",
                "write the slices as PNG",
            ) from None
        if size is None:
            size = arr.shape
            if len(files) * size[0] * size[1] > MAX_VOXELS:
                raise _fail(
                    vol,
                    "volume-too-large",
                    f"{len(files)} slices of {size[1]}x{size[0]} are more than {MAX_VOXELS:,} voxels",
                    "downsample the slices",
                )
            kind = arr.dtype if raw and arr.dtype in (np.uint8, np.uint16) else np.float32
            voxels = np.empty((len(files), *size), dtype=kind)
            peak = peak_i  # the first slice's kind is the volume's (AMBF's rule for a set of images)
        elif arr.shape != size:
            raise _fail(
                vol,
                "volume-slice-size",
                f"slice {i} ({inputs.shown(f.name)}) is {arr.shape[1]}x{arr.shape[0]}, slice 0 is {size[1]}x{size[0]}",
                "every slice of a volume has the same size",
            )
        if flat:
            opaque.append(i)
        voxels[i] = arr if peak_i == peak else np.clip(arr * (peak / peak_i), 0, peak)  # 8 among 16 bit
    assert voxels is not None
    if peak == 1.0 and voxels.size and voxels.max() > 1.0:  # 32-bit integer or float slices: their own maximum
        peak = float(voxels.max())
    if voxels.dtype == np.float32:
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
    count = int(vol.images.count)
    return VolumeData(voxels, dims, files, peak, _findings(vol, found, count, opaque), count)


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
