"""Where AMBF puts the centre of mass of a body whose collision comes from a mesh and whose file
gives no `inertial offset` (or no `mass`): afRigidBody::createFromAttribs estimates it from the
collision mesh as CHAI3D loaded it (afInertialObject::computeInertialOffset), and builds the
collision shape in that inertial frame as if it were the body frame, so the collision shape is
moved by the estimate off the visual (adf-format.md §7.2).

The estimate, measured in AMBF on a hull of two boxes (16 vertices, 14 once welded, the OBJ's two
objects two sub-meshes): the mean of the first sub-mesh's welded vertices, added once for every
sub-mesh; the body came to rest 31.43 mm lower than where its collision mesh, put at the body
frame, holds it, which is 2 x the 15.71 mm of the 14 vertices' mean height.

- The sub-meshes are CHAI3D's (CFileModelOBJ in AMBF's tree): one per material of the `mtllib`
  (`newmtl` entries), or one per object (`o`) where there are more objects than materials, or
  one; a face goes to the sub-mesh of the material named by the `usemtl` before it (the first
  where none is named or the name is not in the library), so only the first sub-mesh has faces
  when the file has objects but no materials. An STL is one sub-mesh.
- The first sub-mesh's vertices are those of its triangles (each face a fan from its first
  corner), welded as cMesh::removeDuplicateVertices welds them with AMBF's threshold 0: two
  corners are one vertex when a hash of their position is equal, (min x + x) + dx·(min y + y) +
  dx·dy·(min z + z) over the sub-mesh's bounds, the first one met kept.
- An OBJ's coordinates are read as single-precision floats (CHAI3D's `%f`), so two corners
  written 0.04 and 0.039999999999999994 are one vertex.
- The vertices are scaled by the body's `scale` first.

Hand-written here: no mesh library reproduces CHAI3D's sub-meshes or its weld. No trimesh
either: the validator reads this (`inertial-offset-estimated`). A 3DS file gets no estimate here."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from .. import inputs
from ..diagnostics import AdfError
from .meshcheck import is_ascii_stl


def body_com(model, body) -> np.ndarray | None:
    """AMBF's estimated centre of mass of ``body`` (of ``model``) in its body frame, or None
    where AMBF takes the file's (model.semantics.com_estimated) or the mesh cannot be read."""
    from ..adf.paths import collision_mesh_path
    from ..model.semantics import com_estimated

    if not com_estimated(body) or (path := collision_mesh_path(model, body)) is None or not path.is_file():
        return None
    scale = body.scale if isinstance(body.scale, (int, float)) and not isinstance(body.scale, bool) else 1.0
    return mesh_com(path, float(scale))


def mesh_com(path: Path, scale: float = 1.0) -> np.ndarray | None:
    """AMBF's estimated centre of mass, in the body frame, of a body whose collision mesh is the
    OBJ or STL file at ``path`` (module docstring); None for a file that cannot be read here."""
    try:
        meshes, corners = _first_submesh(path)
    except (AdfError, OSError, ValueError, IndexError, struct.error):
        return None
    if not len(corners):
        return None
    return meshes * _welded(corners * float(scale)).mean(axis=0)


def _text(path: Path) -> str:
    """A mesh or material file's text, read under the input policy (adfkit.inputs: its size cap,
    no devices or pipes)."""
    return inputs.read_bytes(path, "mesh", what="mesh file").decode("utf-8", errors="replace")


def _first_submesh(path: Path) -> tuple[int, np.ndarray]:
    """(how many sub-meshes CHAI3D makes of the file, the first one's triangle corners in order)."""
    suffix = path.suffix.lower()
    if suffix == ".obj":
        return _obj_first_submesh(path)
    if suffix != ".stl":
        raise ValueError("not an OBJ or STL file")
    if is_ascii_stl(path):
        rows = [ln.split()[1:4] for ln in _text(path).splitlines() if ln.strip().startswith("vertex")]
        return 1, np.asarray(rows, dtype=np.float32).astype(float).reshape(-1, 3)
    data = inputs.read_bytes(path, "mesh", what="mesh file")
    (n,) = struct.unpack_from("<I", data, 80)
    tris = np.frombuffer(
        data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]), count=n, offset=84
    )
    return 1, tris["v"].astype(float).reshape(-1, 3)


def _obj_first_submesh(path: Path) -> tuple[int, np.ndarray]:
    meshes, faces, corners = _obj_submeshes(path)
    return meshes, corners


def empty_submeshes(path: Path) -> tuple[int, int] | None:
    """(sub-meshes CHAI3D makes of the OBJ at ``path``, how many of them have no face), or None
    for a file that is not an OBJ or cannot be read. AMBF 2.0 crashes (a segfault, measured)
    building a concave collision shape (GImpact) of one with an empty sub-mesh: an OBJ with more
    objects than materials, or a material library with a material no face uses."""
    if path.suffix.lower() != ".obj":
        return None
    try:
        meshes, faces, _ = _obj_submeshes(path)
    except (AdfError, OSError, ValueError, IndexError):
        return None
    return meshes, meshes - len(faces)


def _obj_submeshes(path: Path) -> tuple[int, set[int], np.ndarray]:
    """(how many sub-meshes CHAI3D makes, the indices of those with a face, the first one's
    triangle corners in order): one per material of the `mtllib` (or per object where there are
    more objects), each face in the sub-mesh of the `usemtl` before it (module docstring)."""
    text = _text(path)
    materials: list[str] = []
    objects = 0
    for line in text.splitlines():
        head, _, rest = line.strip().partition(" ")
        if head == "mtllib":
            lib = path.parent / rest.strip()
            if lib.is_file():
                materials += [
                    ln.split(None, 1)[1].strip() if len(ln.split(None, 1)) > 1 else ""
                    for ln in _text(lib).splitlines()
                    if ln.strip().startswith("newmtl")
                ]
        elif head == "o":
            objects += 1
    verts: list[list[float]] = []
    corners: list[list[float]] = []
    used: set[int] = set()
    current = 0
    for line in text.splitlines():
        head, _, rest = line.strip().partition(" ")
        if head == "v":
            verts.append([float(np.float32(x)) for x in rest.split()[:3]])  # CHAI3D reads floats (%f)
        elif head == "usemtl" and materials:
            name = rest.strip()
            if name in materials:
                current = materials.index(name)
        elif head == "f":
            used.add(current)
            if current:
                continue
            idx = []
            for tok in rest.split():
                i = int(tok.split("/")[0])
                idx.append(i - 1 if i > 0 else len(verts) + i)
            for k in range(2, len(idx)):
                corners += [verts[idx[0]], verts[idx[k - 1]], verts[idx[k]]]
    return max(len(materials), objects, 1), used, np.asarray(corners, dtype=float).reshape(-1, 3)


def _welded(corners: np.ndarray) -> np.ndarray:
    """The corners' vertices as CHAI3D welds them at threshold 0 (module docstring), in the
    order first met."""
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    dx = hi[0] - lo[0]
    dxy = dx * (hi[1] - lo[1])
    seen: set[float] = set()
    kept = []
    for c in corners:
        h = (lo[0] + c[0]) + dx * (lo[1] + c[1]) + dxy * (lo[2] + c[2])
        if h not in seen:
            seen.add(h)
            kept.append(c)
    return np.asarray(kept)
