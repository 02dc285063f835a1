"""Writing triangle meshes as STL, PLY (trimesh's writers) or 3DS (:mod:`.mesh3ds`), atomically.

OBJ with materials is written by the Blender add-on itself (addon/meshes.py); this module
takes plain parts (name, vertices, triangles) and the format a modeller chose.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..adf.writer import atomic_write_bytes
from .mesh3ds import TooLarge, encode_3ds

#: The formats a mesh can be exported in, with the suffix written (AMBF's add-on wrote capitals).
SUFFIXES = {"OBJ": ".OBJ", "STL": ".STL", "PLY": ".PLY", "3DS": ".3DS"}
#: Formats that hold several named objects in one file (a multi-part collision mesh).
MULTI_OBJECT = ("OBJ", "3DS")
#: Formats that keep the vertex list as written (STL stores three corners per triangle).
VERTEX_ORDER_KEPT = ("OBJ", "PLY", "3DS")

__all__ = ["MULTI_OBJECT", "SUFFIXES", "VERTEX_ORDER_KEPT", "TooLarge", "encode_parts", "format_of", "write_parts"]


def format_of(path: str | os.PathLike) -> str | None:
    """'OBJ', 'STL', 'PLY' or '3DS' from a file name's suffix (any case), else None."""
    suffix = Path(path).suffix.upper()
    return next((f for f, s in SUFFIXES.items() if s == suffix), None)


def write_parts(path: str | os.PathLike, parts: list[tuple[str, np.ndarray, np.ndarray]], split: bool = True) -> Path:
    """Write the parts to ``path`` in the format its suffix names (STL, PLY or 3DS): the bytes
    of :func:`encode_parts`."""
    return atomic_write_bytes(path, encode_parts(format_of(path) or Path(path).suffix, parts, split=split))


def encode_parts(fmt: str, parts: list[tuple[str, np.ndarray, np.ndarray]], split: bool = True) -> bytes:
    """The file of the parts in ``fmt`` ('STL', 'PLY' or '3DS'). STL and PLY hold one mesh:
    the parts are concatenated. 3DS keeps one object per part and splits a part over its
    65535-vertex limit (or raises :class:`TooLarge` without ``split``)."""
    if fmt == "3DS":
        return encode_3ds(parts, split=split)
    if fmt not in ("STL", "PLY"):
        raise ValueError(f"encode_parts writes STL, PLY or 3DS, not {fmt}")
    import trimesh  # noqa: PLC0415 - only when a mesh is written

    verts, tris, base = [], [], 0
    for _name, v, t in parts:
        v = np.asarray(v, dtype=np.float64).reshape(-1, 3)
        verts.append(v)
        tris.append(np.asarray(t, dtype=np.int64).reshape(-1, 3) + base)
        base += len(v)
    mesh = trimesh.Trimesh(
        vertices=np.concatenate(verts) if verts else np.zeros((0, 3)),
        faces=np.concatenate(tris) if tris else np.zeros((0, 3), dtype=np.int64),
        process=False,  # keep the vertex order: a soft body's node numbering depends on it
    )
    data = mesh.export(file_type=fmt.lower())
    return data if isinstance(data, bytes) else data.encode()


def face_normal(points) -> tuple[float, float, float]:
    """The unit normal of a polygon (Newell's method, any vertex count; +z when degenerate)."""
    p = np.asarray(points, dtype=float)
    q = np.roll(p, -1, axis=0)
    n = np.array(
        [
            np.sum((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2])),
            np.sum((p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0])),
            np.sum((p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1])),
        ]
    )
    length = float(np.linalg.norm(n))
    return (0.0, 0.0, 1.0) if length == 0.0 else tuple(float(x) for x in n / length)


def vertex_normals(vertices, faces) -> np.ndarray:
    """(n, 3) unit normals at the vertices: the sum of the normals of the faces around each,
    weighted by their areas (+z for a vertex no face uses)."""
    v = np.asarray(vertices, dtype=float)
    out = np.zeros_like(v)
    for f in faces:
        p = v[list(f)]
        n = np.cross(p[1] - p[0], p[-1] - p[0]) if len(p) == 3 else np.array(face_normal(p))
        out[list(f)] += n
    length = np.linalg.norm(out, axis=1, keepdims=True)
    return np.where(length > 0, out / np.where(length > 0, length, 1.0), np.array([0.0, 0.0, 1.0]))


def obj_faces(vertices, faces, uvs=None, v_base: int = 1, vt_base: int = 1) -> tuple[list[str], list[str]]:
    """(``vn`` lines, ``f`` lines) of an OBJ mesh, every face with normals: `f v//vn`, or
    `f v/vt/vn` with ``uvs`` (one per vertex, same index), a normal per vertex at the vertex's
    own index (so that a reader keeping (vertex, normal) pairs, trimesh's, does not split the
    mesh). AMBF 2.0's OBJ reader (chai3d cOBJModel::parseFaceString) reads any face with a '/'
    as v/vt/vn, and decides from an unterminated copy of the face's first triplet, so that
    `f v/vt` crashes it and a plain `f v` crashes it after a file with slashes was read
    (measured: the sample scene's floor, phantom and needle, loaded in that order, killed
    ambf_simulator). Full triplets read right always."""
    normals = ["vn {:.6g} {:.6g} {:.6g}".format(*n) for n in vertex_normals(vertices, faces)]
    if uvs is None:
        lines = ["f " + " ".join(f"{i + v_base}//{i + v_base}" for i in f) for f in faces]
    else:
        lines = ["f " + " ".join(f"{i + v_base}/{i + vt_base}/{i + v_base}" for i in f) for f in faces]
    return normals, lines
