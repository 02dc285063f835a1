"""Which mesh files PyBullet is given as they are, which are converted first (trimesh), and which
are refused with a reason (too large, unreadable, a binary STL whose size lies)."""

from __future__ import annotations

import contextlib
import itertools
import os
from pathlib import Path

import numpy as np

from ... import inputs, scratch
from ...adf.paths import collision_mesh_path, visual_mesh_path
from ...diagnostics import AdfError
from ...geometry.meshcheck import obj_material_problems
from ..plan import mesh_refusal
from .egl import quiet_stdout

MESH_SUFFIXES = {".obj", ".stl"}  # what PyBullet's GEOM_MESH reads from a file


_MADE = itertools.count()  # numbers the files made in the scratch folder
_STL_CACHE: dict[tuple[str, int, int], tuple[str | None, str | None]] = {}


def pybullet_mesh(model, path: Path) -> tuple[Path | None, str | None]:
    """The file to hand PyBullet for a mesh, or (None, why not).

    PyBullet reads only binary STL, and crashes (SIGSEGV) on an ASCII or malformed STL, or on
    NaN vertices: an STL that is not a consistent binary STL with finite vertices is read with
    trimesh (as AMBF's assimp would) and handed over as a temporary binary STL; one trimesh
    cannot read either is refused like a missing mesh."""
    refused = mesh_refusal(model, path)
    if refused is not None:
        return None, refused
    if path.suffix.lower() != ".stl":
        return path, None
    st = path.stat()
    key = (str(path), st.st_size, st.st_mtime_ns)
    if key not in _STL_CACHE or not _still_there(_STL_CACHE[key][0]):
        _STL_CACHE[key] = _checked_stl(path, st.st_size)
    done, why = _STL_CACHE[key]
    return (Path(done) if done else None), why


