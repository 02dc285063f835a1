"""How many nodes AMBF makes of a soft body's mesh, without numpy where the format allows: the
validator counts them to check `fixed nodes`, and importing numpy (and trimesh) for it was
8 % of `adfkit validate` on the corpus (one soft body, a .3DS cloth). softmesh.unique_nodes
builds the nodes themselves; this counts them by the same rule."""

from __future__ import annotations

import math
import struct
import sys
from array import array
from pathlib import Path

from .format3ds import FACES, OBJECT, VERTICES, empty, unreadable, walk_3ds

MERGE_DECIMALS = 9  # vertices equal to 1e-9 m are one node


def node_count(path: Path, tree=None) -> int | None:
    """The node count of the soft body made of mesh file ``path`` (through the input policy,
    as softmesh.load_soft_mesh reads it), or None where only that can tell (a format other
    than .3DS, a coordinate that is not finite; softmesh imports this module, so the caller
    asks it). AdfError as load_soft_mesh raises it."""
    if path.suffix.lower() != ".3ds":
        return None
    from .. import inputs  # noqa: PLC0415

    p = inputs.check_mesh(path, tree=tree)
    return node_count_3ds(p, inputs.read_bytes(p, "mesh", tree=tree, what="mesh file"))


def node_count_3ds(path, data: bytes) -> int | None:
    """The unique vertices of a .3DS file's bytes, each rounded to MERGE_DECIMALS as numpy
    rounds (x·10^d to the nearest integer, ties to even: Python's round of a float does the
    same), so that the count is softmesh.unique_nodes's. None for a coordinate that is not
    finite; AdfError for a file read_3ds and load_soft_mesh refuse (no triangles, a face
    naming a vertex the file does not hold)."""
    scale = float(10**MERGE_DECIMALS)
    seen: set[tuple[int, int, int]] = set()
    total = base = faces = 0
    top = -1
    for cid, n, at in walk_3ds(path, data):
        if cid == OBJECT:  # an object's faces index its own vertices
            base = total
        elif cid == VERTICES:
            for x, y, z in struct.iter_unpack("<3f", data[at : at + 12 * n]):
                if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
                    return None
                seen.add((round(x * scale), round(y * scale), round(z * scale)))
            total += n
        elif cid == FACES and n:
            idx = array("H", data[at : at + 8 * n])
            if sys.byteorder == "big":  # the file's u16 are little-endian
                idx.byteswap()
            top = max(top, base + max(max(idx[0::4]), max(idx[1::4]), max(idx[2::4])))
            faces += n
    if not total or not faces:
        raise empty(path)
    if top >= total:
        raise unreadable(path, "a triangle refers to a vertex the file does not hold", "re-export the mesh")
    return len(seen)
