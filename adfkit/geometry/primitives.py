"""Fitting ADF primitives (box, sphere, cylinder, capsule) around a mesh or a part, and
compounds of them (e.g. a chain of capsules along a curved needle).

Every fit ENCLOSES the mesh's vertices. The fit error is ``1 - IoU`` of the primitive and the
mesh solid (manifold3d booleans), so 0 is perfect. Results are ``ShapeEntry`` in ADF
conventions: box x/y/z FULL lengths, capsule ``height`` TOTAL including caps, ``axis`` z with
the orientation in ``offset`` (or x/y/z when the fitted axis is a body axis).
"""
from __future__ import annotations

from dataclasses import dataclass

import manifold3d
import numpy as np
import trimesh

from ..model import Geometry, ShapeEntry
from ..model.pose import Pose, Quat, Vec3
from .repair import to_manifold


@dataclass
class PrimitiveFit:
    entry: ShapeEntry
    error: float          # 1 - IoU with the mesh solid
    volume: float         # of the primitive


def _pose(rot: np.ndarray, center) -> Pose:
    return Pose(Vec3(*map(float, center)), Quat.from_matrix(rot.tolist()).normalized())


def _axis_frame(axis: np.ndarray) -> tuple[str, np.ndarray]:
    """ADF ``axis`` letter and the rotation that maps that local axis onto ``axis``."""
    axis = axis / np.linalg.norm(axis)
    for i, name in enumerate("xyz"):
        if abs(abs(axis[i]) - 1.0) < 1e-9:
            return name, np.eye(3)
    z = axis
    x = np.cross([0.0, 0.0, 1.0] if abs(z[2]) < 0.9 else [1.0, 0.0, 0.0], z)
    x /= np.linalg.norm(x)
    return "z", np.column_stack([x, np.cross(z, x), z])


def entry_manifold(entry: ShapeEntry, segments: int = 64) -> manifold3d.Manifold:
    """A solid for an ADF primitive entry (for IoU and union checks)."""
    g, kind = entry.geometry, entry.shape.lower()
    if kind == "box":
        solid = manifold3d.Manifold.cube([g.x, g.y, g.z], True)
    elif kind == "sphere":
        solid = manifold3d.Manifold.sphere(g.radius, segments)
    else:
        half = g.height / 2 - (g.radius if kind == "capsule" else 0.0)
        if kind == "cylinder":
            solid = manifold3d.Manifold.cylinder(g.height, g.radius, g.radius, segments, True)
        else:
            ball = manifold3d.Manifold.sphere(g.radius, segments)
            solid = manifold3d.Manifold.batch_hull([ball.translate([0, 0, -half]), ball.translate([0, 0, half])])
        a = (g.axis or "z").lower()
        if a == "x":
            solid = solid.rotate([0, 90, 0])
        elif a == "y":
            solid = solid.rotate([-90, 0, 0])
    pose = entry.offset or Pose()
    rot = np.array(Quat(*pose.orientation).matrix())
    affine = np.hstack([rot, np.array(pose.position, dtype=float).reshape(3, 1)])
    return solid.transform(affine)


def fit_error(mesh: trimesh.Trimesh, entry: ShapeEntry) -> tuple[float, float]:
    solid, prim = to_manifold(mesh), entry_manifold(entry)
    inter = (solid ^ prim).volume()
    union = (solid + prim).volume()
    return 1.0 - inter / union, prim.volume()


def _axial_extent(pts: np.ndarray, center: np.ndarray, axis: np.ndarray):
    rel = pts - center
    t = rel @ axis
    radial = np.linalg.norm(rel - np.outer(t, axis), axis=1)
    return t, radial


def fit_box(mesh: trimesh.Trimesh) -> ShapeEntry:
    transform, extents = trimesh.bounds.oriented_bounds(mesh)
    inv = np.linalg.inv(transform)  # box frame in mesh frame
    return ShapeEntry(shape="box", geometry=Geometry(x=float(extents[0]), y=float(extents[1]), z=float(extents[2])),
                      offset=_pose(inv[:3, :3], inv[:3, 3]))


def fit_sphere(mesh: trimesh.Trimesh) -> ShapeEntry:
    center, radius = trimesh.nsphere.minimum_nsphere(mesh)
    return ShapeEntry(shape="sphere", geometry=Geometry(radius=float(radius)), offset=_pose(np.eye(3), center))


def _principal_axis(mesh: trimesh.Trimesh) -> tuple[np.ndarray, np.ndarray]:
    """Long axis of the hull's inertia (smallest moment) and the hull centroid."""
    hull = mesh.convex_hull
    moments, axes = np.linalg.eigh(hull.moment_inertia)
    return axes[:, 0], np.asarray(hull.center_mass)


