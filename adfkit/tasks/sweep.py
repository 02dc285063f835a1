"""The needle's swept arc against the tissue's collision shapes, before the episode: where the
planned drive and pull would take the wire into a tissue body, and how the phantom stands at
its holes. It says at once what the physics will meet; the physical run stays the judge (a
pair fails on what the needle and the thread pressed on, never on this).

The needle turns about its circle's centre from the insertion's start to the end of the pull,
so its wire sweeps the circle through entry k and exit k (the hole figure draws it). At points
SAMPLE apart along that circle, the signed distance to each tissue body's collision shapes
(primitives, a static body's concave mesh as its triangles and other meshes as the convex
pieces the engine collides, as the planner's clearance reads them, ``clearance.Tissue``) says
whether the wire fits there: the centre line at least a wire radius
from every body. Where it does not, the finding says which body, from where to where along the
arc (mm past entry k), and either how wide the channel is across the needle's plane, where the
centre line is free but the channel narrower than the wire, or how far the body reaches into
the wire's path. Beside it, for each hole, how far the tissue's surface around it stands above
the hole (rays down onto the tissue, hole bodies left out, on a ring around it): holes must lie
on the surface the needle goes in through.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.semantics import concave_mesh
from .clearance import Tissue
from .grasping import SutureError
from .holes import boundary_body, hole_frame, hole_label, opening_half_extents

SAMPLE = 0.0002  # m between the wire's points along its circle
RING = 0.005  # m from a hole's centre to where the surface around it is read ...
RING_RAYS = 16  # ... by this many rays down
SURFACE_OFF = 0.0015  # m the surface may stand above or below a hole before the check says so
MARCH_EPS = 2e-5  # m: a ray has met the tissue this near it
MARCH_FAR = 0.03  # m a ray looks along its way


def _up(world) -> np.ndarray:
    g = -np.asarray(world.gravity, dtype=float)
    n = float(np.linalg.norm(g))
    return g / n if n > 0 else np.array([0.0, 0.0, 1.0])


def march(shapes: Tissue, starts: np.ndarray, direction: np.ndarray, far: float = MARCH_FAR) -> np.ndarray:
    """How far, m, each ray from ``starts`` (N, 3) along ``direction`` goes before it meets the
    shapes (sphere tracing on their signed distance); ``inf`` for a ray that meets nothing
    within ``far``, 0 for one that starts inside."""
    t = np.zeros(len(starts))
    hit = np.full(len(starts), np.inf)
    live = np.ones(len(starts), dtype=bool)
    for _ in range(400):
        if not live.any():
            break
        idx = np.flatnonzero(live)
        pts = starts[idx] + t[idx, None] * direction
        mid = pts.mean(axis=0)
        d = shapes.exact(pts, mid, float(np.linalg.norm(pts - mid, axis=1).max()) + far)
        met = d <= MARCH_EPS
        hit[idx[met]] = t[idx[met]]
        t[idx] += np.maximum(d, MARCH_EPS)
        live[idx[met]] = False
        live &= t <= far
    return hit


@dataclass
class Block:
    """The wire's path running into a tissue body at pair ``pair``."""

    pair: int
    body: str
    start_m: float  # past entry k along the arc where it begins (negative: before the entry)
    end_m: float
    depth_m: float  # how far the body reaches into the wire at most (its radius less the distance)
    width_m: float | None  # the channel's width across the needle's plane where narrowest, when the centre line is free
    wire_m: float  # the wire's thickness
    opening_m: float | None = None  # the body's opening, when it is one of the pair's holes
    #: the body is a static concave triangle mesh, which the engine (MuJoCo) collides as the
    #: convex hull of each piece, and so it is read here
    hulled_mesh: bool = False

    def text(self, entry: str, exit_: str) -> str:
        a, b = self.start_m * 1000, self.end_m * 1000
        if b - a < 0.3:
            span = f"{a:.1f} mm past {entry}" if a >= 0 else f"{-a:.1f} mm before {entry}"
        elif a >= 0:
            span = f"from {a:.1f} to {b:.1f} mm past {entry}"
        elif b < 0:
            span = f"from {-a:.1f} to {-b:.1f} mm before {entry}"
        else:
            span = f"from {-a:.1f} mm before {entry} to {b:.1f} mm past it"
        if self.opening_m is not None and self.opening_m < self.wire_m:
            return (
                f"{self.body}'s opening ({self.opening_m * 1000:.1f} mm) is narrower than the needle's wire "
                f"({self.wire_m * 1000:.2f} mm)"
            )
        if self.width_m is not None and self.width_m < self.wire_m:
            return (
                f"the channel at pair {self.pair} is {self.width_m * 1000:.1f} mm wide where the wire needs "
                f"{self.wire_m * 1000:.2f} mm ({self.body}, {span})"
            )
        inside = self.depth_m - self.wire_m / 2  # how far the wire's centre line runs inside the body
        how = (
            f"the wire's centre line up to {inside * 1000:.1f} mm inside it"
            if inside > 0
            else f"{self.depth_m * 1000:.1f} mm into the {self.wire_m * 1000:.2f} mm wire"
        )
        said = f"{self.body} lies in the needle's path between {entry} and {exit_} ({span}): {how}"
        if self.hulled_mesh:  # a static mesh AMBF and PyBullet collide as its triangles
            said += (
                f" (the convex hull of {self.body}'s collision mesh, as MuJoCo collides it; AMBF and PyBullet "
                "collide its triangles: give it collision primitives to be played alike everywhere)"
            )
        return said


def triangles(world) -> bool:
    """Whether the engine collides a static concave mesh as its triangles (AMBF does, PyBullet
    does; MuJoCo collides every mesh as the convex hull of each piece)."""
    return getattr(world, "engine", "") != "mujoco"


