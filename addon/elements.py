"""Blender objects the add-on makes or measures, below both the importer (build.py) and the
authoring tools (authoring.py): linking an object into the scene, a collision primitive child,
a body's mass from its density and mesh volume. Nothing here imports the add-on's upper layers."""

from __future__ import annotations

import bpy
from mathutils import Matrix


def _link(obj, scene=None):
    (scene or bpy.context.scene).collection.objects.link(obj)
    return obj


def mesh_volume(obj, evaluated: bool = False) -> tuple[float, bool]:
    """(volume in m³ with the object's scale, closed?) of a mesh object, its modifiers applied
    when ``evaluated`` (a Solidify gives a sheet its thickness); an open mesh gives its convex
    hull's volume (bmesh, no geometry packages needed)."""
    import bmesh

    bm = bmesh.new()
    try:
        if evaluated and len(obj.modifiers):
            bm.from_object(obj, bpy.context.evaluated_depsgraph_get())
        else:
            bm.from_mesh(obj.data)
        bm.transform(Matrix.Diagonal((*obj.matrix_world.to_scale(), 1.0)))
        closed = len(bm.faces) > 0 and all(e.is_manifold for e in bm.edges)
        if not closed and len(bm.verts) >= 4:
            bmesh.ops.convex_hull(bm, input=bm.verts[:], use_existing_faces=False)
            for f in [f for f in bm.faces if not f.is_valid]:
                bm.faces.remove(f)
        return abs(bm.calc_volume()), closed
    finally:
        bm.free()


def _mass_group(obj):
    return obj.adf.soft if obj.adf.kind == "SOFT_BODY" else obj.adf.body


def mass_from_density(obj) -> float | None:
    """Set the mass of a body to density × mesh volume unless it was typed by hand. A soft body
    takes the volume of its evaluated mesh (what export writes) and must be closed: a sheet has
    no volume, and the reason is kept in ``obj.adf.soft.mass_note`` for the panel."""
    pg = _mass_group(obj)
    soft = obj.adf.kind == "SOFT_BODY"
    if pg.mass_typed or obj.type != "MESH" or not len(obj.data.polygons):
        return None
    vol, closed = mesh_volume(obj, evaluated=soft)
    if soft:
        pg.mass_note = (
            ""
            if closed and vol > 0
            else (
                "no mass from density: the mesh (modifiers applied) is not closed, so it has no volume; "
                "give it thickness (Solidify) or type the mass"
            )
        )
        if pg.mass_note:
            return None
    if vol <= 0:
        return None
    pg.use_mass, pg.mass = True, float(obj.adf.density * vol)
    pg.mass_typed = False
    return pg.mass


def add_collision_primitive(
    obj,
    shape: str = "BOX",
    size=(0.1, 0.1, 0.1),
    radius=0.05,
    height=0.1,
    axis: str = "z",
    offset: Matrix | None = None,
    name: str | None = None,
):
    """A collision primitive of ``obj``: a wire mesh child whose outline follows its size."""
    from .outline import update_outline

    name = name or f"{obj.name}.{shape.lower()}"
    e = _link(bpy.data.objects.new(name, bpy.data.meshes.new(name)))
    e.display_type = "WIRE"
    e.hide_render = True
    e.adf.kind = "COLLISION_SHAPE"
    s = e.adf.shape
    s.shape, s.size, s.radius, s.height, s.axis = shape, size, radius, height, axis
    update_outline(e)
    e.parent = obj
    e.matrix_parent_inverse = Matrix.Identity(4)
    e.matrix_basis = offset or Matrix.Identity(4)
    return e
