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

from ..diagnostics import AdfError, SourceLocation, error
from ..model import Geometry, ShapeEntry
from ..model.pose import Pose, Quat, Vec3
from .repair import to_manifold

#: Spread below this share of the largest one counts as none (a flat or straight point set).
_FLAT = 1e-9


@dataclass
class PrimitiveFit:
    entry: ShapeEntry
    error: float  # 1 - IoU with the mesh solid
    volume: float  # of the primitive


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


def _refuse(rule: str, message: str, hint: str) -> AdfError:
    return AdfError(error(rule, message, SourceLocation("<mesh>"), hint))


def _points(mesh: trimesh.Trimesh) -> np.ndarray:
    """The vertices the triangles use (what a primitive must enclose); a mesh without a
    triangle is refused with a message, not a numpy error."""
    faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    verts = np.asarray(mesh.vertices, dtype=np.float64).reshape(-1, 3)
    if len(faces) == 0 or len(verts) == 0:
        raise _refuse(
            "mesh-empty",
            "the mesh has no triangles to fit a shape around",
            "give the object a mesh with faces (or add a primitive by hand)",
        )
    pts = verts[np.unique(faces)]
    if not np.all(np.isfinite(pts)):
        raise _refuse("mesh-unreadable", "the mesh has NaN or infinite vertex coordinates", "fix or re-export the mesh")
    return pts


def spread(points: np.ndarray) -> int:
    """How many directions the points extend in: 0 (one point), 1 (a line), 2 (flat), 3 (a solid)."""
    centred = points - points.mean(axis=0)
    s = np.linalg.svd(centred, compute_uv=False) if len(points) > 1 else np.zeros(3)
    if len(s) == 0 or s[0] <= 0.0:
        return 0
    return int(np.sum(s > _FLAT * s[0]))


def _principal_frame(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Axes of the points' spread (columns, largest first) and their centroid."""
    c = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - c, full_matrices=True)
    return vt.T, c


def fit_error(mesh: trimesh.Trimesh, entry: ShapeEntry) -> tuple[float, float]:
    """1 - IoU of the primitive and the mesh solid, and the primitive's volume. An open or
    non-manifold mesh is measured as the convex hull of its vertices; a flat one has no
    volume, so nothing overlaps it (error 1)."""
    prim = entry_manifold(entry)
    try:
        solid = to_manifold(mesh)
        if solid.status() != manifold3d.Error.NoError or solid.volume() <= 0.0:
            raise ValueError("not a closed solid")
    except Exception:  # noqa: BLE001 - manifold3d refuses open or non-manifold input in several ways
        pts = _points(mesh)
        if spread(pts) < 3:
            return 1.0, prim.volume()
        solid = to_manifold(trimesh.convex.convex_hull(pts))
    inter = (solid ^ prim).volume()
    union = (solid + prim).volume()
    return 1.0 - inter / union, prim.volume()


def _axial_extent(pts: np.ndarray, center: np.ndarray, axis: np.ndarray):
    rel = pts - center
    t = rel @ axis
    radial = np.linalg.norm(rel - np.outer(t, axis), axis=1)
    return t, radial


def fit_box(mesh: trimesh.Trimesh) -> ShapeEntry:
    pts = _points(mesh)
    if spread(pts) < 3:
        raise _refuse(
            "mesh-flat",
            "the mesh is flat (its vertices lie in one plane or on one line): a box around it would have no thickness",
            "give it thickness (a Solidify modifier), or fit a capsule or a sphere around it",
        )
    transform, extents = trimesh.bounds.oriented_bounds(pts)
    inv = np.linalg.inv(transform)  # box frame in mesh frame
    return ShapeEntry(
        shape="box",
        geometry=Geometry(x=float(extents[0]), y=float(extents[1]), z=float(extents[2])),
        offset=_pose(inv[:3, :3], inv[:3, 3]),
    )


def fit_sphere(mesh: trimesh.Trimesh) -> ShapeEntry:
    pts = _points(mesh)
    dims = spread(pts)
    if dims == 0:
        raise _refuse(
            "mesh-degenerate",
            "every vertex of the mesh is at one point: no sphere can enclose it",
            "give the object a mesh with extent",
        )
    if dims == 3:
        center, radius = trimesh.nsphere.minimum_nsphere(pts)
    else:  # flat or straight: the sphere about the bounding box's centre (encloses; not the smallest)
        center = (pts.min(axis=0) + pts.max(axis=0)) / 2
        radius = float(np.linalg.norm(pts - center, axis=1).max())
    return ShapeEntry(shape="sphere", geometry=Geometry(radius=float(radius)), offset=_pose(np.eye(3), center))


