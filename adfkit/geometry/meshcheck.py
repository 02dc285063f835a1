"""A cheap structural read of the mesh files physics engines take (STL, OBJ) and AMBF's 3DS: does the file
hold triangles at all? Used by the validator (before a run) and by the runner (before
PyBullet, which crashes on an OBJ without faces and reads random bytes as an STL).

No trimesh here: the validator imports this, and it must stay fast. A binary STL is its
80-byte header, a triangle count and 50 bytes per triangle; an ASCII STL has ``facet`` and
``vertex`` lines; an OBJ has ``v`` and ``f`` lines; a 3DS file's chunks must nest and hold a
triangle object. Other formats get no opinion (None).
"""

from __future__ import annotations

import os
import re
import struct
from functools import lru_cache
from pathlib import Path

from .. import inputs
from ..diagnostics import AdfError

_OBJ_FACE = re.compile(rb"^[ \t]*f[ \t]", re.M)
_OBJ_VERTEX = re.compile(rb"^[ \t]*v[ \t]", re.M)


def mesh_problem(path: str | os.PathLike) -> str | None:
    """Why the STL/OBJ file at ``path`` holds no usable triangles, or None (also None for other
    formats and for files the input policy refuses: that is reported on its own)."""
    key = _cache_key(path)
    return None if key is None else _problem(*key)


def _cache_key(path: str | os.PathLike) -> tuple[str, int, int] | None:
    """The path with its size and mtime, so a cached read of a file that changed is read again;
    None where it cannot be stat'ed."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return os.fspath(path), st.st_size, st.st_mtime_ns


@lru_cache(maxsize=4096)
def _problem(path: str, size: int, _mtime: int) -> str | None:
    suffix = os.path.splitext(path)[1].lower()
    if suffix not in (".stl", ".obj", ".3ds"):
        return None
    try:
        data = inputs.read_bytes(path, "mesh", what="mesh file")
    except AdfError:
        return None
    if suffix == ".stl":
        return _stl_problem(data)
    if suffix == ".3ds":
        return _3ds_problem(path, data)
    return _obj_problem(data)


def _3ds_problem(path: str, data: bytes) -> str | None:
    from .format3ds import walk_3ds

    try:
        walk_3ds(path, data)
    except AdfError as exc:
        return exc.diagnostics[0].message
    return None


def is_ascii_stl(path: str | os.PathLike) -> bool:
    """An ASCII STL (``solid`` ... ``facet`` text), which MuJoCo's STL decoder refuses."""
    try:
        data = inputs.read_bytes(path, "mesh", what="mesh file")
    except AdfError:
        return False
    if len(data) >= 84 and len(data) == 84 + 50 * struct.unpack_from("<I", data, 80)[0]:
        return False  # a binary STL whose header happens to start with "solid"
    return data[:512].lstrip().lower().startswith(b"solid")


def _stl_problem(data: bytes) -> str | None:
    if len(data) >= 84:
        (n,) = struct.unpack_from("<I", data, 80)
        if len(data) == 84 + 50 * n:
            return None if n else "the STL file holds no triangles"
    head = data[:512].lstrip().lower()
    if head.startswith(b"solid"):
        facets, vertices = data.count(b"facet"), data.count(b"vertex")
        if facets == 0 or vertices < 3:
            return "the ASCII STL file holds no triangles"
        return None
    if len(data) < 84:
        return f"not an STL file ({len(data)} bytes; a binary STL has at least 84)"
    (n,) = struct.unpack_from("<I", data, 80)
    if n and len(data) >= 84 + 50 * n:  # some exporters pad the end
        return None
    return (
        f"not a valid STL file: a binary STL with {n} triangles has {84 + 50 * n} bytes, this one "
        f"{len(data)} (and it does not start with 'solid')"
    )


_OBJ_FACE_LINE = re.compile(rb"^[ \t]*f[ \t]+([^\r\n]*)", re.M)


