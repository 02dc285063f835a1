"""The .3DS (Autodesk 3D Studio) chunk format, as far as a triangle mesh needs it: the chunk ids
the writer (mesh3ds.py) and the reader (softmesh.read_3ds) share, and the chunk walk, with the
standard library alone (the validator checks a 3DS mesh with it without importing numpy).

Every chunk is a little-endian u16 id and a u32 length that counts its 6-byte header."""

from __future__ import annotations

import os
import struct

from ..diagnostics import AdfError, SourceLocation, error

MAIN, VERSION, EDITOR, MESH_VERSION, OBJECT, TRIMESH, VERTICES, FACES = (
    0x4D4D,
    0x0002,
    0x3D3D,
    0x3D3E,
    0x4000,
    0x4100,
    0x4110,
    0x4120,
)
CONTAINERS = (MAIN, EDITOR, TRIMESH)  # chunks that hold chunks


def unreadable(path, message: str, hint: str) -> AdfError:
    """A mesh file that cannot be read: the located `mesh-unreadable` error, with a hint."""
    return AdfError(error("mesh-unreadable", message, SourceLocation(str(path)), hint))


def empty(path, message: str = "the mesh has no triangles") -> AdfError:
    """A mesh file without a triangle: the located `mesh-empty` error."""
    return AdfError(error("mesh-empty", message, SourceLocation(str(path)), "export the object as a triangle mesh"))


def walk_3ds(path: str | os.PathLike, data: bytes) -> list[tuple[int, int, int]]:
    """The triangle objects' blocks of a .3DS file's bytes, in file order: (OBJECT, 0, 0) where
    an object starts (its faces index its own vertices), then (chunk id, count, offset of the
    first item) for each vertex list (VERTICES) and face list (FACES). The chunk walk alone,
    with the standard library (the validator checks a 3DS mesh with it without importing
    numpy). A corrupt or short chunk, or no triangle object, is an AdfError."""
    blocks: list[tuple[int, int, int]] = []
    # depth first in file order, with a stack of the ranges still to read (not recursion: a
    # file of nested chunks, 6 bytes a level, would reach Python's recursion limit at 6 kB)
    stack = [(0, len(data))]
    try:
        while stack:
            off, end = stack.pop()
            while off + 6 <= end:
                cid, length = struct.unpack_from("<HI", data, off)
                if length < 6 or off + length > end:
                    raise unreadable(path, f"corrupt 3DS chunk 0x{cid:04x} at byte {off}", "re-export the mesh")
                body, nxt = off + 6, off + length
                if cid in CONTAINERS or cid == OBJECT:
                    if cid == OBJECT:
                        body = data.index(b"\0", body, nxt) + 1  # past the object's name
                        blocks.append((OBJECT, 0, 0))
                    stack.append((nxt, end))  # the rest of this range, once the chunk's own are read
                    off, end = body, nxt
                    continue
                if cid in (VERTICES, FACES):
                    (n,) = struct.unpack_from("<H", data, body)
                    if body + 2 + n * (12 if cid == VERTICES else 8) > nxt:
                        raise unreadable(
                            path,
                            f"3DS chunk 0x{cid:04x} at byte {off} is shorter than its {n} items",
                            "re-export the mesh",
                        )
                    blocks.append((cid, n, body + 2))
                off = nxt
    except (struct.error, ValueError) as exc:
        raise unreadable(path, f"cannot read 3DS file: {exc}", "re-export the mesh as OBJ or STL") from None
    kinds = {cid for cid, _, _ in blocks}
    if VERTICES not in kinds or FACES not in kinds:
        raise empty(path, "the 3DS file holds no triangle object")
    return blocks