def _principal_axis(mesh: trimesh.Trimesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Long axis of the hull's inertia (smallest moment) and the hull centroid, and the points;
    for a flat or straight mesh (no hull volume) the points' direction of largest spread and
    their centroid. A single point is refused."""
    pts = _points(mesh)
    dims = spread(pts)
    if dims == 0:
        raise _refuse(
            "mesh-degenerate",
            "every vertex of the mesh is at one point: nothing to fit around",
            "give the object a mesh with extent",
        )
    if dims < 3:
        axes, c = _principal_frame(pts)
        return axes[:, 0], c, pts
    hull = trimesh.convex.convex_hull(pts)
    moments, axes = np.linalg.eigh(hull.moment_inertia)
    return axes[:, 0], np.asarray(hull.center_mass), pts


def fit_cylinder(mesh: trimesh.Trimesh) -> ShapeEntry:
    axis, center, pts = _principal_axis(mesh)
    t, radial = _axial_extent(pts, center, axis)
    if radial.max() <= _FLAT * max(1e-300, float(t.max() - t.min())):
        raise _refuse(
            "mesh-degenerate",
            "the mesh is a straight line: a cylinder around it has no radius",
            "fit a capsule, or give the object a mesh with width",
        )
    center = center + axis * (t.max() + t.min()) / 2
    name, rot = _axis_frame(axis)
    return ShapeEntry(
        shape="cylinder",
        geometry=Geometry(radius=float(radial.max()), height=float(t.max() - t.min()), axis=name),
        offset=_pose(rot, center),
    )


def capsule_around(points: np.ndarray, center: np.ndarray, axis: np.ndarray) -> tuple[float, float, np.ndarray]:
    """(radius, total height, centre) of the smallest capsule on this axis line enclosing points."""
    t, radial = _axial_extent(points, center, axis)
    r = float(radial.max())
    reach = np.sqrt(np.maximum(r * r - radial**2, 0.0))
    lo, hi = float((t + reach).min()), float((t - reach).max())  # segment ends [lo, hi]
    if lo > hi:
        lo = hi = 0.5 * (lo + hi)
        r = float(np.sqrt(radial**2 + (t - lo) ** 2).max())
    return r, (hi - lo) + 2 * r, center + axis * (lo + hi) / 2


def smallest_capsule(points: np.ndarray, center: np.ndarray, axis: np.ndarray) -> tuple[float, float, np.ndarray]:
    """(radius, total height, centre) of the capsule of least volume on this axis line that
    encloses the points. The thinnest one (:func:`capsule_around`) is long: its caps must reach
    the corners of a square pad, 0.4 m over a 0.2 m pad; a wider one is shorter (0.35 m), up to
    the sphere that encloses everything. Volume over the radius, scanned then refined."""
    t, radial = _axial_extent(points, center, axis)
    r_thin = float(radial.max())
    r_ball = float(np.hypot(r_thin, (t.max() - t.min()) / 2))  # a sphere about the middle encloses all

    def volume(r: float) -> float:
        reach = np.sqrt(np.maximum(r * r - radial**2, 0.0))
        core = max(float((t - reach).max() - (t + reach).min()), 0.0)
        return np.pi * r * r * core + 4.0 / 3.0 * np.pi * r**3

    lo, hi = r_thin, r_ball
    for _ in range(3):  # each pass narrows to the neighbours of the best of 33 radii
        radii = np.linspace(lo, hi, 33)
        best = int(np.argmin([volume(r) for r in radii]))
        lo, hi = radii[max(best - 1, 0)], radii[min(best + 1, len(radii) - 1)]
    r = float(radii[best])
    reach = np.sqrt(np.maximum(r * r - radial**2, 0.0))
    a, b = float((t + reach).min()), float((t - reach).max())  # segment ends [a, b]
    if a > b:  # a sphere: any centre in [b, a] encloses; the middle, with the radius it needs
        a = b = 0.5 * (a + b)
        r = float(np.sqrt(radial**2 + (t - a) ** 2).max())
    return r, (b - a) + 2 * r, center + axis * (a + b) / 2


def fit_capsule(mesh: trimesh.Trimesh) -> ShapeEntry:
    """The capsule of least volume (the best fit of an enclosing shape) along the mesh's
    principal axes or its oriented bounding box's, whichever encloses it in less."""
    axis, center, pts = _principal_axis(mesh)
    candidates = [(axis, center)]
    if spread(pts) == 3:
        hull = trimesh.convex.convex_hull(pts)
        pts = np.asarray(hull.vertices)  # enclosing the hull is enclosing the mesh
        _, axes = np.linalg.eigh(hull.moment_inertia)
        transform, _ = trimesh.bounds.oriented_bounds(pts)
        box = np.linalg.inv(transform)
        candidates += [(axes[:, i], center) for i in (1, 2)] + [(box[:3, i], box[:3, 3]) for i in range(3)]
    else:
        frame, c = _principal_frame(pts)
        candidates += [(frame[:, i], c) for i in (1, 2)]
    fits = [(smallest_capsule(pts, np.asarray(c, dtype=float), a / np.linalg.norm(a)), a) for a, c in candidates]
    (r, height, c), axis = min(
        fits, key=lambda f: np.pi * f[0][0] ** 2 * (f[0][1] - 2 * f[0][0]) + 4 / 3 * np.pi * f[0][0] ** 3
    )
    if r <= 0.0:
        raise _refuse(
            "mesh-degenerate",
            "the mesh is a straight line: a capsule around it has no radius",
            "give the object a mesh with width",
        )
    name, rot = _axis_frame(axis / np.linalg.norm(axis))
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
        out.append(
            ShapeEntry(shape="capsule", geometry=Geometry(radius=r, height=height, axis=name), offset=_pose(rot, c0))
        )
    return out