def _checked_stl(path: Path, size: int) -> tuple[str | None, str | None]:
    with open(path, "rb") as fh:
        head = fh.read(84)
        count = int.from_bytes(head[80:84], "little") if len(head) == 84 else -1
        if count > 0 and size == 84 + 50 * count and not head.lstrip().startswith(b"solid"):
            records = np.frombuffer(fh.read(), dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", 9), ("a", "<u2")]))
            if np.isfinite(records["v"]).all():
                return str(path), None
            return None, f"{inputs.shown(path)} has NaN or infinite vertices"
    from ...geometry.meshio import load_mesh  # trimesh: only for meshes PyBullet cannot take as they are

    try:
        mesh = load_mesh(path)
    except AdfError as exc:
        return None, f"{inputs.shown(path)} is not a readable mesh ({exc.diagnostics[0].message})"
    out = os.path.join(scratch.scratch_dir(), f"mesh_{next(_MADE)}.stl")
    mesh.export(out, file_type="stl")
    return out, None


_HULL_CACHE: dict[tuple[str, int, int], Path] = {}


def _still_there(made) -> bool:
    """A cached file is still there (the scratch folder it was made in goes when a command ends)."""
    return made is None or os.path.exists(made)


def hull_pieces(path: Path, tree=None) -> Path:
    """The OBJ to hand PyBullet for convex hulls. PyBullet makes one hull per OBJ object, AMBF
    one per sub-mesh, of which its mesh loader makes one for each material of an object
    (``adfkit.geometry.objpieces``): an OBJ whose objects have faces of several materials (the
    corpus suturing set's needle and phantom collision meshes, one object each) is handed over
    as a copy with each sub-mesh an object of its own, vertex positions only; any other file as
    it is."""
    if path.suffix.lower() != ".obj":
        return path
    st = path.stat()
    key = (str(path), st.st_size, st.st_mtime_ns)
    if key not in _HULL_CACHE or not _still_there(_HULL_CACHE[key]):
        _HULL_CACHE[key] = _split_hulls(path, tree)
    return _HULL_CACHE[key]


def _split_hulls(path: Path, tree) -> Path:
    from ...geometry.objpieces import obj_pieces, pieces_obj_text

    try:
        text = inputs.read_text(path, "mesh", tree=tree, what="mesh file")
        pieces = obj_pieces(text)
    except (AdfError, ValueError, IndexError):
        return path  # PyBullet reads it as it is (or refuses it) as before
    objects = {ln.strip() for ln in text.splitlines() if ln.startswith(("o ", "g "))}
    if len(pieces) <= max(len(objects), 1):
        return path  # one material per object: PyBullet's hulls are AMBF's
    out = scratch.scratch_dir() / f"hulls_{next(_MADE)}.obj"
    out.write_text(pieces_obj_text(pieces), encoding="utf-8")
    return out


def is_convex(path: Path, rel: float = 1e-3) -> bool:
    """True when the mesh encloses its own convex hull (volumes within ``rel``): a convex hull of
    it collides exactly as its triangles do. False for open, concave or unreadable meshes."""
    from ...geometry.meshio import load_mesh  # trimesh: only for a static concave mesh beside soft bodies

    try:
        mesh = load_mesh(path)
        if not mesh.is_volume:
            return False
        return abs(mesh.convex_hull.volume - mesh.volume) <= rel * mesh.convex_hull.volume
    except (AdfError, ValueError):
        return False


def obj_colour(path: Path, tree=None) -> list[float] | None:
    """RGBA of the first material an OBJ file uses (its MTL's `Kd` and `d`), or None: how a soft
    body without `color rgba` gets its colour (AMBF's mesh loader reads the MTL; PyBullet's
    soft bodies are loaded from a plain copy of the nodes and would be drawn white)."""
    if path.suffix.lower() != ".obj":
        return None
    try:
        text = inputs.read_text(path, "mesh", tree=tree, what="mesh file")
        libs = [ln.split(None, 1)[1].strip() for ln in text.splitlines() if ln.startswith("mtllib ")]
        used = next((ln.split(None, 1)[1].strip() for ln in text.splitlines() if ln.startswith("usemtl ")), None)
        if not libs:
            return None
        mtl = inputs.read_text(path.parent / libs[0], "mesh", tree=tree, what="material file")
    except (AdfError, IndexError):
        return None
    current, kd, alpha = None, {}, {}
    for line in mtl.splitlines():
        parts = line.split()
        if len(parts) >= 2 and parts[0] == "newmtl":
            current = parts[1]
        elif len(parts) >= 4 and parts[0] == "Kd" and current is not None:
            kd[current] = parts[1:4]
        elif len(parts) >= 2 and parts[0] == "d" and current is not None:
            alpha[current] = parts[1]
    name = used if used in kd else next(iter(kd), None)
    if name is None:
        return None
    try:
        rgba = [float(c) for c in kd[name]] + [float(alpha.get(name, 1.0))]
    except ValueError:
        return None
    return rgba if all(np.isfinite(rgba)) else None


def reads_quietly(files) -> contextlib.AbstractContextManager:
    """Around a PyBullet call that reads mesh ``files``: when an OBJ among them names a material
    file or texture that is not there, PyBullet's seven lines on standard output for each (one
    per folder it tried) are not printed; adfkit says it once (``runner-missing-texture``,
    validate's ``missing-texture``)."""
    untextured = any(str(f).lower().endswith(".obj") and obj_material_problems(str(f)) for f in files)
    return quiet_stdout(discard=True) if untextured else contextlib.nullcontext()


def pybullet_reads_quietly(objs) -> contextlib.AbstractContextManager:
    """Around the PyBullet call that reads the meshes of ``objs`` ((model, body or ghost) pairs):
    createMultiBody, where PyBullet loads the mesh files its shapes name (reads_quietly)."""
    return reads_quietly(
        [p for m, o in objs for p in (visual_mesh_path(m, o), collision_mesh_path(m, o)) if p is not None]
    )
