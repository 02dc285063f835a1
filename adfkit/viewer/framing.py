"""The viewer's first view: every body of the scene in the picture, whatever its cameras are.

The scene's first camera (an endoscope an inch from the tissue, in the challenge's scene) says
from where its author looks at it; the page looks from that side, pulled back until the bodies'
bounding sphere fills the field of view. A static backdrop far larger than everything else (a
10 m floor under a 1 m robot) is left out of the framing, not out of the picture."""

from __future__ import annotations

import math

import numpy as np

#: looking from here towards the bodies when the scene has no camera (above and aside)
DEFAULT_FROM = np.array([1.5, -1.5, 1.2])
#: a static body whose box is this many times wider than all the moving bodies together is a
#: backdrop (the challenge's 1.8 m drape under its two arms and phantom)
BACKDROP = 2.0
MARGIN = 1.1  # the bounding sphere fills the view up to this


def _diag(lo, hi) -> float:
    return float(np.linalg.norm(hi - lo))


def framed_boxes(boxes: list[tuple[np.ndarray, np.ndarray, bool]]) -> list[tuple[np.ndarray, np.ndarray, bool]]:
    """``boxes`` ((low, high, static) world boxes) less the backdrops: the static boxes
    BACKDROP times wider than the union of the moving ones (all of them when none moves)."""
    moving = [b for b in boxes if not b[2]]
    if not moving:
        return boxes
    size = _diag(np.min([b[0] for b in moving], axis=0), np.max([b[1] for b in moving], axis=0))
    return [b for b in boxes if not b[2] or _diag(b[0], b[1]) <= BACKDROP * max(size, 1e-3)]


def overview(boxes, fov: float, look=None) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """(eye, target, up) that shows every box of ``boxes`` (world (low, high, static)) in a view
    of vertical field ``fov`` (rad), looking along ``look`` ((eye, target, up) of the scene's
    first camera) or from DEFAULT_FROM; None without a box."""
    boxes = [b for b in boxes if np.all(np.isfinite(b[0])) and np.all(np.isfinite(b[1]))]
    if not boxes:
        return None
    kept = framed_boxes(boxes)
    lo = np.min([b[0] for b in kept], axis=0)
    hi = np.max([b[1] for b in kept], axis=0)
    centre, radius = (lo + hi) / 2, max(_diag(lo, hi) / 2, 0.02)
    up = np.array([0.0, 0.0, 1.0])
    back = DEFAULT_FROM / np.linalg.norm(DEFAULT_FROM)
    if look is not None:
        eye, target, cam_up = (np.asarray(v, float) for v in look)
        d = eye - target
        if np.linalg.norm(d) > 1e-9 and np.all(np.isfinite(d)):
            back = d / np.linalg.norm(d)
            if np.linalg.norm(np.cross(cam_up, back)) > 1e-6:
                up = cam_up / np.linalg.norm(cam_up)
    dist = MARGIN * radius / math.sin(min(fov, math.radians(170)) / 2)
    return centre + back * dist, centre, up


__all__ = ["overview", "framed_boxes"]