def _per_body(task) -> list[tuple[str, Tissue]]:
    return [(sb.name, Tissue([sb], triangles=triangles(task.world))) for sb in task.roles.tissue]


def _hulled(task) -> set[str]:
    """The tissue bodies read as hulls of a mesh AMBF keeps concave (static: AMBF's default
    collision mesh type), in an engine that collides it so."""
    if triangles(task.world):
        return set()
    return {sb.name for sb in task.roles.tissue if sb.static and concave_mesh(sb.body)}


def arc_blocks(task, pair, wire_r: float, bodies: list[tuple[str, Tissue]]) -> list[Block]:
    """Where the wire's circle at ``pair`` (as the plan drives it) runs into a tissue body."""
    b, psi_x, beyond, _, _ = task.arc_frame(pair)
    r = task.geom.radius
    psi0 = -task.approach - task.geom.span
    psi1 = psi_x + task.geom.span + max(getattr(task, "tail_clears", None) or [0.0])
    psi1 = min(psi1, psi0 + 2 * math.pi)
    psi = np.linspace(psi0, psi1, int((psi1 - psi0) * r / SAMPLE) + 2)
    local = np.c_[r * np.cos(psi), r * np.sin(psi), np.zeros(len(psi)), np.ones(len(psi))]
    pts = (local @ b.T)[:, :3]
    normal = b[:3, 2]
    out = []
    for name, shapes in bodies:
        d = shapes.exact(pts, pts.mean(axis=0), 2 * r)
        bad = d < wire_r
        if not bad.any():
            continue
        # the first run of blocked points along the tip's way (from the insertion's start)
        i = int(np.flatnonzero(bad)[0])
        j = i
        while j + 1 < len(bad) and bad[j + 1]:
            j += 1
        k = i + int(np.argmin(d[i : j + 1]))
        width = None
        if d[k] > 0:
            across = [march(shapes, pts[k : k + 1], s * normal, far=0.01)[0] for s in (1.0, -1.0)]
            width = float(sum(across)) if all(np.isfinite(across)) else None
        out.append(
            Block(pair.index, name, r * psi[i], r * psi[j], wire_r - float(d[i : j + 1].min()), width, 2 * wire_r)
        )
    return sorted(out, key=lambda blk: blk.start_m)


def surface_above(task, hole_ghost, shapes: Tissue) -> float | None:
    """How far, m, the tissue's surface around a hole stands above the hole's centre: RING_RAYS
    rays down on a circle RING from it, the highest mean of two opposite rays (a hole at the edge
    of a ridge has the ridge's top beside it, the channel on the other sides; the mean of
    opposite sides is the centre's height on a slope, and within 1 mm of it on a curved surface:
    the highest single ray stood 2.9 mm above holes lying on a phantom tilted 30 degrees, 1.8 mm
    on a ridge of 12 mm radius); the highest single ray where no two opposite ones meet the
    tissue; None where no ray does."""
    f = hole_frame(task.world, hole_ghost)
    up = _up(task.world)
    centre = f[:3, 3]
    a = np.cross(up, [1.0, 0.0, 0.0])
    if np.linalg.norm(a) < 1e-6:
        a = np.cross(up, [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    c = np.cross(up, a)
    ang = np.linspace(0, 2 * np.pi, RING_RAYS, endpoint=False)
    starts = centre + RING * (np.cos(ang)[:, None] * a + np.sin(ang)[:, None] * c) + MARCH_FAR / 2 * up
    h = MARCH_FAR / 2 - march(shapes, starts, -up)  # -inf where a ray met nothing
    half = RING_RAYS // 2
    both = (h[:half] + h[half:]) / 2
    both = both[np.isfinite(both)]
    if len(both):
        return float(both.max())
    h = h[np.isfinite(h)]
    return float(h.max()) if len(h) else None


def check(task, wire_r: float) -> dict[int, str]:
    """Per pair, what the swept arc and the surface at its holes show, in words (pairs with
    nothing to say are absent)."""
    bodies = _per_body(task)
    hulled = _hulled(task)
    hole_bodies = {id(boundary_body(g) or g.parent) for p in task.pairs for g in (p.entry, p.exit)}
    surface = Tissue([sb for sb in task.roles.tissue if id(sb) not in hole_bodies], triangles=triangles(task.world))
    out: dict[int, str] = {}
    for pair in task.pairs:
        notes = []
        entry, exit_ = hole_label(pair.entry), hole_label(pair.exit)
        off: dict[str, list[str]] = {}
        for label, ghost in ((entry, pair.entry), (exit_, pair.exit)):
            h = surface_above(task, ghost, surface)
            if h is not None and abs(h) > SURFACE_OFF:
                off.setdefault(f"{abs(h) * 1000:.1f} mm {'above' if h > 0 else 'below'}", []).append(label)
        for how, labels in off.items():
            notes.append(f"the tissue's surface is {how} {' and '.join(labels)} (holes lie on the surface)")
        try:
            blocks = arc_blocks(task, pair, wire_r, bodies)
        except SutureError:  # no arc to sweep: the plan says why it cannot drive this pair
            blocks = []
        for blk in blocks:
            hole = next((b for g in (pair.entry, pair.exit) if (b := boundary_body(g)) and b.name == blk.body), None)
            if hole is not None:
                blk.opening_m = 2 * float(min(opening_half_extents(hole.body)))
            blk.hulled_mesh = blk.body in hulled
        notes += [blk.text(entry, exit_) for blk in blocks]
        if notes:
            out[pair.index] = "; ".join(dict.fromkeys(notes))
    return out
