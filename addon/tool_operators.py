"""Operators for a modeller's naming and placement tools (AMBF's own add-on had them): strip
namespaces from object names, move a collision mesh to its body's origin or keep its current
location. Thin wrappers: the work is in :mod:`.namespaces` and :mod:`.collision_place`."""

from __future__ import annotations

import bpy

from adfkit.diagnostics import AdfError


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


CLASSES = (ADF_OT_strip_namespaces, ADF_OT_collision_to_body_origin, ADF_OT_collision_use_current_location)


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
