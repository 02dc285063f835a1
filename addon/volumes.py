"""ADF volumes in Blender: each volume's iso-surface (adfkit.geometry.volume, marching cubes at
its `iso-surface value`) as a mesh object to see it, at the volume's location, in its colour.

The object is a picture only (ADF kind NONE, never exported): the volume itself, its slices
kept by reference, is carried through export as written (build.py's snapshot, with the slice
folder rebased when the file moves), so an import followed by an export changes nothing.
A volume whose slices cannot be read gets no object and a warning."""

from __future__ import annotations

import bpy
from mathutils import Quaternion, Vector

from adfkit.diagnostics import AdfError, Diagnostic, warning
from adfkit.model import Pose

#: the custom property naming the volume an iso-surface object shows
VOLUME_KEY = "adf_volume"


def _matrix(p: Pose):
    q = p.orientation
    m = Quaternion((q.w, q.x, q.y, q.z)).to_matrix().to_4x4()
    m.translation = Vector(p.position)
    return m


def import_volumes(doc, scene, diags: list[Diagnostic]) -> list:
    """One mesh object per readable volume of ``doc``; returns them."""
    from adfkit.geometry.volume import DEFAULT_ISO, iso_surface, load_volume

    made = []
    for vol in doc.volumes:
        if not vol.defined:
            continue
        level = vol.iso_surface_value if vol.iso_surface_value is not None else DEFAULT_ISO
        try:
            verts, faces = iso_surface(load_volume(doc, vol), level)
        except AdfError as exc:
            for d in exc.diagnostics:
                diags.append(warning(d.rule, f"{d.message}; the volume is kept but not shown", d.location, d.hint))
            continue
        name = vol.name or vol.identifier.removeprefix("VOLUME ")
        mesh = bpy.data.meshes.new(f"{name} iso-surface")
        mesh.from_pydata(verts.tolist(), [], faces.tolist())
        mesh.update()
        obj = bpy.data.objects.new(f"{name} (volume)", mesh)
        scene.collection.objects.link(obj)
        obj[VOLUME_KEY] = vol.identifier
        obj.matrix_world = _matrix(vol.location or Pose())
        c = vol.color_rgba
        if c is not None and None not in (c.r, c.g, c.b):
            obj.color = (c.r, c.g, c.b, 1.0 if c.a is None else c.a)
        obj.hide_select = True  # a picture of the slices: editing it would change nothing
        made.append(obj)
    return made


__all__ = ["VOLUME_KEY", "import_volumes"]
