"""What `adfkit drill` reads besides the scene: a tool path file and a volume's labels file.

Tool path file (text, UTF-8): one waypoint per line, ``x y z`` in metres in the world frame,
separated by spaces, tabs or commas; ``#`` starts a comment; blank lines are skipped. The burr
starts where the scene puts it and moves through the waypoints in order, in straight lines.

Labels file (``labels.yaml`` in the volume's slice folder, optional): the tissue each range of
slice values stands for, in the slices' own units (0..255 for 8-bit slices), and which tissues
the burr must not touch::

    bone: [150, 255]
    canal: [60, 120]
    protected: [canal]

Without one, voxels at or above the iso-surface value are ``bone`` and the voxels below it that
are not empty are ``soft tissue``.

Either file, when wrong, is a located error (``file:line:col``) with a hint.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from ... import inputs
from ...adf.volume_labels import parse_labels
from ...diagnostics import AdfError, SourceLocation, error

MAX_WAYPOINTS = 100_000
MAX_COORD = 10.0  # m: a drill path further than this from the origin is a unit mistake
_SPLIT = re.compile(r"[^\s,]+")


def _path_error(path, line: int, col: int, message: str, hint: str) -> AdfError:
    return AdfError(error("drill-path", message, SourceLocation(inputs.shown(path), line, col), hint))


def read_path_file(path: str | Path) -> np.ndarray:
    """The waypoints of a tool path file, (n, 3) metres; any bad line is a located error."""
    text = inputs.read_text(path, "text", what="tool path file")
    points: list[list[float]] = []
    for ln, line in enumerate(text.splitlines(), start=1):
        body = line.split("#", 1)[0]
        tokens = [(m.group(0), m.start() + 1) for m in _SPLIT.finditer(body)]
        if not tokens:
            continue
        if len(tokens) != 3:
            col = tokens[3][1] if len(tokens) > 3 else len(body.rstrip()) + 1
            raise _path_error(
                path,
                ln,
                col,
                f"a waypoint is three numbers x y z; this line has {len(tokens)}",
                "write one waypoint per line: x y z in metres, e.g. 0.0 0.0 0.03",
            )
        xyz = []
        for tok, col in tokens:
            try:
                v = float(tok)
            except ValueError:
                raise _path_error(
                    path, ln, col, f"'{tok[:40]}' is not a number", "coordinates are decimal numbers in metres"
                ) from None
            if not math.isfinite(v) or abs(v) > MAX_COORD:
                raise _path_error(
                    path,
                    ln,
                    col,
                    f"{tok[:40]} m is not a coordinate within {MAX_COORD:g} m of the origin",
                    "coordinates are in metres (a millimetre value is 1000x too large)",
                )
            xyz.append(v)
        points.append(xyz)
        if len(points) > MAX_WAYPOINTS:
            raise _path_error(
                path, ln, 1, f"more than {MAX_WAYPOINTS:,} waypoints", "thin the path: the burr moves in straight lines"
            )
    if not points:
        raise _path_error(path, 1, 1, "the tool path file has no waypoint", "write one waypoint per line: x y z")
    return np.array(points, dtype=float)


def default_labels(iso: float) -> tuple[list[str], list[tuple[float, float]], set[str]]:
    return ["bone", "soft tissue"], [(iso, math.inf), (1e-12, iso)], set()


def read_labels(path: Path, full_scale: float, tree) -> tuple[list[str], list[tuple], set[str]]:
    """Names, value ranges (0..1 of full scale, inclusive) or (r, g, b) colours, and protected
    names of a labels file (its syntax: adf.volume_labels, which ``adfkit validate`` checks too)."""
    text = inputs.read_text(path, "text", tree=tree, what="labels file")
    names, ranges, protected = parse_labels(text, inputs.shown(path))
    scaled = [r if len(r) == 3 else (max(r[0], 0.0) / full_scale, r[1] / full_scale) for r in ranges]
    return names, scaled, set(protected)


def label_array(values: np.ndarray, ranges: list[tuple], unit: float = 1.0, files=None) -> np.ndarray:
    """uint8 label id per voxel: 1 + the first tissue holding it, 0 for none (or empty).
    ``ranges``: (low, high) in the values' units (``unit``: full scale in them), or (r, g, b) of
    a colour tissue, matched against the colour slices ``files`` (read again, a slice at a
    time, rows flipped as geometry.volume reads them)."""
    from PIL import Image

    out = np.zeros(values.shape, dtype=np.uint8)
    eps = 0.5 / 65535.0 * unit  # a value written as an integer and normalised may sit this far off
    by_colour = any(len(r) == 3 for r in ranges)
    step = 1 if by_colour else 16
    for z in range(0, len(values), step):
        v, o = values[z : z + step], out[z : z + step]
        tissue = v > 0
        rgb = None
        if by_colour and files is not None:
            with Image.open(files[z]) as img:
                rgb = np.asarray(img.convert("RGBA"))[::-1, :, :3][None]
        for i in range(len(ranges) - 1, -1, -1):
            r = ranges[i]
            if len(r) == 3:
                if rgb is None:
                    continue
                hit = tissue & np.all(rgb == np.array(r, dtype=np.uint8), axis=-1)
            else:
                hit = (v >= r[0] - eps) & (v <= r[1] + eps) & tissue
            o[hit] = i + 1
    return out


def label_colour(r: tuple) -> str | None:
    """``"#rrggbb"`` of a colour tissue, None for a value range."""
    return "#{:02x}{:02x}{:02x}".format(*r) if len(r) == 3 else None


__all__ = ["MAX_WAYPOINTS", "default_labels", "label_array", "label_colour", "read_labels", "read_path_file"]
