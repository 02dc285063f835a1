"""Operators: thin wrappers that report findings in the UI; the work is in authoring/export/build."""

from __future__ import annotations

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

from adfkit.diagnostics import AdfError

from . import authoring
from .properties import KINDS, MESH_FORMATS, SHAPES
from .volumes import ADF_OT_add_volume


def _report(op, exc: AdfError):
    msgs = [f"{d.message}" + (f" — {d.hint}" if d.hint else "") for d in exc.diagnostics]
    op.report({"ERROR"}, "; ".join(msgs))
    return {"CANCELLED"}


class ADF_OT_export(bpy.types.Operator):
    bl_idname = "adf.export_model"
    bl_label = "Export ADF model"
    bl_description = "Validate and write the scene's ADF objects as MODEL.yaml plus meshes"
    directory: StringProperty(subtype="DIR_PATH")
    model_name: StringProperty(name="Model name", default="model")
    use_selection: BoolProperty(
        name="Selected only",
        default=False,
        description="export the selected ADF objects only (joints need both bodies selected)",
    )
    mesh_format: EnumProperty(
        name="Mesh format",
        items=MESH_FORMATS + (("SCENE", "Scene setting", "the format chosen in the sidebar's Export options"),),
        default="SCENE",
    )

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        from .export import export_scene

        objects = list(context.selected_objects) if self.use_selection else None
        fmt = None if self.mesh_format == "SCENE" else self.mesh_format
        res = export_scene(context.scene, self.directory, self.model_name, objects, mesh_format=fmt)
        context.scene.adf.findings = "\n".join(f"{d.severity.name}: {d.message}" for d in res.diagnostics)
        if not res.ok:
            self.report(
                {"ERROR"},
                "Export refused, nothing written: " + "; ".join(d.message for d in res.diagnostics if d.severity >= 2),
            )
            return {"CANCELLED"}
        self.report({"INFO"}, f"Wrote {res.path} ({len(res.skipped)} unchanged meshes kept)")
        return {"FINISHED"}


class ADF_OT_import(bpy.types.Operator):
    bl_idname = "adf.import_model"
    bl_label = "Import ADF model"
    filepath: StringProperty(subtype="FILE_PATH")
    filter_glob: StringProperty(default="*.yaml;*.yml", options={"HIDDEN"})

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        from .build import import_model

        try:
            made, diags = import_model(self.filepath, context.scene)
        except AdfError as exc:
            return _report(self, exc)
        self.report({"INFO"}, f"Imported {len(made)} objects, {len(diags)} findings")
        return {"FINISHED"}


class ADF_OT_mark(bpy.types.Operator):
    bl_idname = "adf.mark"
    bl_label = "Set ADF kind"
    kind: EnumProperty(items=KINDS)

    def execute(self, context):
        for o in context.selected_objects or [context.active_object]:
            authoring.mark(o, self.kind)
        return {"FINISHED"}


class _ActiveBody:
    @classmethod
    def poll(cls, context):
        o = context.active_object
        return o is not None and o.adf.kind in ("BODY", "GHOST", "SOFT_BODY")


class ADF_OT_generate_collision(_ActiveBody, bpy.types.Operator):
    bl_idname = "adf.generate_collision"
    bl_label = "Generate convex collision (CoACD)"
    threshold: FloatProperty(name="Concavity threshold", default=0.05, min=0.01, max=1.0)
    max_hulls: IntProperty(name="Max hulls", default=16, min=-1)

    def execute(self, context):
        try:
            hulls = authoring.generate_collision(context.active_object, self.threshold, self.max_hulls)
        except AdfError as exc:
            return _report(self, exc)
        self.report({"INFO"}, f"{len(hulls)} convex hulls")
        return {"FINISHED"}


class ADF_OT_add_primitive(_ActiveBody, bpy.types.Operator):
    bl_idname = "adf.add_collision_primitive"
    bl_label = "Add collision primitive"
    shape: EnumProperty(items=[(s, s.title(), s.title()) for s in SHAPES])

    def execute(self, context):
        authoring.add_collision_primitive(context.active_object, self.shape)
        return {"FINISHED"}


class ADF_OT_estimate_inertia(_ActiveBody, bpy.types.Operator):
    bl_idname = "adf.estimate_inertia"
    bl_label = "Estimate inertia from mesh"
    bl_description = "Mass (from density, or keep the mass), inertia and inertial offset from the closed mesh"

    def execute(self, context):
        try:
            authoring.estimate_body(context.active_object)
        except AdfError as exc:
            return _report(self, exc)
        return {"FINISHED"}


