"""A volume's slices found in a folder of images, for authoring a volume from it: the files
named ``<prefix><index>.<format>`` (``bone_0.png`` .. ``bone_47.png``), as an ADF volume's
``images: {path, prefix, format, count}`` names them and AMBF reads them (indices from 0, no
padding). A folder that does not hold one such stack (no slices, several stacks, a gap in the
numbering, zero-padded indices, slices of different sizes) is a located error with a hint.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from .. import inputs
from ..diagnostics import AdfError, SourceLocation, error
from .volume import MAX_SLICES

#: image formats Pillow reads that slice stacks come in
SLICE_FORMATS = ("png", "tif", "tiff", "jpg", "jpeg", "bmp", "pgm", "ppm")
_NAME = re.compile(r"^(?P<prefix>.*?)(?P<index>\d+)\.(?P<format>[A-Za-z0-9]+)$")


@dataclass
class SliceStack:
    folder: Path
    prefix: str
    format: str  # the extension as the files have it, without the dot
    count: int
    width: int
    height: int

    def names(self) -> list[str]:
        return [f"{self.prefix}{i}.{self.format}" for i in range(self.count)]


def _fail(folder: Path, rule: str, message: str, hint: str) -> AdfError:
    return AdfError(error(rule, f"{inputs.shown(folder)}: {message}", SourceLocation(inputs.shown(folder)), hint))


def _listed(names: list[str], most: int = 4) -> str:
    return ", ".join(names[:most]) + (f" and {len(names) - most} more" if len(names) > most else "")


def find_slices(folder: str | Path, prefix: str | None = None) -> SliceStack:
    """The one slice stack in ``folder`` (of ``prefix`` when given), its slices checked."""
    folder = Path(folder)
    inputs.check_path_text(folder)
    if not folder.is_dir():
        raise _fail(folder, "volume-folder", "is not a folder", "choose the folder that holds the slice images")
    stacks: dict[tuple[str, str], dict[int, str]] = {}
    padded: list[str] = []
    for p in sorted(folder.iterdir()):
        m = _NAME.match(p.name)
        if m is None or m["format"].lower() not in SLICE_FORMATS or not inputs.is_regular(p):
            continue
        if prefix is not None and m["prefix"] != prefix:
            continue
        if len(m["index"]) > 1 and m["index"].startswith("0"):
            padded.append(p.name)
            continue
        stacks.setdefault((m["prefix"], m["format"]), {})[int(m["index"])] = p.name
    example = f"{prefix or 'slice_'}0.png"
    if not stacks:
        if padded:
            raise _fail(
                folder,
                "volume-slice-names",
                f"the slices are numbered with leading zeros ({_listed(padded, 2)}); an ADF volume "
                "reads <prefix><index>.<format> with the index unpadded",
                f"rename them {example}, {example.replace('0.', '1.')}, ...",
            )
        what = f"named {prefix}<index>" if prefix is not None else "named <prefix><index>.<format>"
        raise _fail(
            folder,
            "volume-no-slices",
            f"no slice images {what} ({', '.join(SLICE_FORMATS)})",
            f"choose the folder that holds the slices, numbered from 0: {example}, ...",
        )
    if len(stacks) > 1:
        found = [f"{p}<index>.{f} ({len(ix)} files)" for (p, f), ix in sorted(stacks.items())]
        raise _fail(
            folder,
            "volume-slice-names",
            f"holds several slice stacks: {_listed(found)}",
            "give the prefix of the one to use (and the format if two share it)",
        )
    ((pre, fmt), index) = next(iter(stacks.items()))
    top = max(index)
    missing = [f"{pre}{i}.{fmt}" for i in range(top + 1) if i not in index]
    if missing:
        raise _fail(
            folder,
            "volume-slice-gap",
            f"the numbering of {pre}<index>.{fmt} has gaps: {_listed(missing)} missing "
            f"({len(index)} slices between {min(index)} and {top})",
            "number the slices 0, 1, 2, ... without gaps (an ADF volume reads slices 0 to count - 1)",
        )
    if len(index) > MAX_SLICES:
        raise _fail(folder, "volume-images", f"{len(index)} slices; a volume has at most {MAX_SLICES}", "downsample")
    sizes: dict[tuple[int, int], str] = {}
    for i in range(top + 1):
        sizes.setdefault(_size(folder / index[i], folder), index[i])
        if len(sizes) > 1:
            (a, first), (b, other) = sizes.items()
            raise _fail(
                folder,
                "volume-slice-size",
                f"the slices have different sizes: {first} is {a[0]}x{a[1]}, {other} is {b[0]}x{b[1]}",
                "every slice of a volume has the same size: resample them to one",
            )
    ((w, h),) = sizes
    return SliceStack(folder, pre, fmt, top + 1, w, h)


def _size(path: Path, folder: Path) -> tuple[int, int]:
    from PIL import Image, UnidentifiedImageError

    inputs.check_file(path, "image", what="slice image")
    try:
        with Image.open(path) as im:
            return im.size
    except (UnidentifiedImageError, OSError, ValueError) as exc:
        raise _fail(
            folder,
            "volume-slice-unreadable",
            f"{path.name} is not an image Pillow reads ({type(exc).__name__})",
            "write the slices as PNG, TIFF or another Pillow format",
        ) from None
