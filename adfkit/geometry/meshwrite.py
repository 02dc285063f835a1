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
