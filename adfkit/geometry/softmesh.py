"""Soft-body meshes: the nodes and triangles AMBF builds a btSoftBody from, and a reader
for 3D Studio (.3DS) files, the format of the corpus cloth (sb/low_res/cloth.3DS).

AMBF (afSoftBody::cleanupMesh) loads the collision mesh with CHAI3D and merges repeated
vertices before creating the soft body, so a soft body's nodes are the mesh's *unique*
vertex positions; `fixed nodes` index them. We keep them in order of first appearance
(AMBF's sequential variant; its block-sorted variant may number them differently, see
docs/soft-bodies.md). numpy only: the validator calls this too.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..diagnostics import AdfError, error
from .format3ds import OBJECT, VERTICES, empty, unreadable, walk_3ds
from .softnodes import MERGE_DECIMALS


@dataclass
class SoftMesh:
    nodes: np.ndarray  # (n, 3) float64, unique vertex positions, metres (times scale)
    triangles: np.ndarray  # (m, 3) int64, node indices

    @property
    def node_count(self) -> int:
        return len(self.nodes)


def read_3ds(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of every triangle object in a .3DS file, concatenated.

    Vertices are taken as stored (3DS keeps them in the scene frame; the object's local
    matrix is not applied, as CHAI3D does not either)."""
    data = Path(path).read_bytes()
    verts: list[np.ndarray] = []
    faces: list[np.ndarray] = []
    base = 0
    for cid, n, at in walk_3ds(path, data):
        if cid == OBJECT:  # an object's faces index its own vertices
            base = sum(len(v) for v in verts)
        elif cid == VERTICES:
            verts.append(np.frombuffer(data, "<f4", n * 3, at).reshape(n, 3).astype(np.float64))
        else:
            faces.append(np.frombuffer(data, "<u2", n * 4, at).reshape(n, 4)[:, :3].astype(np.int64) + base)
    return np.concatenate(verts), np.concatenate(faces)


def _raw_triangles(path: Path) -> tuple[np.ndarray, np.ndarray]:
    if path.suffix.lower() == ".3ds":
        return read_3ds(path)
    import trimesh  # noqa: PLC0415 - heavy, only for formats numpy cannot read

    try:
        loaded = trimesh.load(str(path), force="mesh", process=False, skip_materials=True)
    except Exception as exc:  # trimesh raises many types for bad input
        raise unreadable(path, f"cannot read mesh: {type(exc).__name__}: {exc}", "is this a valid mesh file?") from None
    return np.asarray(loaded.vertices, dtype=np.float64), np.asarray(loaded.faces, dtype=np.int64)


def unique_nodes(vertices: np.ndarray, faces: np.ndarray) -> SoftMesh:
    """Merge vertices at the same position (first appearance keeps the lowest index);
    drop triangles that collapse."""
    key = np.round(vertices, MERGE_DECIMALS)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    order = np.argsort(first)  # unique rows in order of first appearance
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    nodes = vertices[first[order]]
    tris = rank[inverse[faces]]
    ok = (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 0] != tris[:, 2])
    return SoftMesh(nodes, tris[ok])


def nodes_at(mesh: SoftMesh, points, tol: float = 1e-6) -> list[int]:
    """Node indices of the nodes at ``points`` (n × 3, the mesh's frame, within ``tol``):
    how an editor turns selected vertices (a Blender vertex group) into `fixed nodes`.
    Raises ValueError naming the first point no node is at."""
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    out: list[int] = []
    for p in pts:
        d = np.linalg.norm(mesh.nodes - p, axis=1)
        i = int(np.argmin(d)) if len(d) else -1
        if i < 0 or d[i] > tol:
            raise ValueError(f"no node at {p.tolist()}")
        if i not in out:
            out.append(i)
    return sorted(out)


def load_soft_mesh(path: str | os.PathLike, scale: float = 1.0, tree=None) -> SoftMesh:
    """The soft body AMBF makes of a collision mesh file: unique nodes (times ``scale``) and
    triangles. Raises AdfError (mesh-not-found, mesh-unreadable, mesh-empty, or an input-policy
    rule of adfkit.inputs: bad-path, not-a-regular-file, file-too-large, outside-tree when
    ``tree``, the naming ADF file's tree, is given)."""
    from .. import inputs  # noqa: PLC0415

    p = inputs.check_mesh(path, tree=tree)
    v, f = _raw_triangles(p)
    if len(v) == 0 or len(f) == 0:
        raise empty(p)
    if f.min() < 0 or f.max() >= len(v):
        raise unreadable(p, "a triangle refers to a vertex the file does not hold", "re-export the mesh")
    mesh = unique_nodes(v, f)
    mesh.nodes = mesh.nodes * float(scale)
    return mesh


def placed_soft_mesh(model, sb) -> SoftMesh:
    """The soft body's nodes in the world: its collision mesh (adf-format.md §6.2) times
    `scale`, moved by `location`. Raises AdfError when there is no mesh or it cannot be read."""
    from ..adf.paths import collision_mesh_path  # noqa: PLC0415

    path = collision_mesh_path(model, sb) if sb.mesh else None
    if path is None:
        raise AdfError(
            error(
                "mesh-not-found",
                f"soft body '{sb.identifier}' names no mesh",
                sb.where(),
                "AMBF builds soft bodies from their collision mesh; name one with `mesh`",
            )
        )
    mesh = load_soft_mesh(path, sb.scale or 1.0, tree=getattr(model, "tree", None))
    if sb.location is not None:
        rot = np.array(sb.location.orientation.matrix())
        mesh.nodes = mesh.nodes @ rot.T + np.array([*sb.location.position])
    return mesh


DEFAULT_SOFT_MASS = 1.0  # AMBF's when `mass` is missing


def link_stiffness(sb, nodes: int, dt: float) -> float:
    """A spring stiffness (N/m) standing for Bullet's position-based links: each of
    `piterations` (default 1) moves a link a share `kLST` (default 1) of the way back to its
    rest length, so one step removes 1 − (1 − kLST)^piterations of a stretch; a spring on a
    node of mass m removes the same share in one step of ``dt`` when k = share·m/dt²."""
    cfg = sb.config
    klst = cfg.kLST if cfg is not None and cfg.kLST is not None else 1.0
    pit = cfg.piterations if cfg is not None and cfg.piterations is not None else 1
    mass = sb.mass if sb.mass is not None and sb.mass > 0 else DEFAULT_SOFT_MASS
    share = 1.0 - (1.0 - min(max(klst, 0.0), 1.0)) ** max(pit, 1)
    return share * (mass / max(nodes, 1)) / dt**2


def write_obj(mesh: SoftMesh, path: str | os.PathLike) -> Path:
    """The nodes and triangles as a plain OBJ (what PyBullet's loadSoftBody reads)."""
    p = Path(path)
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in mesh.nodes]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in mesh.triangles]
    p.write_text("\n".join(lines) + "\n", encoding="ascii")
    return p


__all__ = [
    "SoftMesh",
    "read_3ds",
    "unique_nodes",
    "nodes_at",
    "load_soft_mesh",
    "placed_soft_mesh",
    "link_stiffness",
    "write_obj",
    "DEFAULT_SOFT_MASS",
]
