"""Blender objects the add-on makes or measures, below both the importer (build.py) and the
authoring tools (authoring.py): linking an object into the scene, a collision primitive child,
a body's mass from its density and mesh volume. Nothing here imports the add-on's upper layers."""

from __future__ import annotations

import bpy
from mathutils import Matrix

from . import exact, lowres
from .precision import FLOAT32_DIGITS, rounded, typed


def _link(obj, scene=None):
    (scene or bpy.context.scene).collection.objects.link(obj)
    return obj


def exported_evaluated() -> bool:
    """Whether export writes bodies' evaluated meshes (modifiers applied): the scene's *Apply
    modifiers*. The geometry tools measure the same mesh."""
    return bool(bpy.context.scene.adf.apply_modifiers)


def digits() -> int:
    """The scene's *Float digits*: the most significant digits a computed value is written with."""
    return int(bpy.context.scene.adf.precision)


def mesh_volume(obj, evaluated: bool = False) -> tuple[float, bool]:
    """(volume in m³ with the object's scale, closed?) of a mesh object, its modifiers applied
    when ``evaluated`` (a Solidify gives a sheet its thickness); an open mesh gives its convex
    hull's volume (bmesh, no geometry packages needed). Computed in float64 from the
    coordinates as typed (precision.typed): a 4 cm cube holds 6.4e-05 m³, not 6.3999996e-05."""
    import bmesh
    import numpy as np

    bm = bmesh.new()
    try:
        if evaluated and len(obj.modifiers):
            with lowres.shown([obj], False):  # the visual mesh: low-res modifiers make the collision
                bm.from_object(obj, bpy.context.evaluated_depsgraph_get())
        else:
            bm.from_mesh(obj.data)
        closed = len(bm.faces) > 0 and all(e.is_manifold for e in bm.edges)
        if not closed and len(bm.verts) >= 4:
            bmesh.ops.convex_hull(bm, input=bm.verts[:], use_existing_faces=False)
            for f in [f for f in bm.faces if not f.is_valid]:
                bm.faces.remove(f)
        bmesh.ops.triangulate(bm, faces=bm.faces[:])
        bm.verts.index_update()
        co = typed([v.co[:] for v in bm.verts]).reshape(-1, 3) * typed(obj.matrix_world.to_scale()[:])
        tris = np.array([[v.index for v in f.verts] for f in bm.faces], dtype=np.int64).reshape(-1, 3)
        a, b, c = co[tris[:, 0]], co[tris[:, 1]], co[tris[:, 2]]
        return abs(float(np.einsum("ij,ij->", a, np.cross(b, c)))) / 6.0, closed
    finally:
        bm.free()


def _mass_group(obj):
    return obj.adf.soft if obj.adf.kind == "SOFT_BODY" else obj.adf.body


def mass_from_density(obj) -> float | None:
    """Set the mass of a body to density × volume of the mesh export writes (its modifiers
    applied, with *Apply modifiers*) unless it was typed by hand. A soft body's mesh must be
    closed; a body's open mesh counts its convex hull. Where the mesh has no volume (a sheet) the
    mass is left as it is and the reason kept in ``mass_note`` for the panel."""
    pg = _mass_group(obj)
    soft = obj.adf.kind == "SOFT_BODY"
    if pg.mass_typed or obj.type != "MESH" or not len(obj.data.polygons):
        return None
    vol, closed = mesh_volume(obj, evaluated=exported_evaluated())
    if soft and not closed:
        pg.mass_note = (
            "no mass from density: the mesh (modifiers applied) is not closed, so it has no volume; "
            "give it thickness (Solidify) or type the mass"
        )
        return None
    if vol <= 0:
        pg.mass_note = (
            "no mass from density: the mesh (modifiers applied) is flat, so it has no volume; "
            "give it thickness (Solidify) or type the mass"
        )
        return None
    pg.mass_note = ""
    mass = rounded(obj.adf.density * vol, min(digits(), FLOAT32_DIGITS))  # what float32 coordinates hold
    pg.use_mass, pg.mass = True, mass
    pg.mass_typed = False
    exact.keep(obj, mass=mass)
    return mass


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
