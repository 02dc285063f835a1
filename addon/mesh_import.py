"""Mesh files into Blender objects for the importer: Blender's own OBJ, STL and PLY importers,
adfkit's 3DS reader; a file none of them reads gives a warning (collected in ``UNREADABLE``
and drained into import_model's diagnostics), never an exception."""

from __future__ import annotations

from pathlib import Path

import bpy
from mathutils import Matrix

from adfkit.diagnostics import AdfError, Diagnostic, SourceLocation, warning
from adfkit.inputs import shown

from . import meshes


def _empty(name: str, scene):
    obj = bpy.data.objects.new(name, None)
    scene.collection.objects.link(obj)
    return obj


#: meshes Blender's importers refused during the current import_model (drained into its diagnostics)
UNREADABLE: list[Diagnostic] = []
_IMPORTERS = {".obj": "obj_import", ".stl": "stl_import", ".ply": "ply_import"}


def import_file(path: Path, scene) -> list:
    """Objects created by Blender's own importer for ``path``, axes left as in the file. A file
    the importer refuses (garbage, truncated) gives no object and a warning, never an exception."""
    before = set(scene.objects)
    op = _IMPORTERS.get(path.suffix.lower())
    if op is None and path.suffix.lower() != ".3ds":
        UNREADABLE.append(
            warning(
                "mesh-unreadable",
                f"no importer for the mesh {path.name} (OBJ, STL, PLY and 3DS are read); imported without it",
                SourceLocation(shown(path)),
                "convert the mesh to OBJ or STL",
            )
        )
        return []
    try:
        if op is None:
            return meshes.objects_from_3ds(path, scene)
        getattr(bpy.ops.wm, op)(filepath=str(path), forward_axis="Y", up_axis="Z")
    except (RuntimeError, AdfError) as exc:  # Blender's operators report a failed read this way
        for o in [o for o in scene.objects if o not in before]:
            bpy.data.objects.remove(o, do_unlink=True)
        text = exc.diagnostics[0].message if isinstance(exc, AdfError) else str(exc).strip()
        reason = text.splitlines()[-1] if text else "unreadable"
        UNREADABLE.append(
            warning(
                "mesh-unreadable",
                f"Blender could not import the mesh {path.name}: {reason}; imported without it",
                SourceLocation(shown(path)),
                "check the mesh file (adfkit validate says why)",
            )
        )
        return []
    return sorted((o for o in scene.objects if o not in before), key=lambda o: o.name)


def _join(objs, scene):
    if len(objs) == 1:
        return objs[0]
    for o in scene.objects:
        o.select_set(False)
    for o in objs:
        o.select_set(True)
    bpy.context.view_layer.objects.active = objs[0]
    bpy.ops.object.join()
    return objs[0]


def mesh_object(name: str, path: Path | None, scene):
    if path is not None and path.is_file():
        made = import_file(path, scene)
        if made:
            obj = _join(made, scene)
            obj.name = name
            obj.data.name = name
            obj.matrix_world = Matrix.Identity(4)
            return obj
    return _empty(name, scene)
