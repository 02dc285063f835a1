"""The distance from points to a static tissue body's collision mesh as AMBF and PyBullet collide
it: its triangles (AMBF's default `collision mesh type`, CONCAVE_MESH: a ``btGImpactMeshShape``
per sub-mesh, ``afShapeUtils::createCollisionShape``; PyBullet's ``GEOM_FORCE_CONCAVE_TRIMESH``
for a static body), not their convex hull, which fills every channel and hole of a phantom
modelled as one mesh.

Own numpy, not ``trimesh.proximity``: that needs ``rtree`` (not a dependency of the project),
and the clearance asks for a few hundred points at a time against the triangles near them,
which a vectorised closest-point routine (Ericson, *Real-Time Collision Detection* §5.1.5)
answers in one pass. The distance is signed (negative inside) where the mesh is closed and
consistently wound, by the angle-weighted pseudo-normal of the nearest feature (face, edge or
vertex; Bærentzen and Aanæs 2005), which is exact for any point of a closed mesh; an open mesh
(a sheet) has no inside, in Bullet either, and its distance is unsigned. A file's connected
pieces are meshes of their own, the distance the least of theirs: a phantom exported as boxes
standing on a slab (each closed, the ridge's bottom face inside the slab's top) is their union,
whose inside the nearest triangle of them all does not tell (the ridge's inside read the slab's
top face beneath it, outside, 2.5 mm).
"""

from __future__ import annotations

import numpy as np

CHUNK = 400_000  # point-triangle pairs evaluated at a time (memory: ~30 arrays of this many)
MERGE = 1e-9  # m: vertices nearer than this are one (an OBJ may repeat a position per face)


def _fan(faces) -> list[list[int]]:
    return [[f[0], f[k], f[k + 1]] for f in faces for k in range(1, len(f) - 1)]


