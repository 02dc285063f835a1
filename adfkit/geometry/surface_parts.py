"""A volume's iso-surface cut to fit an engine, with the contact kept at the surface.

Neither engine takes a real skull's surface whole: PyBullet refuses a mesh of more than 131,072
vertices or 524,288 indices (``createCollisionShape failed``; measured: 131,072 vertices pass,
131,073 fail), MuJoCo's STL reader more than 200,000 faces, and MuJoCo collides any mesh as its
convex hull, which fills every cavity of a bone. So:

- :func:`split_surface` cuts the triangles into pieces under a vertex and a face limit (halving
  along the longest side of the piece's box at the median centroid), every triangle in exactly
  one piece: PyBullet collides with each piece as a concave triangle mesh, so the contact is on
  the surface itself; the converters write pieces MuJoCo's STL reader loads.
- :func:`convex_parts` gives, for MuJoCo, one point set per block of ``block``³ voxels that the
  surface crosses (the surface's vertices in the block, its triangles' corners reaching a
  little past it, and the solid voxel centres inside it); the convex hull of each is a part,
  so the contact is on the surface up to concavities smaller than a block.
"""

from __future__ import annotations

import numpy as np

#: PyBullet's limits for a mesh given as arrays (createCollisionShape / createVisualShape)
PYBULLET_MAX_VERTICES = 131_072
PYBULLET_MAX_FACES = 524_288 // 3
#: MuJoCo's STL reader
MUJOCO_STL_MAX_FACES = 200_000
#: voxels per side of a MuJoCo convex part
PART_BLOCK = 8


def _reindex(verts: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    used, inverse = np.unique(faces.ravel(), return_inverse=True)
    return verts[used], inverse.reshape(-1, 3).astype(faces.dtype)


def split_surface(
    verts: np.ndarray, faces: np.ndarray, max_vertices: int, max_faces: int
) -> list[tuple[np.ndarray, np.ndarray]]:
    """(vertices, faces) pieces of a triangle mesh, each within both limits."""
    verts, faces = np.asarray(verts), np.asarray(faces)
    if len(faces) == 0:
        return []
    centroids = verts[faces].mean(axis=1)
    mark = np.zeros(len(verts), dtype=bool)
    out: list[tuple[np.ndarray, np.ndarray]] = []
    stack = [np.arange(len(faces))]
    while stack:
        idx = stack.pop()
        sub = faces[idx]
        n_verts = max_vertices + 1
        if len(sub) <= max_faces:
            mark[sub.ravel()] = True
            n_verts = int(np.count_nonzero(mark))
            mark[sub.ravel()] = False
        if n_verts <= max_vertices or len(idx) < 2:
            out.append(_reindex(verts, sub))
            continue
        c = centroids[idx]
        axis = int(np.argmax(c.max(axis=0) - c.min(axis=0)))
        half = len(idx) // 2
        part = np.argpartition(c[:, axis], half)
        stack += [idx[part[half:]], idx[part[:half]]]
    return out


def convex_parts(
    verts: np.ndarray,
    faces: np.ndarray,
    solid: np.ndarray,
    dimensions: np.ndarray,
    block: int = PART_BLOCK,
) -> list[np.ndarray]:
    """Point sets, one per block of ``block``³ voxels the surface crosses, whose convex hulls
    cover the surface (``verts``/``faces`` in the volume frame, metres) and the solid behind it
    (``solid``: (slices, rows, columns) bool). A block whose points are flat is thickened by
    half a voxel either side."""
    verts, faces = np.asarray(verts, dtype=float), np.asarray(faces)
    if len(faces) == 0:
        return []
    dims = np.asarray(dimensions, dtype=float)
    n, rows, cols = solid.shape
    step = dims / np.array([cols, rows, n])  # x, y, z
    size = step * block
    nb = np.maximum(1, -(-np.array([cols, rows, n]) // block))
    centroid = verts[faces].mean(axis=1)
    cell = np.clip(((centroid + dims / 2) // size).astype(int), 0, nb - 1)
    key = (cell[:, 2] * nb[1] + cell[:, 1]) * nb[0] + cell[:, 0]
    order = np.argsort(key, kind="stable")
    keys, starts = np.unique(key[order], return_index=True)
    bounds = [*starts[1:], len(order)]
    out = []
    for k, a, b in zip(keys, starts, bounds):
        bx = int(k % nb[0])
        by = int((k // nb[0]) % nb[1])
        bz = int(k // (nb[0] * nb[1]))
        pts = [verts[np.unique(faces[order[a:b]].ravel())]]
        sub = solid[bz * block : (bz + 1) * block, by * block : (by + 1) * block, bx * block : (bx + 1) * block]
        kz, ky, kx = np.nonzero(sub)
        if len(kz):
            ijk = np.stack([kx + bx * block, ky + by * block, kz + bz * block], axis=1)
            pts.append((ijk + 0.5) * step - dims / 2)
        p = np.concatenate(pts)
        centred = p - p.mean(axis=0)
        _, sv, vt = np.linalg.svd(centred, full_matrices=False)
        if len(p) < 4 or sv[-1] < 1e-3 * float(step.min()) * np.sqrt(len(p)):
            normal = vt[-1] * float(step.min()) / 2
            p = np.concatenate([p + normal, p - normal])
        out.append(p)
    return out


def hull_vertices(points: np.ndarray) -> np.ndarray:
    """The vertices of the convex hull of ``points`` (all of them when qhull cannot make one)."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        return points[ConvexHull(points).vertices]
    except (QhullError, ValueError):
        return points


__all__ = [
    "MUJOCO_STL_MAX_FACES",
    "PART_BLOCK",
    "PYBULLET_MAX_FACES",
    "PYBULLET_MAX_VERTICES",
    "convex_parts",
    "hull_vertices",
    "split_surface",
]
