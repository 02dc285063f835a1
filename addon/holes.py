"""Hole helpers for a suturing phantom: an entry or exit hole as `adfkit suture` reads one.

A hole is a static body ``Entry k`` / ``Exit k`` (a small disc to see) framed by four capsules
around a square opening, its z along the needle's path out of the tissue, and its ghost
``ghostEntry k`` / ``ghostExit k``: a thin box on the hole, whose name makes the runner apply
the hole's viscous friction to what passes through it. A pair's two holes are tilted along the
arc of a needle of the given radius through both, as the bundled phantom's are.
"""

from __future__ import annotations

import math

import bpy
from mathutils import Matrix, Vector

from .elements import _link, add_collision_primitive

OPENING = 0.0048  # m: the free square inside the capsules (the bundled phantom's)
CAPSULE_RADIUS = 0.0006
GHOST_SIZE = (0.005, 0.005, 0.00045)
DISC = (0.0014, 0.0003)  # m: the hole's visual disc, radius and thickness
NEEDLE_RADIUS = 0.0094  # m: the bundled needle's circle
PAIR_DISTANCE = 0.014  # m from entry to exit, the bundled phantom's


def _disc(name: str):
    bpy.ops.mesh.primitive_cylinder_add(vertices=16, radius=DISC[0], depth=DISC[1])
    o = bpy.context.active_object
    o.name = o.data.name = name
    return o


def add_hole(kind: str, k: int, matrix: Matrix, opening: float = OPENING, radius: float = CAPSULE_RADIUS):
    """Hole ``kind`` ("Entry" or "Exit") number ``k`` at ``matrix`` (its z out of the tissue
    along the needle's path): the static body with its four capsules, and its ghost. Returns
    (body, ghost)."""
    from .authoring import mark

    name = f"{kind}{k}"
    body = _disc(name)
    body.matrix_world = matrix
    mark(body, "BODY")
    b = body.adf.body
    b.use_mass, b.mass, b.mass_typed = True, 0.0, True  # static, as tissue is
    # no friction on the boundary (the ghost's viscous friction holds what passes through; the
    # default 0.5 held the thread back at the capsules and it did not follow the needle through)
    b.use_friction_static, b.friction_static = True, 0.0
    b.use_friction_rolling, b.friction_rolling = True, 0.0
    off = opening / 2 + radius
    for axis, at in (("x", (0.0, -off, 0.0)), ("x", (0.0, off, 0.0)), ("y", (off, 0.0, 0.0)), ("y", (-off, 0.0, 0.0))):
        add_collision_primitive(
            body, "CAPSULE", radius=radius, height=2 * off + 0.001, axis=axis, offset=Matrix.Translation(at)
        )
    ghost = _link(bpy.data.objects.new(f"ghost{name}", None))
    ghost.adf.kind = "GHOST"
    ghost.empty_display_type, ghost.empty_display_size = "CUBE", GHOST_SIZE[0] / 2
    ghost.parent = body
    ghost.matrix_parent_inverse = Matrix.Identity(4)
    add_collision_primitive(ghost, "BOX", size=GHOST_SIZE)
    bpy.context.view_layer.update()  # the children's world matrices, which export reads
    return body, ghost


def hole_pair_frames(
    centre, direction, up=(0.0, 0.0, 1.0), distance: float = PAIR_DISTANCE, needle_radius: float = NEEDLE_RADIUS
) -> tuple[Matrix, Matrix]:
    """World frames of the entry and the exit of a pair: ``distance`` apart along ``direction``
    (from entry to exit) about ``centre`` on the tissue's surface (``up`` out of it), each
    tilted about the axis across the pair so that its z is the path, out of the tissue, of a
    needle of ``needle_radius`` turning through both."""
    up = Vector(up).normalized()
    x = Vector(direction) - Vector(direction).dot(up) * up
    x.normalize()
    y = up.cross(x)
    if distance >= 2 * needle_radius:
        raise ValueError(
            f"holes {distance * 1000:.1f} mm apart: a needle of {needle_radius * 1000:.1f} mm radius spans less"
        )
    tilt = math.asin(math.sqrt(needle_radius**2 - (distance / 2) ** 2) / needle_radius)
    base = Matrix((x, y, up)).transposed().to_4x4()
    out = []
    for sign in (-1.0, 1.0):
        frame = Matrix.Translation(Vector(centre) + sign * distance / 2 * x) @ base
        out.append(frame @ Matrix.Rotation(sign * tilt, 4, "Y"))
    return out[0], out[1]


def add_hole_pair(k: int, centre, direction=(1.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), distance: float = PAIR_DISTANCE):
    """Entry k and Exit k (bodies and ghosts) about ``centre`` (see hole_pair_frames). Returns
    (entry body, exit body)."""
    entry, exit_ = hole_pair_frames(centre, direction, up, distance)
    return add_hole("Entry", k, entry)[0], add_hole("Exit", k, exit_)[0]


class ADF_OT_add_hole_pair(bpy.types.Operator):
    bl_idname = "adf.add_hole_pair"
    bl_label = "Add hole pair"
    bl_description = (
        "Entry k and Exit k for the suture (bodies framed by capsules, and their ghosts), about the 3D "
        "cursor on the tissue's surface: from entry to exit along the cursor's X, out of the tissue along its Z"
    )
    bl_options = {"REGISTER", "UNDO"}

    number: bpy.props.IntProperty(name="Pair", default=1, min=1, description="k of Entry k and Exit k")
    distance: bpy.props.FloatProperty(
        name="Entry to exit", default=PAIR_DISTANCE, min=0.001, unit="LENGTH", description="distance between the holes"
    )

    def execute(self, context):
        cursor = context.scene.cursor.matrix
        try:
            add_hole_pair(self.number, cursor.translation, cursor.col[0].xyz, cursor.col[2].xyz, self.distance)
        except ValueError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        return {"FINISHED"}


def register():
    bpy.utils.register_class(ADF_OT_add_hole_pair)


def unregister():
    bpy.utils.unregister_class(ADF_OT_add_hole_pair)


__all__ = ["add_hole", "add_hole_pair", "hole_pair_frames"]
