"""Operators for a modeller's naming, placement and collision tools (AMBF's own add-on had them):
strip namespaces from object names, move a collision mesh to its body's origin or keep its
current location, fit every body's collision primitive, low-res modifiers. Thin wrappers: the
work is in :mod:`.namespaces`, :mod:`.collision_place`, :mod:`.authoring` and :mod:`.lowres`."""

from __future__ import annotations

import bpy

from adfkit.diagnostics import AdfError

from .properties import SHAPES


class ADF_OT_strip_namespaces(bpy.types.Operator):
    bl_idname = "adf.strip_namespaces"
    bl_label = "Strip namespaces"
    bl_description = (
        "Remove the 'namespace/' prefix from ADF object names; the namespace becomes the model's when they all share it"
    )

    def execute(self, context):
        from .namespaces import strip_namespaces

        said = strip_namespaces(context.scene)
        context.scene.adf.findings = "\n".join(f"INFO: {s}" for s in said)
        self.report({"INFO"}, "; ".join(said) if said else "No object name has a namespace")
        return {"FINISHED"}


def _collision_meshes(objs) -> list:
    """The selected collision meshes, and those of the selected bodies (AMBF's add-on acted on
    the active body's collision mesh)."""
    out = []
    for o in objs:
        kids = [o] if o.adf.kind == "COLLISION_MESH" else []
        if o.adf.kind in ("BODY", "GHOST", "SOFT_BODY"):
            kids = sorted((c for c in o.children if c.adf.kind == "COLLISION_MESH"), key=lambda c: c.name)
        out += [k for k in kids if k not in out]
    return out


class _CollisionPlacement:
    @classmethod
    def poll(cls, context):
        return bool(_collision_meshes(context.selected_objects))

    def execute(self, context):
        from . import collision_place

        done = []
        for o in _collision_meshes(context.selected_objects):
            try:
                getattr(collision_place, self.action)(o)
            except AdfError as exc:
                d = exc.diagnostics[0]
                self.report({"ERROR"}, f"{d.message} — {d.hint}")
                return {"CANCELLED"}
            done.append(o.name)
        self.report({"INFO"}, f"{len(done)} collision meshes placed")
        return {"FINISHED"}


class ADF_OT_collision_to_body_origin(_CollisionPlacement, bpy.types.Operator):
    bl_idname = "adf.collision_to_body_origin"
    bl_label = "Move collision mesh to body origin"
    bl_description = (
        "Put the selected collision meshes (or the selected bodies' ones) on their body's origin, where AMBF reads them"
    )
    action = "move_to_body_origin"


class ADF_OT_collision_use_current_location(_CollisionPlacement, bpy.types.Operator):
    bl_idname = "adf.collision_use_current_location"
    bl_label = "Use current location of collision mesh"
    bl_description = (
        "Keep the selected collision meshes (or the selected bodies' ones) where they are: their offset goes "
        "into their vertices and their origin onto the body's"
    )
    action = "use_current_location"


class ADF_OT_fit_all_collision(bpy.types.Operator):
    bl_idname = "adf.fit_all_collision"
    bl_label = "Fit collision primitives (all bodies)"
    bl_description = (
        "Fit a collision primitive around every body's mesh: each body's own primitive again, a box where it has "
        "none (or the shape chosen); compounds and collision meshes are left as they are"
    )
    shape: bpy.props.EnumProperty(
        name="Shape",
        items=[("AUTO", "Each body's own", "each body's one primitive in its own shape; a box where it has none")]
        + [(s, s.title(), s.title()) for s in SHAPES],
        default="AUTO",
    )

    def execute(self, context):
        from .authoring import fit_all

        done, skipped = fit_all(context.scene, self.shape)
        context.scene.adf.findings = "\n".join(f"INFO: not fitted: {s}" for s in skipped)
        self.report({"INFO"}, f"{len(done)} bodies fitted, {len(skipped)} left as they are")
        return {"FINISHED"}


class ADF_OT_add_low_res_modifiers(bpy.types.Operator):
    bl_idname = "adf.add_low_res_modifiers"
    bl_label = "Add low-res modifiers"
    bl_description = (
        "A Decimate modifier on every body mesh with more vertices than the limit: export writes the collision "
        "(low-res) copy of the visual mesh with it, the visual mesh without"
    )
    max_vertices: bpy.props.IntProperty(name="Vertices", default=150, min=4, description="about this many at most")

    def execute(self, context):
        from .lowres import add

        made = add(context.scene, self.max_vertices)
        self.report({"INFO"}, f"low-res modifiers on {len(made)} meshes")
        return {"FINISHED"}


class ADF_OT_toggle_low_res_modifiers(bpy.types.Operator):
    bl_idname = "adf.toggle_low_res_modifiers"
    bl_label = "Show/hide low-res modifiers"
    bl_description = "Show the low-res (collision) meshes in the viewport, or the visual ones; export is not affected"

    def execute(self, context):
        from .lowres import toggle

        self.report({"INFO"}, f"{toggle(context.scene)} low-res modifiers")
        return {"FINISHED"}


class ADF_OT_remove_low_res_modifiers(bpy.types.Operator):
    bl_idname = "adf.remove_low_res_modifiers"
    bl_label = "Remove low-res modifiers"
    bl_description = "Remove the low-res modifiers (other modifiers, a Solidify, stay)"

    def execute(self, context):
        from .lowres import remove

        self.report({"INFO"}, f"{remove(context.scene)} low-res modifiers removed")
        return {"FINISHED"}


CLASSES = (
    ADF_OT_strip_namespaces,
    ADF_OT_collision_to_body_origin,
    ADF_OT_collision_use_current_location,
    ADF_OT_fit_all_collision,
    ADF_OT_add_low_res_modifiers,
    ADF_OT_toggle_low_res_modifiers,
    ADF_OT_remove_low_res_modifiers,
)


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
