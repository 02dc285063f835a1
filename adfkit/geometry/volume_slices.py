"""Which slice files a volume's ``images: {path, prefix, format, count}`` names, and what value
each voxel of a slice has, both as AMBF 2.0 reads them (checked in AMBF itself, headless, and
in its source: ``afVolume::createFromAttribs`` hands the four keys to CHAI3D's
``cMultiImage::loadFromFiles(path + "/" + prefix, format, count)``).

Files. ``count`` is the most AMBF searches for, not how many there must be: for every index i
from 0 to ``count`` (inclusive) it tries ``prefix + i + "." + format`` with i written in every
width from its own digits up to the digits of ``count`` (``plane005.png``, ``plane0005.png``
and ``plane00005.png`` for i = 5, count = 512, prefix ``plane00``), and stacks every file that
exists, in index order. Missing indices leave no hole: the slices after a gap move down (the
stack fills the volume's ``dimensions`` whatever its height). No file at all: AMBF skips the
volume. The extension is matched as written (``format: .png`` looks for ``plane00..png``), and
CHAI3D reads only bmp, gif, jpg, png, ppm and raw files.

Values. CHAI3D draws and collides a volume by one channel: a grey slice by its grey level, a
slice with an alpha channel (RGBA, grey + alpha, a palette or grey PNG with transparency) by
its alpha, and a colour slice without alpha as fully opaque (every voxel solid). 16-bit slices
keep their full precision here (CHAI3D strips them to their high byte: a difference below 1/255).
A slice's first row is the top of the picture; CHAI3D puts the bottom row at the volume's -y
side, so rows are flipped: row r of the array is picture row height-1-r.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: the slice file formats CHAI3D (AMBF's image reader) reads, by extension; raw files have no
#: header Pillow could read, so adfkit reads the other five
AMBF_FORMATS = ("bmp", "gif", "jpg", "png", "ppm", "raw")
READ_FORMATS = ("bmp", "gif", "jpg", "png", "ppm")


def digits(n: int) -> int:
    """CHAI3D's cNumDigits: the decimal digits of ``n`` (1 for 0)."""
    return len(str(abs(int(n))))


@dataclass
class SliceFiles:
    """The slice files AMBF would stack, in order, and what is odd about them."""

    folder: Path  # where they are looked for
    stem: str  # the file name's prefix part (``prefix`` may hold folders)
    files: list[Path] = field(default_factory=list)
    indices: list[int] = field(default_factory=list)  # the index each file stands for
    others: list[str] = field(default_factory=list)  # up to a few names in the folder that did not match

    @property
    def gaps(self) -> list[int]:
        """Indices missing between 0 and the highest found."""
        have = set(self.indices)
        return [i for i in range(max(self.indices, default=-1) + 1) if i not in have]

    @property
    def twice(self) -> list[int]:
        """Indices found under two widths (``plane005.png`` and ``plane0005.png``)."""
        seen: set[int] = set()
        out = []
        for i in self.indices:
            if i in seen and i not in out:
                out.append(i)
            seen.add(i)
        return out


def find_slice_files(base: Path, prefix: str, fmt: str, count: int) -> SliceFiles:
    """The files ``base/prefix<i>.<fmt>`` AMBF stacks for ``count`` (see the module's text):
    one listing of the folder, not count·widths look-ups."""
    joined = os.path.join(str(base), str(prefix))
    folder, stem = Path(os.path.dirname(joined) or "."), os.path.basename(joined)
    out = SliceFiles(folder, stem)
    suffix = "." + str(fmt)
    width = digits(count)
    try:
        names = sorted(os.listdir(folder))
    except OSError:
        return out
    found = []
    for name in names:
        if not (name.startswith(stem) and name.endswith(suffix)):
            if len(out.others) < 3 and not name.startswith("."):
                out.others.append(name)
            continue
        number = name[len(stem) : len(name) - len(suffix)]
        if not (number.isascii() and number.isdigit()):
            continue
        i = int(number)
        if i <= count and digits(i) <= len(number) <= width:
            found.append((i, len(number), name))
    for i, _, name in sorted(found):
        out.files.append(folder / name)
        out.indices.append(i)
    return out


_ALPHA_MODES = ("RGBA", "LA", "PA", "RGBa", "La")
_GREY_MODES = ("L", "I", "F", "1", "I;16", "I;16L", "I;16B", "I;16N")


def slice_values(img) -> tuple[np.ndarray, float, bool]:
    """(values (rows, columns), full scale, opaque) of one Pillow image, as CHAI3D draws it: the
    alpha channel where there is one, the grey level of a grey slice, and for a colour slice
    without alpha all ones (``opaque`` True). Rows flipped: row 0 is the picture's bottom row."""
    mode = img.mode
    opaque = False
    if mode in _ALPHA_MODES:
        arr = np.asarray(img.getchannel("A"))
    elif "transparency" in img.info and mode in ("P", "L", "RGB"):
        arr = np.asarray(img.convert("RGBA").getchannel("A"))
    elif mode in _GREY_MODES:
        arr = np.asarray(img.convert("L") if mode == "1" else img)
    else:  # RGB, a palette without transparency, CMYK, YCbCr ...: CHAI3D's alpha is 1
        arr = np.full((img.height, img.width), 255, dtype=np.uint8)
        opaque = True
    if arr.dtype == np.uint8:
        peak = 255.0
    elif arr.dtype == np.uint16 or mode.startswith("I;16"):
        peak = 65535.0
    else:
        peak = 1.0  # 32-bit integer or float slices: the caller scales by the volume's maximum
    return arr[::-1], peak, opaque


__all__ = [
    "AMBF_FORMATS",
    "READ_FORMATS",
    "SliceFiles",
    "digits",
    "find_slice_files",
    "slice_values",
]
