"""The mesh format a body's files are written in, and what that format cannot hold: said as a
finding, never dropped silently (materials in STL/PLY/3DS, collision parts in STL/PLY, a soft
body over the 3DS object limits)."""

from __future__ import annotations

from adfkit.diagnostics import Diagnostic, SourceLocation, error, warning
from adfkit.geometry.mesh3ds import LIMIT
from adfkit.geometry.meshwrite import MULTI_OBJECT

DEFAULT_COLOUR = (0.8, 0.8, 0.8)  # Blender's material without a colour of its own


def _where(obj) -> SourceLocation:
    return SourceLocation(f"blender:{obj.name}")


def findings(obj, arr, fmt: str, soft: bool) -> list[Diagnostic]:
    """What writing ``arr`` (meshes.MeshArrays) of ``obj`` as ``fmt`` would lose or cannot do."""
    out: list[Diagnostic] = []
    what = "soft body" if soft else "body"
    coloured = [
        m.name
        for m in arr.materials
        if m.texture or m.normal_map or tuple(round(c, 3) for c in m.base_color[:3]) != DEFAULT_COLOUR
    ]
    if fmt != "OBJ" and coloured:
        out.append(
            warning(
                "mesh-format-materials",
                f"{what} '{obj.name}': the {fmt} format holds no material; the colour and textures of "
                f"{', '.join(repr(n) for n in coloured)} are not written",
                _where(obj),
                "export the meshes as OBJ to keep them",
            )
        )
    tris = 0 if arr.tris is None else len(arr.tris)
    if soft and fmt == "3DS" and (len(arr.co) > LIMIT or tris > LIMIT):
        out.append(
            error(
                "mesh-format-limit",
                f"soft body '{obj.name}' has {len(arr.co)} vertices and {tris} triangles; a 3DS object "
                f"holds at most {LIMIT} of each, and a soft body's mesh cannot be split (its node numbers)",
                _where(obj),
                "export the meshes as OBJ or PLY, or decimate the mesh",
            )
        )
    return out


def collision_format(obj, parts: int, out) -> str:
    """The format of a body's collision mesh of ``parts`` objects: the chosen one, or OBJ (with a
    warning in ``out.diagnostics``) when that format holds a single mesh and there are several
    parts (AMBF would make one convex hull around all of them)."""
    fmt = out.options.mesh_format
    if parts > 1 and fmt not in MULTI_OBJECT:
        out.diagnostics.append(
            warning(
                "mesh-format-parts",
                f"body '{obj.name}': its {parts} collision parts are written as OBJ; the {fmt} format holds "
                "one mesh, of which AMBF would make a single convex hull",
                _where(obj),
                "choose OBJ or 3DS as the mesh format to keep the parts in that format",
            )
        )
        return "OBJ"
    return fmt
