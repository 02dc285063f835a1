"""Inertia between ADF's principal form (ix, iy, iz + `inertial offset`) and full tensors."""

from __future__ import annotations

import numpy as np

from .. import inputs
from ..model.pose import Quat


def adf_principal(body) -> tuple[float, float, float]:
    """The principal moments written in the file (0 where missing), rounding noise removed
    (:func:`without_noise`)."""
    i = body.inertia
    if i is None:
        return (0.0, 0.0, 0.0)
    return without_noise((i.ix or 0.0, i.iy or 0.0, i.iz or 0.0))


def without_noise(moments, rel: float = 1e-9) -> tuple[float, float, float]:
    """Principal moments with floating-point noise taken out, so that engines accept them.

    An eigen-solver's last bits differ from one BLAS build or processor to another: the
    principal moments of a rod-like tensor come out as (5.6e-17, 0.21499999999999989, 0.215)
    on one machine and exactly on the triangle inequality on another, and PyBullet and MuJoCo
    zero or refuse a tensor that breaks it by a single ulp. A moment below ``rel`` times the
    largest is 0, and one that exceeds the sum of the other two by no more than that is lowered
    to the sum. Real violations (larger than the noise) are kept for the caller to report."""
    m = [float(x) for x in moments]
    tol = rel * max(abs(x) for x in m)
    m = [0.0 if abs(x) <= tol else x for x in m]
    for k in range(3):
        rest = m[(k + 1) % 3] + m[(k + 2) % 3]
        if rest < m[k] <= rest + tol:
            m[k] = rest
    return (m[0], m[1], m[2])


def principal(tensor) -> tuple[tuple[float, float, float], Quat]:
    """Principal moments and the rotation R (principal frame in the tensor's frame) with
    tensor = R diag(m) Rᵀ. A diagonal tensor keeps its axes and order (R = identity)."""
    t = np.asarray(tensor, dtype=float)
    off = abs(t[0, 1]) + abs(t[0, 2]) + abs(t[1, 2])
    if off <= 1e-12 * max(1e-300, float(np.abs(np.diag(t)).max())):
        return (float(t[0, 0]), float(t[1, 1]), float(t[2, 2])), Quat(0.0, 0.0, 0.0, 1.0)
    moments, axes = np.linalg.eigh(t)
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    return without_noise(moments), Quat.from_matrix(axes.tolist())


def physical_problem(moments, rel: float = 1e-9) -> str | None:
    """Why principal moments cannot belong to a rigid body (negative, or one larger than the
    sum of the other two: the triangle inequality), or None when they can."""
    a, b, c = moments
    if min(moments) < 0.0:
        return "include a negative moment"
    tol = rel * max(a, b, c)
    if a + b < c - tol or a + c < b - tol or b + c < a - tol:
        return "break the triangle inequality"
    return None


def world_tensor(moments, rotation) -> np.ndarray:
    """R diag(m) Rᵀ for a principal frame with orientation ``rotation`` (a Quat)."""
    r = np.asarray(rotation.matrix())
    return r @ np.diag(moments) @ r.T


def estimate_from_collision(model, body, mass: float) -> tuple[float, float, float] | None:
    """What AMBF (Bullet's ``calculateLocalInertia``) uses for a body without `inertia`: the box
    inertia of the collision shape's axis-aligned bounding box in the inertial frame. None
    when there is no collision shape or the geometry extra is not installed."""
    from ..adf.paths import collision_mesh_path
    from ..model.semantics import collision_primitives, inertial_offset

    com = inertial_offset(body).inverse()
    points = []
    prims = collision_primitives(body)
    if prims:
        for p in prims:
            g, k = p.geometry, p.kind.value
            if k == "box":
                h = ((g.x or 0) / 2, (g.y or 0) / 2, (g.z or 0) / 2)
            elif k == "sphere":
                h = ((g.radius or 0),) * 3
            elif k in ("cylinder", "capsule", "cone"):
                r, half = g.radius or 0, (g.height or 0) / 2
                axis = (g.axis or "z").lower()
                h = tuple(half if a == axis else r for a in "xyz")
            else:
                continue
            for sx in (-1, 1):
                for sy in (-1, 1):
                    for sz in (-1, 1):
                        points.append((com * p.pose).transform((sx * h[0], sy * h[1], sz * h[2])))
    elif prims is None:
        path = collision_mesh_path(model, body)
        if path is None or not inputs.is_regular(path):
            return None
        try:
            from ..geometry.meshio import load_mesh
        except ImportError:
            return None
        mesh = load_mesh(
            path,
            scale=body.scale if body.scale is not None else 1.0,
            tree=getattr(model, "tree", None),
            referrer=body.where("mesh"),
        )
        r = np.asarray(com.orientation.matrix())
        pts = np.asarray(mesh.vertices) @ r.T + np.asarray(com.position)
        points = pts.tolist()
    if not points:
        return None
    pts = np.asarray(points)
    lx, ly, lz = pts.max(axis=0) - pts.min(axis=0)
    return (mass / 12 * (ly * ly + lz * lz), mass / 12 * (lx * lx + lz * lz), mass / 12 * (lx * lx + ly * ly))