class ADF_OT_estimate_all(bpy.types.Operator):
    bl_idname = "adf.estimate_all"
    bl_label = "Estimate all bodies"
    bl_description = "Mass (density × volume unless typed by hand), inertia and inertial offset of every ADF body"

    def execute(self, context):
        done, skipped = authoring.estimate_all(context.scene)
        context.scene.adf.findings = "\n".join(f"INFO: not estimated: {s}" for s in skipped)
        self.report({"INFO"}, f"{len(done)} bodies estimated, {len(skipped)} skipped")
        return {"FINISHED"}


class ADF_OT_fit_primitive(_ActiveBody, bpy.types.Operator):
    bl_idname = "adf.fit_collision_primitive"
    bl_label = "Fit collision primitive"
    bl_description = "Replace the body's collision with an oriented primitive fitted around its mesh"
    shape: EnumProperty(items=[(s, s.title(), s.title()) for s in SHAPES], default="CAPSULE")

    def execute(self, context):
        try:
            authoring.fit_collision_primitive(context.active_object, self.shape)
        except AdfError as exc:
            return _report(self, exc)
        return {"FINISHED"}


class ADF_OT_fix_nodes(bpy.types.Operator):
    bl_idname = "adf.fix_selected_nodes"
    bl_label = "Fixed nodes = selected vertices"
    bl_description = "The soft body's fixed nodes become the selected vertices (its fixed-node vertex group)"

    @classmethod
    def poll(cls, context):
        o = context.active_object
        return o is not None and o.adf.kind == "SOFT_BODY" and o.type == "MESH"

    def execute(self, context):
        picked = authoring.fix_selected_nodes(context.active_object)
        self.report({"INFO"}, f"{len(picked)} fixed nodes")
        return {"FINISHED"}


class ADF_OT_estimate_gains(bpy.types.Operator):
    bl_idname = "adf.estimate_gains"
    bl_label = "Estimate joint controller gains"
    bl_description = "P, I and D of every joint (or the selected ones) from what it moves"
    frequency: FloatProperty(name="Frequency (Hz)", default=2.0, min=0.01)
    damping_ratio: FloatProperty(name="Damping ratio", default=1.0, min=0.0)
    selected_only: BoolProperty(
        name="Selected joints only", default=False, description="the selected joints (off: every joint of the scene)"
    )

    def execute(self, context):
        from .tuning import estimate_gains

        pool = context.selected_objects if self.selected_only else context.scene.objects
        joints = [o for o in pool if o.adf.kind == "JOINT"]
        done = estimate_gains(context.scene, joints, self.frequency, self.damping_ratio)
        left = sorted(o.name for o in joints if o.name not in done)
        context.scene.adf.findings = "\n".join(
            f"INFO: no gains for joint {n}: its constraint has no child body" for n in left
        )
        self.report({"INFO"}, f"gains of {len(done)} joints" + (f"; none for {', '.join(left)}" if left else ""))
        return {"FINISHED"}


class ADF_OT_show_joints(bpy.types.Operator):
    bl_idname = "adf.show_joints"
    bl_label = "Show/hide joints"
    show: BoolProperty(name="Show", default=True)
    passive_only: BoolProperty(name="Passive joints only", default=False)

    def execute(self, context):
        from .tuning import show_joints

        show_joints(context.scene, self.show, self.passive_only)
        return {"FINISHED"}


_SELECTED_ONLY = {
    "name": "Selected only",
    "default": False,
    "description": "the selected objects (off: the whole scene)",
}


class ADF_OT_show_collision(bpy.types.Operator):
    bl_idname = "adf.show_collision"
    bl_label = "Show/hide collision shapes"
    bl_description = "Show or hide the collision shapes and meshes of every body (or of the selected ones)"
    show: BoolProperty(name="Show", default=False)
    selected_only: BoolProperty(**_SELECTED_ONLY)

    def execute(self, context):
        from .tuning import show_collision

        objs = list(context.selected_objects) if self.selected_only else None
        self.report({"INFO"}, f"{show_collision(context.scene, self.show, objs)} collision objects")
        return {"FINISHED"}


class ADF_OT_rename_joints(bpy.types.Operator):
    bl_idname = "adf.rename_joints"
    bl_label = "Name joints after their bodies"
    bl_description = "Rename every joint (or the selected ones) 'parent-child' from its constraint's bodies"
    selected_only: BoolProperty(**_SELECTED_ONLY)

    def execute(self, context):
        from .tuning import rename_joints

        objs = list(context.selected_objects) if self.selected_only else None
        self.report({"INFO"}, f"{len(rename_joints(context.scene, objs))} joints named")
        return {"FINISHED"}