def fit_cylinder(mesh: trimesh.Trimesh) -> ShapeEntry:
    axis, center = _principal_axis(mesh)
    t, radial = _axial_extent(mesh.vertices, center, axis)
    center = center + axis * (t.max() + t.min()) / 2
    name, rot = _axis_frame(axis)
    return ShapeEntry(shape="cylinder", geometry=Geometry(radius=float(radial.max()), height=float(t.max() - t.min()), axis=name),
                      offset=_pose(rot, center))


def capsule_around(points: np.ndarray, center: np.ndarray, axis: np.ndarray) -> tuple[float, float, np.ndarray]:
    """(radius, total height, centre) of the smallest capsule on this axis line enclosing points."""
    t, radial = _axial_extent(points, center, axis)
    r = float(radial.max())
    reach = np.sqrt(np.maximum(r * r - radial ** 2, 0.0))
    lo, hi = float((t + reach).min()), float((t - reach).max())  # segment ends [lo, hi]
    if lo > hi:
        lo = hi = 0.5 * (lo + hi)
        r = float(np.sqrt(radial ** 2 + (t - lo) ** 2).max())
    return r, (hi - lo) + 2 * r, center + axis * (lo + hi) / 2


def fit_capsule(mesh: trimesh.Trimesh) -> ShapeEntry:
    axis, center = _principal_axis(mesh)
    r, height, c = capsule_around(np.asarray(mesh.vertices), center, axis)
    name, rot = _axis_frame(axis)
    return ShapeEntry(shape="capsule", geometry=Geometry(radius=r, height=height, axis=name), offset=_pose(rot, c))


FITTERS = {"box": fit_box, "sphere": fit_sphere, "cylinder": fit_cylinder, "capsule": fit_capsule}


def fit_primitives(mesh: trimesh.Trimesh, kinds=("box", "sphere", "cylinder", "capsule")) -> list[PrimitiveFit]:
    """Each kind fitted around ``mesh`` (closed), best (lowest error) first."""
    fits = []
    for k in kinds:
        entry = FITTERS[k](mesh)
        err, vol = fit_error(mesh, entry)
        fits.append(PrimitiveFit(entry, err, vol))
    return sorted(fits, key=lambda f: f.error)


def capsule_chain(points, radius: float) -> list[ShapeEntry]:
    """Capsules of ``radius`` along a polyline (one per segment), e.g. a needle's arc."""
    pts = np.asarray(points, dtype=float)
    out = []
    for a, b in zip(pts[:-1], pts[1:]):
        d = b - a
        length = float(np.linalg.norm(d))
        name, rot = _axis_frame(d / length)
        out.append(ShapeEntry(shape="capsule", geometry=Geometry(radius=radius, height=length + 2 * radius, axis=name),
                              offset=_pose(rot, (a + b) / 2)))
    return out


def fit_capsule_chain(mesh: trimesh.Trimesh, count: int = 4) -> list[ShapeEntry]:
    """``count`` capsules enclosing a curved, tube-like mesh (a suture needle).

    The mesh's plane comes from PCA, its arc from a least-squares circle in that plane; the
    vertices are cut into ``count`` equal angular bins and each bin gets its enclosing capsule
    along its chord.
    """
    v = np.asarray(mesh.vertices)
    mean = v.mean(axis=0)
    _, _, vt = np.linalg.svd(v - mean, full_matrices=False)
    u, w = vt[0], vt[1]
    x, y = (v - mean) @ u, (v - mean) @ w
    a = np.column_stack([x, y, np.ones_like(x)])
    cx, cy, c = np.linalg.lstsq(a, x * x + y * y, rcond=None)[0] / np.array([2, 2, 1])
    theta = np.arctan2(y - cy, x - cx)
    # rotate angles so the gap in the arc sits at ±pi
    order = np.sort(theta)
    gaps = np.diff(np.concatenate([order, [order[0] + 2 * np.pi]]))
    start = order[(np.argmax(gaps) + 1) % len(order)]
    theta = (theta - start) % (2 * np.pi)
    edges = np.linspace(0.0, theta.max(), count + 1)
    out = []
    for i in range(count):
        sel = v[(theta >= edges[i]) & (theta <= edges[i + 1])]
        center = sel.mean(axis=0)
        _, _, vt2 = np.linalg.svd(sel - center, full_matrices=False)
        axis = vt2[0]
        r, height, c0 = capsule_around(sel, center, axis)
        name, rot = _axis_frame(axis)
        out.append(ShapeEntry(shape="capsule", geometry=Geometry(radius=r, height=height, axis=name),
                              offset=_pose(rot, c0)))
    return out
