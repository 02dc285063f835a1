"""A moving concave mesh as convex parts that keep its hollows.

AMBF collides a mesh whose `collision mesh type` is CONCAVE_MESH (its default) as the triangles
themselves (one btGImpactMeshShape per sub-mesh), on moving bodies too. PyBullet cannot collide a
moving triangle mesh and MuJoCo collides every mesh as its convex hull, so an engine here takes
the hull of each sub-mesh, which fills the mesh's hollows: puzzle1's Torus's hull fills its hole
and starts inside its peg. A sub-mesh that fills less than ``HULL_FILL`` of its hull is played
as convex parts instead: each connected piece of it that fills at least ``HULL_FILL`` of its own
hull as that hull (the peg and the slab of puzzle1's PegBase, one sub-mesh of two pieces), each
other piece decomposed by CoACD (``geometry.decompose``, cached on disk by content, so only the
first run pays). Every engine and writer asks ``convex_parts``, so all make the same decision.
"""

from __future__ import annotations

import os
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from .. import inputs, scratch
from ..diagnostics import AdfError

#: CoACD's settings for a stand-in: coarser and about three times faster than `adfkit decompose`'s
#: (a concavity of 0.1 of the piece's size, at most 8 parts, a shallower search): puzzle1's Torus
#: in 8 parts in 0.5 s (13 in 1.9 s), the KUKA's link4 in 11 s (36 s); its ring's hole keeps
#: room for the peg (8 chords take 9 mm of its 120 mm radius; the peg's is 90 mm)
STAND_IN = dict(threshold=0.1, max_hulls=8, mcts_iterations=20, mcts_max_depth=2, resolution=500)

#: a sub-mesh (or a connected piece of one) filling less than this share of its convex hull's
#: volume is a poor stand-in for the triangles AMBF collides: decomposed. puzzle1's Torus fills
#: 0.67 of its hull, its PegBase 0.18 (a slab and a peg), the KUKA's links 0.70-0.99
HULL_FILL = 0.8


@dataclass
class ConvexParts:
    """What stands in for a moving concave mesh: convex ``hulls`` in the mesh file's frame
    (unscaled), ``fill``: the smallest share of its hull any sub-mesh fills, ``decomposed``:
    the pieces CoACD decomposed, ``coacd_s``: CoACD's time (0 when every piece came from the
    cache)."""

    hulls: list[trimesh.Trimesh]
    fill: float
    decomposed: int
    coacd_s: float

    def describe(self) -> str:
        how = f", {self.decomposed} piece{'s' * (self.decomposed != 1)} of it by CoACD" if self.decomposed else ""
        return f"fills {self.fill:.0%} of its convex hull: collided as {len(self.hulls)} convex parts{how}"


def _hull(mesh: trimesh.Trimesh) -> trimesh.Trimesh | None:
    """The mesh's convex hull, or None where it has no volume (flat, a lone triangle)."""
    try:
        hull = mesh.convex_hull
    except Exception:  # noqa: BLE001 - qhull refuses flat and degenerate point sets, each its own way
        return None
    volume = float(hull.volume)
    return hull if np.isfinite(volume) and volume > 0 else None


def hull_fill(mesh: trimesh.Trimesh) -> float:
    """The share of its convex hull's volume ``mesh`` fills: its volume closed by
    ``repair_mesh`` where it can be, else the volume trimesh reads from the open surface (its
    faces wound one way). 1.0 for a mesh without volume (flat: its hull is no better)."""
    from .repair import repair_mesh

    hull = _hull(mesh)
    if hull is None:
        return 1.0
    try:
        solid, _ = repair_mesh(mesh)
        volume = float(solid.volume)
    except AdfError:
        work = mesh.copy()
        trimesh.repair.fix_winding(work)
        volume = abs(float(work.volume))
    return min(volume / float(hull.volume), 1.0)


def _sub_meshes(path: Path, tree) -> list[trimesh.Trimesh]:
    """The mesh's sub-meshes as AMBF makes them (an OBJ's objects and materials:
    geometry.objpieces), vertices shared where they coincide."""
    from .meshio import load_mesh
    from .objpieces import obj_pieces

    if path.suffix.lower() == ".obj":
        try:
            pieces = obj_pieces(inputs.read_text(path, "mesh", tree=tree, what="mesh file"))
        except ValueError:
            pieces = []
        if len(pieces) > 1:
            out = []
            for verts, faces in pieces:
                m = trimesh.Trimesh(np.array(verts, dtype=float), np.array(_fan(faces), dtype=np.int64), process=False)
                m.merge_vertices()
                out.append(m)
            return out
    mesh = load_mesh(path, tree=tree)
    return [mesh]


def _fan(faces: list[list[int]]) -> list[list[int]]:
    """Polygons as triangles (a fan from each polygon's first corner)."""
    return [[f[0], f[i], f[i + 1]] for f in faces for i in range(1, len(f) - 1)]


_DONE: dict[tuple[str, int, int], ConvexParts | None] = {}


def convex_parts(path: Path, tree=None, label: str = "", progress: bool | None = None) -> ConvexParts | None:
    """The convex parts to collide a moving concave mesh file as, or None where each of its
    sub-meshes fills at least ``HULL_FILL`` of its hull (its hull stands in well, as before).
    ``label`` names the mesh on the progress line CoACD's runs show on a terminal. Raises
    AdfError for a mesh that cannot be read (the caller has checked it can)."""
    st = path.stat()
    key = (str(path), st.st_size, st.st_mtime_ns)
    if key not in _DONE:
        _DONE[key] = _measure(path, tree, label or path.name, progress)
    return _DONE[key]