class ADF_OT_cleanup(bpy.types.Operator):
    bl_idname = "adf.cleanup"
    bl_label = "Clean up ADF scene"
    bl_description = "Remove joints without bodies and stray collision objects; clear ADF data of unmarked objects"

    def execute(self, context):
        from .tuning import cleanup

        said = cleanup(context.scene)
        context.scene.adf.findings = "\n".join(f"INFO: {s}" for s in said)
        self.report({"INFO"}, f"{len(said)} clean-ups")
        return {"FINISHED"}


class ADF_OT_strip(bpy.types.Operator):
    bl_idname = "adf.strip"
    bl_label = "Remove ADF data from selected"

    def execute(self, context):
        from .tuning import strip

        self.report({"INFO"}, f"{strip(context.selected_objects)} objects made plain")
        return {"FINISHED"}


class ADF_OT_add_joint(bpy.types.Operator):
    bl_idname = "adf.add_joint"
    bl_label = "Add joint (active = child)"
    joint_type: EnumProperty(
        items=[
            (t, t, t)
            for t in (
                "revolute",
                "prismatic",
                "fixed",
                "six dof spring",
                "linear spring",
                "torsion spring",
                "p2p",
                "six dof",
                "cone twist",
            )
        ]
    )

    def execute(self, context):
        child = context.active_object
        others = [o for o in context.selected_objects if o is not child]
        if child is None or len(others) != 1:
            self.report({"ERROR"}, "Select the parent body, then the child body (active)")
            return {"CANCELLED"}
        authoring.add_joint(others[0], child, self.joint_type)
        return {"FINISHED"}


class ADF_OT_rope(bpy.types.Operator):
    bl_idname = "adf.create_rope"
    bl_label = "Create thread"
    bl_description = "A chain of capsule bodies joined by six-dof springs"

    def execute(self, context):
        p = context.scene.adf
        authoring.create_rope(
            "Thread", p.rope_count, p.rope_length, p.rope_radius, p.rope_mass, tuple(context.scene.cursor.location)
        )
        return {"FINISHED"}


class ADF_OT_grasp(bpy.types.Operator):
    bl_idname = "adf.add_grasp"
    bl_label = "Add grasp sensor + actuator"

    def execute(self, context):
        try:
            authoring.add_grasp(context.active_object)
        except AdfError as exc:
            return _report(self, exc)
        return {"FINISHED"}


class ADF_OT_ghost(bpy.types.Operator):
    bl_idname = "adf.add_ghost"
    bl_label = "Add ghost object"

    def execute(self, context):
        o = context.active_object
        authoring.add_ghost("Ghost", parent=o if o is not None and o.adf.kind == "BODY" else None)
        return {"FINISHED"}


class ADF_OT_check(bpy.types.Operator):
    bl_idname = "adf.check"
    bl_label = "Check model"

    def execute(self, context):
        found = authoring.problems(context.scene)
        context.scene.adf.findings = "\n".join(found)
        self.report({"WARNING"} if found else {"INFO"}, f"{len(found)} findings" if found else "No findings")
        return {"FINISHED"}


CLASSES = (
    ADF_OT_export,
    ADF_OT_import,
    ADF_OT_mark,
    ADF_OT_generate_collision,
    ADF_OT_add_primitive,
    ADF_OT_estimate_inertia,
    ADF_OT_add_joint,
    ADF_OT_rope,
    ADF_OT_grasp,
    ADF_OT_ghost,
    ADF_OT_check,
    ADF_OT_estimate_all,
    ADF_OT_fit_primitive,
    ADF_OT_estimate_gains,
    ADF_OT_show_joints,
    ADF_OT_cleanup,
    ADF_OT_strip,
    ADF_OT_fix_nodes,
    ADF_OT_show_collision,
    ADF_OT_rename_joints,
    ADF_OT_add_volume,
)


def _menu_export(self, context):
    self.layout.operator(ADF_OT_export.bl_idname, text="AMBF Description Format (.yaml)")


def _menu_import(self, context):
    self.layout.operator(ADF_OT_import.bl_idname, text="AMBF Description Format (.yaml)")


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)
    bpy.types.TOPBAR_MT_file_export.append(_menu_export)
    bpy.types.TOPBAR_MT_file_import.append(_menu_import)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(_menu_import)
    bpy.types.TOPBAR_MT_file_export.remove(_menu_export)
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