def _obj_problem(data: bytes) -> str | None:
    if _OBJ_VERTEX.search(data) is None:
        return "the OBJ file has no vertices ('v' lines)"
    if _OBJ_FACE.search(data) is None:
        return "the OBJ file has no faces ('f' lines)"
    return _obj_face_problem(data)


def _obj_face_problem(data: bytes) -> str | None:
    """The first face corner that names no vertex of the file (0, an index past the vertices,
    a relative index before the first, or no number): every reader indexes the vertices with it
    (adfkit's own hull split raised IndexError on a static body's mesh)."""
    total = len(_OBJ_VERTEX.findall(data))
    for tok in b" ".join(_OBJ_FACE_LINE.findall(data)).split():
        try:
            i = int(tok.split(b"/", 1)[0])
        except ValueError:
            return f"a face corner is not a vertex number ({_shown(tok)})"
        if i == 0 or not -total <= i <= total:
            return f"a face names vertex {i}; the file has {total} vertices"
    return None


def _shown(raw: bytes) -> str:
    text = raw.decode("utf-8", errors="replace")
    return text if len(text) <= 40 else text[:40] + "..."


#: a face whose first corner is `v/vt`: texture coordinates without normals
_OBJ_VT_FACE = re.compile(rb"^f[ \t]+-?\d+/-?\d+(?=[ \t\r\n])", re.M)


def obj_faces_crash_ambf(obj_path: str) -> bool:
    """The OBJ has faces written `f v/vt` (texture coordinates, no normals), which AMBF 2.0's OBJ
    reader (chai3d cOBJModel::parseFaceString) reads as `v/vt/vn` with an index it never set:
    ambf_simulator crashes loading it (measured, a one-triangle file). `f v`, `f v//vn` and
    `f v/vt/vn` load."""
    key = _cache_key(obj_path)
    return key is not None and _vt_faces(*key)


@lru_cache(maxsize=1024)
def _vt_faces(path: str, _size: int, _mtime: int) -> bool:
    try:
        data = inputs.read_bytes(path, "mesh", what="mesh file")
    except AdfError:
        return False
    return _OBJ_VT_FACE.search(data) is not None


TEXTURE_KEYS = ("map_", "bump", "norm", "disp", "decal", "refl")  # MTL statements naming a file


def _absolute(name: str) -> bool:
    """A POSIX or Windows absolute path (``C:\\...``, ``\\\\server\\...``)."""
    return name.startswith(("/", "\\")) or (len(name) > 2 and name[1] == ":" and name[2] in "/\\")


@lru_cache(maxsize=1024)
def obj_material_problems(obj_path: str) -> tuple[str, ...]:
    """Missing MTL libraries and textures of an OBJ file (names as written)."""
    missing: list[str] = []
    base = Path(obj_path).parent
    try:
        inputs.check_file(obj_path, "mesh")
        with open(obj_path, encoding="utf-8", errors="replace") as fh:
            libs = [line.split(None, 1)[1].strip() for line in fh if line.startswith("mtllib") and " " in line]
    except (OSError, ValueError, AdfError):
        return ()
    for lib in libs:
        mtl = base / lib
        if not inputs.is_regular(str(mtl)):
            missing.append(f"material library {inputs.shown(lib, 80)}")
            continue
        try:
            data = inputs.read_bytes(mtl, "text", tree=inputs.Tree(Path(os.path.realpath(base))))
            lines = data.decode("utf-8", errors="replace").splitlines()
        except AdfError:
            missing.append(f"material library {inputs.shown(lib, 80)} (outside the mesh's folder or not readable)")
            continue
        for line in lines:
            parts = line.strip().split()
            if len(parts) >= 2 and parts[0].lower().startswith(TEXTURE_KEYS):
                tex = parts[-1]
                if not inputs.is_regular(str(mtl.parent / tex)) and not inputs.is_regular(
                    str(mtl.parent / tex.replace("\\", "/"))
                ):
                    far = "; an absolute path, from the machine the file was made on" if _absolute(tex) else ""
                    missing.append(f"texture {inputs.shown(tex, 80)} (in {inputs.shown(lib, 80)}{far})")
    return tuple(dict.fromkeys(missing))
