"""Writing 3D Studio (.3DS) triangle meshes: the chunk format AMBF's soft bodies and CHAI3D read.

Blender 4.2 and later ship no 3DS exporter and trimesh cannot write the format, so this is a
small writer of the part of it a mesh needs::

    MAIN3DS 0x4D4D
      M3D_VERSION 0x0002 (3)
      EDIT3DS 0x3D3D
        MESH_VERSION 0x3D3E (3)
        EDIT_OBJECT 0x4000  name (NUL-terminated, at most 10 characters)
          OBJ_TRIMESH 0x4100
            TRI_VERTEXL 0x4110  u16 count, count x 3 float32
            TRI_FACEL1  0x4120  u16 count, count x (u16 a, b, c, u16 flags)

Every chunk is a little-endian u16 id and a u32 length that counts its 6-byte header. Counts
are u16, so one object holds at most 65535 vertices and 65535 triangles: a larger part is
split into several objects (triangles in order, each object's vertices in order of first
use), unless ``split=False`` (a soft body, whose node numbering must not change), when
:class:`TooLarge` says so. numpy only.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np

from ..adf.writer import atomic_write_bytes
from .format3ds import EDITOR, FACES, MAIN, MESH_VERSION, OBJECT, TRIMESH, VERSION, VERTICES

LIMIT = 0xFFFF  # u16 counts: vertices and triangles per object
NAME_CHARS = 10  # the format's object-name length (longer names break older readers)
FACE_FLAGS = 0x0007  # edges AB, BC and CA visible, as 3D Studio writes them


class TooLarge(ValueError):
    """A part over the 3DS object limits that may not be split."""


def _chunk(cid: int, body: bytes) -> bytes:
    return struct.pack("<HI", cid, 6 + len(body)) + body


def _object(name: str, vertices: np.ndarray, triangles: np.ndarray) -> bytes:
    v = np.ascontiguousarray(vertices, dtype="<f4").reshape(-1, 3)
    f = np.empty((len(triangles), 4), dtype="<u2")
    f[:, :3] = triangles
    f[:, 3] = FACE_FLAGS
    mesh = _chunk(VERTICES, struct.pack("<H", len(v)) + v.tobytes()) + _chunk(
        FACES, struct.pack("<H", len(f)) + f.tobytes()
    )
    return _chunk(OBJECT, name.encode("ascii", "replace") + b"\0" + _chunk(TRIMESH, mesh))


def _fits(tris: np.ndarray) -> bool:
    return len(tris) <= LIMIT and len(np.unique(tris)) <= LIMIT


def _pieces(vertices: np.ndarray, triangles: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Consecutive runs of triangles, each within the limits, with their own vertices."""
    out = []
    start, n = 0, len(triangles)
    while start < n:
        lo, hi = 1, min(LIMIT, n - start)  # the longest run from start that fits (bisection)
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if _fits(triangles[start : start + mid]):
                lo = mid
            else:
                hi = mid - 1
        run = triangles[start : start + lo]
        used, first = np.unique(run.reshape(-1), return_index=True)
        order = used[np.argsort(first)]  # vertices in order of first use
        remap = np.empty(int(order.max()) + 1, dtype=np.int64)
        remap[order] = np.arange(len(order))
        out.append((vertices[order], remap[run]))
        start += lo
    return out


def _names(base: str, count: int, taken: set[str]) -> list[str]:
    clean = "".join(c if c.isascii() and c.isprintable() else "_" for c in base) or "mesh"
    out = []
    for i in range(count):
        tail = "" if count == 1 else f"_{i}"
        name = clean[: NAME_CHARS - len(tail)] + tail
        k = 1
        while name in taken:  # truncation made two names equal
            tail = f"~{k}"
            name = clean[: NAME_CHARS - len(tail)] + tail
            k += 1
        taken.add(name)
        out.append(name)
    return out


def encode_3ds(parts: list[tuple[str, np.ndarray, np.ndarray]], split: bool = True) -> bytes:
    """The bytes of a .3DS file with one object per part (name, vertices (n, 3), triangles
    (m, 3) indexing them); a part over 65535 vertices or triangles becomes several objects
    (``split``) or raises :class:`TooLarge`."""
    objects = []
    taken: set[str] = set()
    for name, vertices, triangles in parts:
        v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
        t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
        if len(t) and (t.min() < 0 or t.max() >= len(v)):
            raise ValueError(f"part '{name}': a triangle indexes a vertex that is not there")
        if len(v) <= LIMIT and len(t) <= LIMIT:
            pieces = [(v, t)]
        elif not split:
            raise TooLarge(
                f"part '{name}' has {len(v)} vertices and {len(t)} triangles; "
                f"a 3DS object holds at most {LIMIT} of each"
            )
        else:
            pieces = _pieces(v, t)
        for nm, (pv, pt) in zip(_names(name, len(pieces), taken), pieces):
            objects.append(_object(nm, pv, pt))
    editor = _chunk(MESH_VERSION, struct.pack("<I", 3)) + b"".join(objects)
    return _chunk(MAIN, _chunk(VERSION, struct.pack("<I", 3)) + _chunk(EDITOR, editor))


def write_3ds(path: str | os.PathLike, parts: list[tuple[str, np.ndarray, np.ndarray]], split: bool = True) -> Path:
    """Write :func:`encode_3ds` atomically (a temporary file beside the target, then renamed)."""
    data = encode_3ds(parts, split=split)
    return atomic_write_bytes(path, data)
