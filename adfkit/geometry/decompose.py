"""Convex decomposition with CoACD, deterministic for a seed, cached by content.

How a decomposition maps onto ADF (adf-format.md §7.4): ``compound collision shape`` only
holds primitives, so hulls go into ONE OBJ file with one object/group and one material per
hull, referenced as the body's ``collision mesh`` with ``collision mesh type: CONVEX_HULL``.
AMBF makes one child shape per sub-mesh, so every hull becomes its own btConvexHullShape.
This is the layout of the corpus' own ``NeedleCollision.OBJ`` and ``PhantomCollision.OBJ``.

Cache: ``$ADFKIT_CACHE/coacd`` or ``~/.cache/adfkit/coacd``; the key is a SHA-256 of the
repaired mesh's vertex and face bytes, the parameters and the CoACD version.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import time
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

import manifold3d
import numpy as np
import trimesh

from ..scratch import temp_beside
from .repair import from_manifold

#: Number of times CoACD itself ran in this process (the cache skips it).
COACD_CALLS = 0


@dataclass(frozen=True)
class DecompositionParams:
    threshold: float = 0.05  # CoACD concavity threshold (smaller = more, tighter hulls)
    max_hulls: int = 16  # upper bound on the hull count (-1: no bound)
    preprocess_resolution: int = 30  # manifold pre-processing voxel resolution
    resolution: int = 1000  # sampling resolution of the concavity metric
    mcts_iterations: int = 60
    mcts_nodes: int = 10
    mcts_max_depth: int = 3
    preprocess: str = "auto"  # CoACD's own manifold pre-pass: auto, on, off
    merge: bool = True
    seed: int = 0


@dataclass
class Decomposition:
    hulls: list[trimesh.Trimesh]
    params: DecompositionParams
    key: str
    cache_hit: bool
    seconds: float

    @property
    def volumes(self) -> list[float]:
        return [float(h.volume) for h in self.hulls]


def cache_dir() -> Path:
    base = os.environ.get("ADFKIT_CACHE")
    root = Path(base) if base else Path.home() / ".cache" / "adfkit"
    return root / "coacd"


def _coacd_version() -> str:
    try:
        return metadata.version("coacd")
    except metadata.PackageNotFoundError:  # pragma: no cover
        return "unknown"


def cache_key(mesh: trimesh.Trimesh, params: DecompositionParams) -> str:
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(mesh.vertices, dtype="<f8").tobytes())
    h.update(np.ascontiguousarray(mesh.faces, dtype="<i8").tobytes())
    h.update(json.dumps(dataclasses.asdict(params), sort_keys=True).encode())
    h.update(_coacd_version().encode())
    return h.hexdigest()


def _read_cache(path: Path) -> list[trimesh.Trimesh] | None:
    try:
        with np.load(path) as data:
            verts, faces = data["vertices"], data["faces"]
            vsplit, fsplit = data["vertex_counts"], data["face_counts"]
    except (OSError, KeyError, ValueError):
        return None  # a missing or damaged entry is recomputed
    hulls, v0, f0 = [], 0, 0
    for nv, nf in zip(vsplit, fsplit):
        hulls.append(trimesh.Trimesh(verts[v0 : v0 + nv], faces[f0 : f0 + nf], process=False))
        v0, f0 = v0 + nv, f0 + nf
    return hulls


def _write_cache(path: Path, hulls: list[trimesh.Trimesh]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = temp_beside(path, ".tmp.npz")
    os.close(fd)
    try:
        np.savez(
            tmp,
            vertices=np.concatenate([h.vertices for h in hulls]),
            faces=np.concatenate([h.faces for h in hulls]),
            vertex_counts=np.array([len(h.vertices) for h in hulls]),
            face_counts=np.array([len(h.faces) for h in hulls]),
        )
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _run_coacd(mesh: trimesh.Trimesh, p: DecompositionParams) -> list[trimesh.Trimesh]:
    global COACD_CALLS
    import coacd

    coacd.set_log_level("error")
    COACD_CALLS += 1
    parts = coacd.run_coacd(
        coacd.Mesh(np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int32)),
        threshold=p.threshold,
        max_convex_hull=p.max_hulls,
        preprocess_mode=p.preprocess,
        preprocess_resolution=p.preprocess_resolution,
        resolution=p.resolution,
        mcts_nodes=p.mcts_nodes,
        mcts_iterations=p.mcts_iterations,
        mcts_max_depth=p.mcts_max_depth,
        merge=p.merge,
        seed=p.seed,
    )
    hulls = []
    for verts, _faces in parts:
        # Re-hull with manifold3d: CoACD's hull triangles can carry slivers that fail a strict
        # convexity check; the hull of its vertices is the same solid, closed and convex.
        solid = manifold3d.Manifold.hull_points(np.ascontiguousarray(verts, dtype=np.float64))
        if solid.volume() > 0:
            hulls.append(from_manifold(solid))
    return hulls


def decompose(
    mesh: trimesh.Trimesh, params: DecompositionParams | None = None, use_cache: bool = True
) -> Decomposition:
    """Convex hulls of ``mesh`` (closed; run ``repair_mesh`` first) by CoACD."""
    params = params or DecompositionParams()
    start = time.perf_counter()
    key = cache_key(mesh, params)
    path = cache_dir() / key[:2] / f"{key}.npz"
    if use_cache and path.is_file():
        hulls = _read_cache(path)
        if hulls:
            return Decomposition(hulls, params, key, True, time.perf_counter() - start)
    hulls = _run_coacd(mesh, params)
    if use_cache:
        try:
            _write_cache(path, hulls)
        except OSError:
            pass  # a read-only cache only costs time
    return Decomposition(hulls, params, key, False, time.perf_counter() - start)


def hull_color(i: int, n: int) -> tuple[float, float, float]:
    """Distinct colours around the hue circle (golden-ratio steps)."""
    import colorsys

    return colorsys.hsv_to_rgb((i * 0.618033988749895) % 1.0, 0.65, 0.95)


def hulls_obj_text(hulls: list[trimesh.Trimesh], mtl_name: str, prefix: str = "hull") -> tuple[str, str]:
    """(OBJ text, MTL text): one object, group and material per hull."""
    obj = [f"# {len(hulls)} convex hulls written by adfkit", f"mtllib {mtl_name}"]
    mtl = [f"# materials for {len(hulls)} convex hulls"]
    from .meshwrite import obj_faces

    base = 1
    for i, h in enumerate(hulls):
        name = f"{prefix}_{i:03d}"
        r, g, b = hull_color(i, len(hulls))
        mtl += [f"newmtl {name}", f"Kd {r:.4f} {g:.4f} {b:.4f}", "Ka 0 0 0", "Ks 0 0 0", "d 1", ""]
        obj += [f"o {name}", f"g {name}", f"usemtl {name}"]
        obj += [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in h.vertices]
        normals, faces = obj_faces(h.vertices, h.faces, v_base=base)  # full triplets: AMBF reads them
        obj += normals + faces
        base += len(h.vertices)
    return "\n".join(obj) + "\n", "\n".join(mtl)


def write_hulls_obj(hulls: list[trimesh.Trimesh], path: str | os.PathLike) -> tuple[Path, Path]:
    """Write hulls to ``path`` (.obj) and its .mtl beside it, atomically. Returns both paths."""
    from ..adf import atomic_write_text

    path = Path(path)
    mtl_path = path.with_suffix(".mtl")
    obj_text, mtl_text = hulls_obj_text(hulls, mtl_path.name)
    atomic_write_text(mtl_path, mtl_text)
    atomic_write_text(path, obj_text)
    return path, mtl_path


def write_hull_files(hulls: list[trimesh.Trimesh], directory: str | os.PathLike, stem: str) -> list[Path]:
    """One OBJ per hull (``stem_000.obj`` ...), for tools that want separate files."""
    out = []
    for i, h in enumerate(hulls):
        p = Path(directory) / f"{stem}_{i:03d}.obj"
        text, _ = hulls_obj_text([h], p.with_suffix(".mtl").name, prefix=stem)
        from ..adf import atomic_write_text

        atomic_write_text(p, "\n".join(l for l in text.splitlines() if not l.startswith(("mtllib", "usemtl"))) + "\n")
        out.append(p)
    return out


def load_hulls(path: str | os.PathLike) -> list[trimesh.Trimesh]:
    """The sub-meshes of a hull OBJ, one per object, as AMBF sees them."""
    scene = trimesh.load(str(path), force="scene", process=False, group_material=False)
    return [g for g in scene.geometry.values() if isinstance(g, trimesh.Trimesh)]


def apply_to_body(body, obj_file_name: str) -> None:
    """Point ``body``'s collision at a hull OBJ written by ``write_hulls_obj`` (§7.4)."""
    body.collision_mesh = obj_file_name
    body.collision_mesh_type = "CONVEX_HULL"
    body.collision_shape = None
    body.collision_geometry = None
    body.compound_collision_shape = None
