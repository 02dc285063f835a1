"""A hole of the phantom as the pass test sees it: its frame (the boundary body's, z out of the
tissue along the needle's path), its real opening (the free square inside the boundary
body's capsules, not the ghost's box) and the crossings of its plane by a point or a chain.

Pure geometry on the ADF model and 4x4 poses (numpy only), so that the verdict rules can be
tested on exact numbers as well as on a simulation.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

#: a hole's name: "entry" or "exit" and its pair's number, however a modeller spells it
#: (ghostEntry1, Entry 1, entry_1, Entry1_ghost)
HOLE_NAME = re.compile(r"(entry|exit)\D*?(\d+)", re.IGNORECASE)

#: opening half-width used when a hole body has no capsule boundary (m)
DEFAULT_HALF_OPENING = 0.0024


#: rad: a pair on tissue sloping more than this, for which the plan finds no grasp the arms
#: reach, is said to lie on a slope (the 2-pair phantom 45 degrees along its line, pair 1 end
#: down: psm2's outer_wrist_yaw 4.8 degrees past its limit; 30 degrees planned)
STEEP = math.radians(35.0)


def pair_tilt(entry: np.ndarray, exit_: np.ndarray) -> float:
    """The angle (rad) from the vertical of the tissue's surface at a pair (its holes' 4x4 frames):
    the hole axes (z, along the needle's path out of the tissue) lean opposite ways about the
    surface's normal, so their sum, taken pointing up, is along it."""
    u = entry[:3, 2] + exit_[:3, 2]
    n = float(np.linalg.norm(u))
    return 0.0 if n < 1e-9 else math.acos(min(1.0, abs(float(u[2])) / n))


def slope_note(pairs: list[tuple[str, str, np.ndarray, np.ndarray]]) -> str:
    """ "; Entry1 and Exit1 lie on tissue sloping n°: ..." for the steepest of the pairs (entry's
    name, exit's name, their frames) sloping more than STEEP, else ""."""
    steep = [(pair_tilt(e, x), a, b) for a, b, e, x in pairs if pair_tilt(e, x) > STEEP]
    if not steep:
        return ""
    tilt, a, b = max(steep)
    return (
        f"; {a} and {b} lie on tissue sloping {math.degrees(tilt):.0f}° from level: the arms stand for level "
        "tissue (turned about the vertical only) and do not turn the needle that far, lay the pairs on a "
        "gentler slope"
    )


def hole_name(name: str) -> tuple[str, int] | None:
    """("entry" or "exit", pair k) of a hole's name, or None."""
    m = HOLE_NAME.search(name or "")
    return (m.group(1).lower(), int(m.group(2))) if m else None


def has_boundary(body) -> bool:
    """Whether a hole body is framed by capsule boundary bodies: the bundled scene's holes and the
    corpus set's (its Entry/Exit bodies have a mesh to draw and four capsules to collide, 2.5 mm
    off the centre with 0.6 mm radius: a 3.8 mm opening)."""
    return any((s.shape or "").lower() == "capsule" for s in getattr(body, "compound_collision_shape", None) or [])


def boundary_body(ghost):
    """The capsule-framed hole body a hole ghost sits on, or None."""
    parent = getattr(ghost, "parent", None)
    return parent if parent is not None and has_boundary(parent.body) else None


def ghost_box(ghost) -> tuple[float, float, float] | None:
    """A hole ghost's box (x, y, z sizes, m): its shape's geometry, else its collision
    geometry, else a box of its compound collision shape (the Blender add-on writes a ghost's
    box so); None for another shape. AMBF 2.x does not scale primitive collision shapes by the
    object's ``scale`` (adf-format.md §12.3), nor does the runner: neither does this."""
    g = ghost.ghost
    found = [(g.shape, g.geometry), (g.collision_shape, g.collision_geometry)]
    found += [(e.shape, e.geometry) for e in g.compound_collision_shape or []]
    for shape, geo in found:
        if geo is not None and (shape or "box").lower() == "box" and None not in (geo.x, geo.y, geo.z):
            return (geo.x, geo.y, geo.z)
    return None


def hole_label(ghost) -> str:
    """A hole's name for a modeller: its boundary body's (Entry1), else its ghost's."""
    b = boundary_body(ghost)
    return (b.body.name or b.body.identifier) if b is not None else (ghost.ghost.name or ghost.ghost.identifier)


def hole_frame(world, ghost) -> np.ndarray:
    """World pose of a hole: its boundary body's frame where it has one (the ghost may sit
    off the hole: the needle must go through the hole), else the ghost's; its z out of the
    tissue (against gravity): a hole whose z points into the tissue (a normal flipped in
    Blender) is read turned half a turn about its x, so that the needle going in crosses it
    inward (read as it was, such a pair that the needle went through was "entry-missed")."""
    b = boundary_body(ghost)
    f = b.world_matrix() if b is not None else world.ghost_pose(ghost)
    g = getattr(world, "gravity", None)
    g = np.asarray((0.0, 0.0, -9.81) if g is None else g, dtype=float)
    if float(f[:3, 2] @ g) > 0.0:  # z along gravity: into the tissue
        f = f.copy()
        f[:3, 1:3] *= -1.0
    return f


def opening_half_extents(body) -> np.ndarray:
    """Half-widths (x, y), m, of the free opening inside a hole body's boundary: per in-plane
    axis, the nearest capsule lying across that axis, less its radius. A body without
    capsules gets DEFAULT_HALF_OPENING on both axes. The body's ``scale`` leaves its capsules
    as they are (AMBF 2.x scales meshes only, adf-format.md §12.3, and so does the runner: a
    hole scaled 0.2 was read as a 1.0 mm opening that its unscaled 4.8 mm capsules do not make)."""
    half = [np.inf, np.inf]
    for s in getattr(body, "compound_collision_shape", None) or []:
        if (s.shape or "").lower() != "capsule" or s.geometry is None:
            continue
        off = s.offset.position if s.offset is not None and s.offset.position is not None else None
        if off is None:
            continue
        r = float(s.geometry.radius or 0.0)
        axis = (s.geometry.axis or "z").lower()
        if axis == "x":  # a capsule along x bounds the opening in y
            half[1] = min(half[1], abs(off.y) - r)
        elif axis == "y":
            half[0] = min(half[0], abs(off.x) - r)
    return np.array([h if np.isfinite(h) else DEFAULT_HALF_OPENING for h in half])


@dataclass
class Crossing:
    """The tip crossing a hole's plane between two control steps."""

    t: float
    inward: bool  # from the +z side (outside the tissue at an entry) to the -z side
    at: np.ndarray  # (x, y) in the hole frame where it crossed
    outside_by: float  # m beyond the opening (0 when inside it)
    tip_leading: bool  # the wire's tangent at the tip points the way the tip moved


def plane_crossing(prev_local: np.ndarray, local: np.ndarray, half: np.ndarray):
    """Where the segment prev -> now (hole frame) crosses z = 0, and how far outside the
    opening that is (m, 0 inside); None when it does not cross."""
    if (prev_local[2] > 0) == (local[2] > 0):
        return None
    s = prev_local[2] / (prev_local[2] - local[2])
    at = prev_local + s * (local - prev_local)
    beyond = np.maximum(np.abs(at[:2]) - half, 0.0)
    return at[:2], float(np.linalg.norm(beyond))


def chain_crossing(points_local: np.ndarray, half: np.ndarray, tolerance: float) -> int | None:
    """Index i of the first segment (i, i+1) of a chain (points in the hole frame) that crosses
    the hole's plane inside its opening (+ tolerance); None when none does."""
    for i in range(len(points_local) - 1):
        hit = plane_crossing(points_local[i], points_local[i + 1], half + tolerance)
        if hit is not None and hit[1] == 0.0:
            return i
    return None


def tip_leading(tangent_local: np.ndarray, prev_local: np.ndarray, local: np.ndarray) -> bool:
    """True when the needle went tip first: its tangent at the tip (tail -> tip) points along
    the tip's motion across the plane."""
    motion = local - prev_local
    return float(np.dot(tangent_local, motion)) > 0.0