class TriangleMesh:
    """A mesh's triangles in the world, with what a signed distance needs."""

    def __init__(self, v: np.ndarray, f: np.ndarray) -> None:
        """``v``: vertices (N, 3), each once; ``f``: triangles (T, 3) as indices into them."""
        a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        n = np.cross(b - a, c - a)
        area2 = np.linalg.norm(n, axis=1)
        keep = (area2 > 1e-18) & (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
        f, n, area2 = f[keep], n[keep], area2[keep]
        self.a, self.b, self.c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        self.normal = n / area2[:, None]
        self.centre = (self.a + self.b + self.c) / 3
        self.reach = np.linalg.norm(np.stack([self.a, self.b, self.c]) - self.centre, axis=2).max(axis=0)
        self.closed = self._pseudo_normals(v, f)

    def _pseudo_normals(self, v: np.ndarray, f: np.ndarray) -> bool:
        """Per triangle, the pseudo-normals of its face, corners and edges (T, 7, 3: face, A, B,
        C, AB, BC, CA); whether the mesh is closed and consistently wound (every directed edge
        once, its reverse once), turned outward if it was wound inward."""
        t = len(f)
        directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])  # (3T, 2): AB, BC, CA
        keys = np.sort(directed, axis=1)
        _, edge, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
        edge = edge.reshape(-1)
        _, dcounts = np.unique(directed, axis=0, return_counts=True)
        closed = t > 0 and bool((counts == 2).all()) and bool((dcounts == 1).all())
        if not closed:
            self.pseudo = np.repeat(self.normal[:, None, :], 7, axis=1)
            return False
        # the signed volume: a mesh wound inward has every normal turned in
        if float(np.einsum("ij,ij->", self.a, np.cross(self.b, self.c))) < 0:
            self.normal = -self.normal
        en = np.zeros((counts.size, 3))
        np.add.at(en, edge, np.tile(self.normal, (3, 1)))
        corners = [self.a, self.b, self.c]
        vn = np.zeros((len(v), 3))
        for k in range(3):
            e1 = corners[(k + 1) % 3] - corners[k]
            e2 = corners[(k + 2) % 3] - corners[k]
            cos = (e1 * e2).sum(axis=1) / (np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1))
            np.add.at(vn, f[:, k], np.arccos(np.clip(cos, -1.0, 1.0))[:, None] * self.normal)
        pseudo = np.empty((t, 7, 3))
        pseudo[:, 0] = self.normal
        for k in range(3):
            pseudo[:, 1 + k] = vn[f[:, k]]
            pseudo[:, 4 + k] = en[edge[k * t : (k + 1) * t]]
        self.pseudo = pseudo
        return True

    def exact(self, pts: np.ndarray, near: np.ndarray, radius: float) -> np.ndarray:
        """The distance, m, from each point (M, 3) to the triangles within ``radius`` of ``near``
        (signed where the mesh is closed); ``radius`` where none is."""
        out = np.full(len(pts), radius)
        tris = np.flatnonzero(np.linalg.norm(self.centre - near, axis=1) < radius + self.reach)
        if not len(tris) or not len(pts):
            return out
        step = max(1, CHUNK // len(tris))
        for s in range(0, len(pts), step):
            out[s : s + step] = np.minimum(out[s : s + step], self._nearest(pts[s : s + step], tris))
        return out

    def _nearest(self, p: np.ndarray, tris: np.ndarray) -> np.ndarray:
        """Signed distance from points p (P, 3) to the triangles ``tris`` (their nearest)."""
        a, b, c = self.a[tris], self.b[tris], self.c[tris]
        ab, ac = b - a, c - a
        ap = p[:, None, :] - a[None]
        bp = p[:, None, :] - b[None]
        cp = p[:, None, :] - c[None]
        d1, d2 = (ab * ap).sum(axis=2), (ac * ap).sum(axis=2)
        d3, d4 = (ab * bp).sum(axis=2), (ac * bp).sum(axis=2)
        d5, d6 = (ab * cp).sum(axis=2), (ac * cp).sum(axis=2)
        va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
        with np.errstate(divide="ignore", invalid="ignore"):
            denom = va + vb + vc
            v = np.where(denom != 0, vb / denom, 0.0)
            w = np.where(denom != 0, vc / denom, 0.0)
            region = np.zeros(d1.shape, dtype=np.int8)  # the face, unless a rule below says otherwise
            # Ericson's tests, the first that holds wins: applied last to first
            bc = (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0)
            t_bc = np.where(bc, (d4 - d3) / ((d4 - d3) + (d5 - d6)), 0.0)
            region[bc] = 5
            v, w = np.where(bc, 1 - t_bc, v), np.where(bc, t_bc, w)
            ca = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
            t_ca = np.where(ca, d2 / (d2 - d6), 0.0)
            region[ca] = 6
            v, w = np.where(ca, 0.0, v), np.where(ca, t_ca, w)
            at_c = (d6 >= 0) & (d5 <= d6)
            region[at_c] = 3
            v, w = np.where(at_c, 0.0, v), np.where(at_c, 1.0, w)
            ab_ = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
            t_ab = np.where(ab_, d1 / (d1 - d3), 0.0)
            region[ab_] = 4
            v, w = np.where(ab_, t_ab, v), np.where(ab_, 0.0, w)
            at_b = (d3 >= 0) & (d4 <= d3)
            region[at_b] = 2
            v, w = np.where(at_b, 1.0, v), np.where(at_b, 0.0, w)
            at_a = (d1 <= 0) & (d2 <= 0)
            region[at_a] = 1
            v, w = np.where(at_a, 0.0, v), np.where(at_a, 0.0, w)
        gap = ap - v[:, :, None] * ab[None] - w[:, :, None] * ac[None]  # p less its closest point
        dist2 = (gap * gap).sum(axis=2)
        k = np.argmin(dist2, axis=1)
        rows = np.arange(len(p))
        d = np.sqrt(dist2[rows, k])
        if not self.closed:
            return d
        normal = self.pseudo[tris[k], region[rows, k]]
        inside = (gap[rows, k] * normal).sum(axis=1) < 0
        return np.where(inside, -d, d)


class TriangleMeshes:
    """The connected pieces of a mesh, each a TriangleMesh: the distance is the least of theirs."""

    def __init__(self, vertices: np.ndarray, faces: np.ndarray) -> None:
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        key = np.round(vertices / MERGE).astype(np.int64)
        _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
        v, f = vertices[first], inverse.reshape(-1)[faces]
        edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]]])
        graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(len(v), len(v)))
        _, label = connected_components(graph, directed=False)
        part = label[f[:, 0]]
        parts = [TriangleMesh(v, f[part == k]) for k in np.unique(part)]
        self.parts = [m for m in parts if len(m.a)]  # a piece of degenerate triangles only is none
        self.centre = np.array([m.centre.mean(axis=0) for m in self.parts]).reshape(-1, 3)
        self.reach = np.array(
            [np.linalg.norm(m.centre - c, axis=1).max() + m.reach.max() for m, c in zip(self.parts, self.centre)]
        )

    @property
    def closed(self) -> bool:
        return all(m.closed for m in self.parts)

    def exact(self, pts: np.ndarray, near: np.ndarray, radius: float) -> np.ndarray:
        """The least of the pieces' distances (TriangleMesh.exact) from each point (M, 3)."""
        out = np.full(len(pts), radius)
        for k in np.flatnonzero(np.linalg.norm(self.centre - near, axis=1) < radius + self.reach):
            out = np.minimum(out, self.parts[k].exact(pts, near, radius))
        return out


def obj_triangles(path, scale: float, world: np.ndarray) -> TriangleMeshes | None:
    """Every triangle of an OBJ file (all its objects: one triangle mesh, as the engines make
    a static concave body), scaled and placed by ``world`` (4x4); None when it has none or
    names a vertex it lacks (the engines do not make the body)."""
    from ..geometry.objpieces import obj_pieces

    with open(path, encoding="utf-8", errors="replace") as fh:
        try:
            pieces = obj_pieces(fh.read())
        except ValueError:
            return None
    verts, faces = [], []
    base = 0
    for v, fs in pieces:
        try:
            verts.append(np.array(v, dtype=float).reshape(-1, 3))
        except ValueError:
            return None
        faces += [[base + i for i in t] for t in _fan(fs)]
        base += len(v)
    if not faces:
        return None
    v = np.concatenate(verts) * scale
    v = v @ world[:3, :3].T + world[:3, 3]
    mesh = TriangleMeshes(v, np.array(faces, dtype=np.int64))
    return mesh if mesh.parts else None