def _measure(path: Path, tree, label: str, progress: bool | None) -> ConvexParts | None:
    """The parts, or None where each sub-mesh fills ``HULL_FILL`` of its hull. A piece without
    volume (flat, a stray triangle) in a sub-mesh that is decomposed has no part."""
    subs = _sub_meshes(path, tree)
    fills = [hull_fill(s) for s in subs]
    if min(fills) >= HULL_FILL:
        return None
    todo: list[tuple[trimesh.Trimesh | None, trimesh.Trimesh]] = []  # (piece to decompose or None, its hull)
    for sub, fill in zip(subs, fills):
        for piece in sub.split(only_watertight=False) if fill < HULL_FILL and sub.body_count > 1 else [sub]:
            if (hull := _hull(piece)) is not None:
                todo.append((None if hull_fill(piece) >= HULL_FILL else piece, hull))
    return _decompose(todo, min(fills), label, progress)


def _decompose(todo, fill: float, label: str, progress: bool | None) -> ConvexParts:
    from ..report import Progress
    from .decompose import DecompositionParams, decompose
    from .repair import repair_mesh

    hulls: list[trimesh.Trimesh] = []
    n = sum(1 for piece, _ in todo if piece is not None)
    bar = Progress(n, f"decomposing {label} (CoACD, cached)", enabled=progress)
    spent = 0.0
    for piece, hull in todo:
        if piece is None:
            hulls.append(hull)
            continue
        bar.update(0, suffix=f"{len(hulls)} parts so far")
        try:  # a piece closed by repair as it is (exact); an open one through CoACD's manifold pre-pass
            solid, _ = repair_mesh(piece)
            params = DecompositionParams(preprocess="off", **STAND_IN)
        except AdfError:
            solid, params = piece, DecompositionParams(preprocess="on", **STAND_IN)
        t0 = time.perf_counter()
        result = decompose(solid, params)
        if not result.cache_hit:
            spent += time.perf_counter() - t0
        hulls += _within(result.hulls, hull) or [hull]
        bar.update(1, suffix=f"{len(hulls)} parts")
    if n:
        bar.stream.write("\r\x1b[K" if bar.enabled else "")
    return ConvexParts(hulls, fill, n, spent)


def _within(parts: list[trimesh.Trimesh], hull: trimesh.Trimesh) -> list[trimesh.Trimesh]:
    """Each part cut to the piece's own hull: CoACD's manifold pre-pass (an open piece) remeshes
    it on a voxel grid and grows it by up to a voxel (14 mm of puzzle1's 0.65 m PuzzleBase, which
    then rested that much higher); what stands outside the piece's hull is no part of it."""
    import manifold3d

    from .repair import from_manifold

    bound = manifold3d.Manifold.hull_points(np.ascontiguousarray(hull.vertices, dtype=np.float64))
    out = []
    for p in parts:
        cut = manifold3d.Manifold.hull_points(np.ascontiguousarray(p.vertices, dtype=np.float64)) ^ bound
        if cut.volume() > 0:
            out.append(from_manifold(cut.hull()))  # (the cut's own triangles may split a face)
    return out


# by the parts' id, each kept with its parts: a dead object's id, reused by a new one, found
# the other's file (the tests that swap _DONE out free theirs)
_FILES: dict[int, tuple[ConvexParts, Path]] = {}


def parts_obj(parts: ConvexParts) -> Path:
    """The parts as one OBJ file in the scratch folder, one object per part (PyBullet makes a
    hull of each OBJ object; the MJCF and URDF writers split it into a file per part)."""
    from .decompose import hulls_obj_text

    kept = _FILES.get(id(parts))
    made = kept[1] if kept is not None and kept[0] is parts else None
    if made is None or not made.exists():
        text, _ = hulls_obj_text(parts.hulls, "", prefix="part")
        fd, name = tempfile.mkstemp(prefix="parts_", suffix=".obj", dir=scratch.scratch_dir())
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write("\n".join(ln for ln in text.splitlines() if not ln.startswith(("mtllib", "usemtl"))) + "\n")
        made = Path(name)
        _FILES[id(parts)] = (parts, made)
    return made


def body_parts(model, body, progress: bool | None = None) -> ConvexParts | None:
    """``convex_parts`` for a moving body (mass > 0) whose collision mesh AMBF keeps concave
    (``model.semantics.concave_mesh``); None for any other body or object, and for a mesh that
    cannot be read (each engine and writer says why where it reads the mesh)."""
    from ..adf.paths import collision_mesh_path
    from ..model import Body
    from ..model.semantics import concave_mesh, effective_mass

    if not isinstance(body, Body) or effective_mass(body) <= 0 or not concave_mesh(body):
        return None
    path = collision_mesh_path(model, body)
    if path is None:
        return None
    tree = getattr(model, "tree", None)
    try:
        inputs.check_file(path, "mesh", tree=tree, what="mesh file")
        return convex_parts(path, tree, f"{body.identifier}'s {path.name}", progress)
    except (AdfError, OSError, ValueError):
        return None
