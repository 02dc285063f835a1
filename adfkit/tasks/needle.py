"""The curved needle's geometry, measured from its mesh: the circle its wire follows (centre,
axis, radius in the needle body frame), where the tip and the tail sit on it, and frames along
the arc. Engine-neutral: numpy and the ADF model only.

The arc frame A (in the needle body frame N) has its origin at the circle's centre, x toward
the tip, z along the circle's axis oriented so that turning the needle by +a about z moves the
tip forward (the tail lies at angle -span). A point of the wire at angle phi is
``centre + r (cos phi x + sin phi y)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np


def obj_vertices(path: Path) -> np.ndarray:
    """The vertex positions of a Wavefront OBJ file (every object in it)."""
    out = []
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            if line.startswith("v "):
                out.append([float(x) for x in line.split()[1:4]])
    return np.array(out, dtype=float)


@dataclass
class NeedleGeometry:
    radius: float
    span: float  # rad, tail to tip
    arc_in_needle: np.ndarray  # 4x4: arc frame A in the needle body frame N

    def point(self, phi: float) -> np.ndarray:
        """A point of the wire at angle phi (0: tip, -span: tail), in N."""
        return (self.arc_in_needle @ np.array([self.radius * np.cos(phi), self.radius * np.sin(phi), 0.0, 1.0]))[:3]

    @property
    def tip(self) -> np.ndarray:
        return self.point(0.0)

    @property
    def tail(self) -> np.ndarray:
        return self.point(-self.span)


def fit_needle(vertices: np.ndarray, tail_hint: np.ndarray | None = None) -> NeedleGeometry:
    """Circle fitted to the mesh vertices of a curved needle (in its body frame). The end
    nearer ``tail_hint`` (the thread's attachment) is the tail; without one, the end whose
    vertices spread the widest across the wire (the blunt one)."""
    v = np.asarray(vertices, dtype=float)
    if len(v) < 6:
        raise ValueError("the needle mesh has too few vertices to fit a circle")
    mean = v.mean(axis=0)
    _, _, vt = np.linalg.svd(v - mean)
    e1, e2 = vt[0], vt[1]
    n = np.cross(e1, e2)  # right-handed: angles below run counter-clockwise about n
    xy = np.c_[(v - mean) @ e1, (v - mean) @ e2]
    a = np.c_[2 * xy, np.ones(len(xy))]
    sol = np.linalg.lstsq(a, (xy**2).sum(axis=1), rcond=None)[0]
    c2 = sol[:2]
    radius = float(np.sqrt(sol[2] + c2 @ c2))
    centre = mean + c2[0] * e1 + c2[1] * e2
    ang = np.sort(np.arctan2(xy[:, 1] - c2[1], xy[:, 0] - c2[0]))
    gaps = np.diff(np.r_[ang, ang[0] + 2 * np.pi])
    k = int(np.argmax(gaps))
    start = ang[(k + 1) % len(ang)]  # the arc runs counter-clockwise from start ...
    span = float(2 * np.pi - gaps[k])  # ... to start + span
    end = start + span

    def at(phi):
        return centre + radius * (np.cos(phi) * e1 + np.sin(phi) * e2)

    if tail_hint is not None:
        tail_is_start = np.linalg.norm(at(start) - tail_hint) < np.linalg.norm(at(end) - tail_hint)
    else:

        def width(phi):
            near = np.abs(((np.arctan2(xy[:, 1] - c2[1], xy[:, 0] - c2[0]) - phi + np.pi) % (2 * np.pi)) - np.pi) < 0.1
            return float(np.ptp((v[near] - mean) @ n)) if near.any() else 0.0

        tail_is_start = width(start) >= width(end)
    if tail_is_start:  # tip at end: counter-clockwise about n moves the tip forward
        x = np.cos(end) * e1 + np.sin(end) * e2
        z = n
    else:  # tip at start: clockwise about n, so the axis is -n
        x = np.cos(start) * e1 + np.sin(start) * e2
        z = -n
    y = np.cross(z, x)
    t = np.eye(4)
    t[:3, :3] = np.c_[x, y, z]
    t[:3, 3] = centre
    return NeedleGeometry(radius, span, t)


def wire_radius(task) -> float:
    """The needle wire's radius, m, measured from its collision mesh (the 90th percentile of
    the vertices' distances from the fitted circle: the tip's taper does not count)."""
    from ..adf.paths import collision_mesh_path
    from ..runner.rotations import invert

    b = task.needle.body
    path = collision_mesh_path(task.needle.model, b)
    if path is None or not path.is_file():
        return 0.0
    v = obj_vertices(path) * (b.scale or 1.0)
    a = invert(task.geom.arc_in_needle)
    p = v @ a[:3, :3].T + a[:3, 3]
    rho = np.hypot(np.hypot(p[:, 0], p[:, 1]) - task.geom.radius, p[:, 2])
    return float(np.percentile(rho, 90))
