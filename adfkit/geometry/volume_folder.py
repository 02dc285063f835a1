"""A volume's slices found in a folder of images, for authoring a volume from it: the files
named ``<prefix><index>.<format>`` (``bone_0.png`` .. ``bone_47.png``, ``plane000.png`` ..
``plane00252.png`` with prefix ``plane00``), as an ADF volume's ``images: {path, prefix, format,
count}`` names them and AMBF reads them (geometry.volume_slices: indices 0..count, zero-padded
up to count's digits). A folder that does not hold one such stack (no slices, several stacks, a
gap in the numbering, widths AMBF would not read as one stack, slices of different sizes) is a
located error with a hint.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from .. import inputs
from ..diagnostics import AdfError, SourceLocation, error
from .volume import MAX_SLICES
from .volume_slices import READ_FORMATS, digits

#: the image formats AMBF reads slices in (and Pillow too)
SLICE_FORMATS = READ_FORMATS
_NAME = re.compile(r"^(?P<prefix>.*?)(?P<index>\d+)\.(?P<format>[A-Za-z0-9]+)$")


@dataclass
class SliceStack:
    folder: Path
    prefix: str
    format: str  # the extension as the files have it, without the dot
    count: int
    width: int
    height: int
    files: list[str]  # the slice file names, in order

    def names(self) -> list[str]:
        return list(self.files)


def _fail(folder: Path, rule: str, message: str, hint: str) -> AdfError:
    return AdfError(error(rule, f"{inputs.shown(folder)}: {message}", SourceLocation(inputs.shown(folder)), hint))


def _listed(names: list[str], most: int = 4) -> str:
    return ", ".join(names[:most]) + (f" and {len(names) - most} more" if len(names) > most else "")


def _as_stack(stem: str, runs: list[str]) -> tuple[str, int] | None:
    """The prefix and count under which AMBF reads exactly these numbered files (their digit
    runs after ``stem``) as slices 0..n-1: leading zeros belong to the prefix (``plane00`` +
    ``0``..``252``) or are padding within count's digits (``s_00``..``s_47`` for count 48)."""
    n = len(runs)
    for k in range(min(len(r) for r in runs)):
        if any(not r.startswith("0" * k) for r in runs):
            break
        numbers = [r[k:] for r in runs]
        index = [int(x) for x in numbers]
        if sorted(index) == list(range(n)) and all(digits(i) <= len(x) <= digits(n) for i, x in zip(index, numbers)):
            return stem + "0" * k, n
    return None


def find_slices(folder: str | Path, prefix: str | None = None) -> SliceStack:
    """The one slice stack in ``folder`` (of ``prefix`` when given), its slices checked."""
    folder = Path(folder)
    inputs.check_path_text(folder)
    if not folder.is_dir():
        raise _fail(folder, "volume-folder", "is not a folder", "choose the folder that holds the slice images")
    stacks: dict[tuple[str, str], dict[str, str]] = {}  # (stem, format) -> digit run -> file name
    for p in sorted(folder.iterdir()):
        m = _NAME.match(p.name)
        if m is None or m["format"].lower() not in SLICE_FORMATS or not inputs.is_regular(p):
            continue
        stem, run = m["prefix"], m["index"]
        if prefix is not None:
            rest = p.name[len(prefix) : -len(m["format"]) - 1]
            if not (p.name.startswith(prefix) and rest.isascii() and rest.isdigit()):
                continue
            stem, run = prefix, rest
        stacks.setdefault((stem, m["format"]), {})[run] = p.name
    example = f"{prefix or 'slice_'}0.png"
    if not stacks:
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
    ((stem, fmt), runs) = next(iter(stacks.items()))
    if len(runs) > MAX_SLICES:
        raise _fail(folder, "volume-images", f"{len(runs)} slices; a volume has at most {MAX_SLICES}", "downsample")
    stack = _as_stack(stem, list(runs))
    if stack is None:
        index = {int(r): r for r in runs}
        top = max(index)
        width = {len(r) for r in runs}
        pad = width.pop() if len(width) == 1 else 1
        missing = [f"{stem}{i:0{pad}d}.{fmt}" for i in range(top + 1) if i not in index]
        if missing:
            raise _fail(
                folder,
                "volume-slice-gap",
                f"the numbering of {stem}<index>.{fmt} has gaps: {_listed(missing)} missing "
                f"({len(index)} slices between {min(index)} and {top})",
                "number the slices 0, 1, 2, ... without gaps (AMBF stacks the slices it finds, so the "
                "ones after a gap would move down)",
            )
        raise _fail(
            folder,
            "volume-slice-names",
            f"{stem}<index>.{fmt} mixes widths of numbering that AMBF does not read as one stack "
            f"({_listed(sorted(runs.values()), 3)})",
            f"rename them {example}, {example.replace('0.', '1.')}, ... (no leading zeros)",
        )
    pre, count = stack
    names = [runs[r] for r in sorted(runs, key=lambda r: int(r[len(pre) - len(stem) :]))]
    sizes: dict[tuple[int, int], str] = {}
    for name in names:
        sizes.setdefault(_size(folder / name, folder), name)
        if len(sizes) > 1:
            (a, first), (b, other) = sizes.items()
            raise _fail(
                folder,
                "volume-slice-size",
                f"the slices have different sizes: {first} is {a[0]}x{a[1]}, {other} is {b[0]}x{b[1]}",
                "every slice of a volume has the same size: resample them to one",
            )
    ((w, h),) = sizes
    return SliceStack(folder, pre, fmt, count, w, h, names)


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
            "write the slices as PNG",
        ) from None
