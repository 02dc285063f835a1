"""The needle's bed beside a sloping phantom (``adfkit suture --phantom``, own_phantom.compose).

Beside level tissue the needle lies as in the bundled scene, its thread straight on along the line
of holes (own_phantom's docstring). Where the holes lie on a slope that line runs up or down it:
the level tray, raised onto the tissue under the needle, stood up to 30 mm over the holes with
its thread strip beside them (the needle pressed on it in carry 1 at 45° uphill), or its strip
ran into the slope rising under it (the thread on the phantom with 4654 N from the first step at
15° downhill). So, on a slope, the bed is also tried turned a quarter turn about the needle's
grasp (the thread then runs straight out from the line of holes, away from the ridge: level
across a slope along the line), OUT further out, and moved along the line (ALONG) to where the
tissue under it is lowest; the lay that leaves the bed lowest (the thread's strip counted) is
taken, the bundled one on a tie. Each lay's tray stands level, on nothing but the tissue it
clears (a stand the engine does not need), with no tissue over it within COLUMN.

Measured (2-pair phantom standing on the floor, pair 1, PyBullet, seed 0): along the line
+15/+30/+45° and -15° passed turned (+45° and -15° failed laid as the bundled scene); across the
line, the bundled lay stays the lowest and is kept. Laying the tray off the slab beside the
phantom instead failed every slope tried (the carried needle struck the slab's edge).
"""

from __future__ import annotations

import math

import numpy as np

from ...tasks.holes import pair_tilt
from . import layout as L
from .frames import rot_z, translation

#: rad from the vertical beyond which the holes' surface is a slope and the turned bed is tried
SLOPE = math.radians(5.0)
TURN = -90.0  # degrees about the vertical: the thread from along -y (the line) to -x (away from the ridge)
OUT = -0.010  # m along x (away from the ridge): at 0 psm2's wrist came 4.0-4.4 mm into the tray in insertion 1
ALONG = (-0.03, -0.02, -0.01, 0.0, 0.01)  # m along the line of holes (bundled y) tried
COLUMN = 0.1  # m above the bed kept free of tissue (no bed under an overhang)
STEP = 0.002  # m between the points the tray's top is sampled at


def holes_tilt(frames: dict) -> float:
    """The angle (rad) from the vertical of the holes' surface: the largest over the pairs
    (tasks.holes.pair_tilt)."""
    return max((pair_tilt(f["entry"], f["exit"]) for f in frames.values() if len(f) == 2), default=0.0)


def _points(rects: list, bed: float) -> np.ndarray:
    pts = []
    for (x0, y0), (x1, y1) in rects:
        nx, ny = max(2, int((x1 - x0) / STEP) + 1), max(2, int((y1 - y0) / STEP) + 1)
        pts += [(x, y, bed) for x in np.linspace(x0, x1, nx) for y in np.linspace(y0, y1, ny)]
    return np.array(pts).reshape(-1, 3)


def raise_needed(tops, rects: list, slot: list, thread: np.ndarray, bed: float, depth: float, t: np.ndarray) -> float:
    """How far (m) the tray (rectangles of the bundled frame, top at ``bed``, ``depth`` deep,
    placed by ``t``) must rise for its top, the thread lying on it and the slot's depth to clear
    the tissue; ``tops(points, below)``: the tissue's height under world points
    (own_phantom.tissue_top)."""
    top = np.r_[_points(rects, bed), thread[:, :3] * [1, 1, 0] + [0, 0, bed]]
    pts = np.r_[top, _points(slot, bed - depth)]
    placed = np.c_[pts, np.ones(len(pts))] @ t.T
    over = tops(placed[:, :3], COLUMN) - placed[:, 2]
    return max(0.0, float(over.max())) if np.isfinite(over).any() else 0.0


def turned(dx: float, dy: float, deg: float = TURN) -> np.ndarray:
    """The bed turned ``deg`` about the needle's grasp point and moved (dx, dy), bundled frame."""
    gx, gy = L.NEEDLE_GRASP_XY
    return translation(gx + dx, gy + dy, 0.0) @ rot_z(math.radians(deg)) @ translation(-gx, -gy, 0.0)


def sloped_bed(tops, frames: dict, rects: list, slot: list, thread: np.ndarray, bed: float, depth: float, needle_t):
    """(the bed's move in the bundled frame, its rise) where a turned lay beside a sloping
    phantom leaves the bed lower than the bundled one; None beside level tissue or where the
    bundled lay is as low (raise_needed for ``tops`` and the tray's shape)."""
    if holes_tilt(frames) <= SLOPE:
        return None
    level = raise_needed(tops, rects, slot, thread, bed, depth, needle_t)
    best = None
    for dy in ALONG:
        s = turned(OUT, dy)
        rise = raise_needed(tops, rects, slot, thread, bed, depth, needle_t @ s)
        key = (round(rise, 3), abs(dy))
        if best is None or key < best[0]:
            best = (key, s, rise)
    if best is None or best[2] >= level - 0.001:
        return None
    return best[1], best[2]
