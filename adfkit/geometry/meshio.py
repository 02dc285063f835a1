"""Reading meshes for ADF bodies through trimesh, with unit scale and clear diagnostics.

``load_mesh`` is the one entry point other modules use (runner, add-on, converters): its
signature is stable. Every failure a user can cause is an ``AdfError`` carrying a
diagnostic with a rule id and a hint, never a bare trimesh/numpy exception.
"""

from __future__ import annotations

import os

import numpy as np
import trimesh

from .. import inputs
from ..diagnostics import AdfError, SourceLocation, error

#: Suffixes we hand to trimesh (lower case). DAE needs pycollada; trimesh says so if absent.
MESH_SUFFIXES = (".stl", ".obj", ".ply", ".3ds", ".dae", ".off", ".glb", ".gltf")


def _fail(rule: str, message: str, path: str | os.PathLike, hint: str) -> AdfError:
    return AdfError(error(rule, message, SourceLocation(inputs.shown(path)), hint))


def _as_single_mesh(loaded, path) -> trimesh.Trimesh:
    """A Scene (multi-object OBJ, DAE) becomes one mesh in the file's frame."""
    if isinstance(loaded, trimesh.Trimesh):
        return loaded
    if isinstance(loaded, trimesh.Scene):
        meshes = []
        for node in loaded.graph.nodes_geometry:
            transform, name = loaded.graph[node]
            geom = loaded.geometry[name]
            if isinstance(geom, trimesh.Trimesh) and len(geom.faces):
                meshes.append(geom.copy().apply_transform(transform))
        if not meshes:
            raise _fail(
                "mesh-empty",
                "the mesh file holds no triangles",
                path,
                "export the object as a triangle mesh (not only points or lines)",
            )
        return trimesh.util.concatenate(meshes)
    raise _fail(
        "mesh-empty",
        f"the file holds no triangle mesh (got {type(loaded).__name__})",
        path,
        "export the object as a triangle mesh (not only points or lines)",
    )


def load_mesh(
    path: str | os.PathLike, scale: float = 1.0, tree: inputs.Tree | None = None, referrer: SourceLocation | None = None
) -> trimesh.Trimesh:
    """Load STL/OBJ/PLY/DAE (whatever trimesh reads) or 3DS as one triangle mesh, times ``scale``.

    ``scale`` multiplies vertex coordinates about the mesh origin, as ADF's per-body
    ``scale`` does for visual and collision meshes (adf-format.md §12.3). Multi-object
    files (OBJ groups, DAE nodes) are concatenated in the file's frame. Vertices that share
    a position are merged (ignoring normals and UVs) so closed meshes read as watertight.

    Raises ``AdfError`` with rule ``mesh-not-found``, ``mesh-unreadable``, ``mesh-empty``,
    ``mesh-non-finite`` or ``mesh-bad-scale``, or an input-policy rule (adfkit.inputs:
    ``bad-path``, ``not-a-regular-file``, ``file-too-large``, ``outside-tree`` when ``tree``
    is given: the tree of the ADF file that names the mesh).
    """
    p = inputs.check_mesh(path, tree=tree, referrer=referrer)
    if not np.isfinite(scale) or scale <= 0:
        raise _fail(
            "mesh-bad-scale",
            f"scale must be a positive finite number, got {scale!r}",
            p,
            "ADF 'scale' is a positive factor (default 1.0)",
        )
    suffix = p.suffix.lower()
    try:
        if suffix == ".3ds":  # trimesh has no 3DS reader; softmesh has (CHAI3D's reading: vertices as stored)
            from .softmesh import read_3ds

            loaded = trimesh.Trimesh(*read_3ds(p), process=False)
        else:
            loaded = trimesh.load(
                str(p), file_type=suffix.lstrip(".") or None, force=None, process=False, skip_materials=True
            )
    except AdfError:
        raise
    except Exception as exc:  # trimesh raises many types for bad input
        raise _fail(
            "mesh-unreadable",
            f"cannot read mesh: {type(exc).__name__}: {exc}",
            p,
            f"is this a valid {suffix.lstrip('.').upper() or 'mesh'} file? formats: "
            + ", ".join(s.lstrip(".").upper() for s in MESH_SUFFIXES),
        ) from None
    mesh = _as_single_mesh(loaded, p)
    if len(mesh.faces) == 0 or len(mesh.vertices) == 0:
        raise _fail("mesh-empty", "the mesh has no triangles", p, "export the object as a triangle mesh")
    if not np.all(np.isfinite(mesh.vertices)):
        bad = int((~np.isfinite(mesh.vertices)).any(axis=1).sum())
        raise _fail(
            "mesh-non-finite",
            f"{bad} vertices have NaN or infinite coordinates",
            p,
            "fix the exporter or the modelling tool; NaN vertices cannot be simulated",
        )
    mesh = trimesh.Trimesh(
        vertices=np.asarray(mesh.vertices, dtype=np.float64) * float(scale),
        faces=np.asarray(mesh.faces),
        process=True,
        validate=False,
    )
    mesh.metadata["file_name"] = p.name
    mesh.metadata["file_path"] = str(p)
    return mesh
