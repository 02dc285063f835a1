"""Panels: Properties editor (Object tab) and the 3D view N-panel, drawn from the field tables."""

from __future__ import annotations

import bpy

from . import fields
from .properties import group


def _visible(kind: str, pg, f: fields.Field) -> bool:
    if kind == "SENSOR":
        return f.prop not in fields.RESISTANCE_ONLY or (pg.use_type and pg.type.lower() == "resistance")
    if kind != "JOINT":
        return True
    t = pg.type
    six = t in ("six dof", "six dof spring")
    spring_axes = (
        "damping_linear",
        "damping_angular",
        "stiffness_linear",
        "stiffness_angular",
        "equilibrium_linear",
        "equilibrium_angular",
    )
    if f.prop in ("linear_low", "linear_high", "angular_low", "angular_high"):
        return six
    if f.prop in spring_axes:
        return t == "six dof spring"
    if f.prop == "cone_limits":
        return t == "cone twist"
    if f.prop in ("limit_low", "limit_high"):
        return not six and t not in ("cone twist", "p2p", "fixed")
    if f.prop in ("damping", "stiffness", "equilibrium"):
        return "spring" in t and t != "six dof spring"
    return True


def draw_object(layout, obj) -> None:
    adf = obj.adf
    layout.prop(adf, "kind")
    if adf.kind == "NONE":
        return
    layout.prop(adf, "identifier")
    pg = group(obj)
    if adf.kind == "COLLISION_SHAPE":
        s = adf.shape
        layout.prop(s, "shape")
        if s.shape == "BOX":
            layout.prop(s, "size")
        else:
            layout.prop(s, "radius")
            if s.shape != "SPHERE":
                layout.prop(s, "height")
                layout.prop(s, "axis")
        return
    if adf.kind == "COLLISION_MESH" or any(c.adf.kind == "COLLISION_MESH" for c in obj.children):
        layout.operator("adf.collision_to_body_origin")
        layout.operator("adf.collision_use_current_location")
    if pg is None:
        return
    table = fields.TABLES[adf.kind][1]
    for f in table:
        if not _visible(adf.kind, pg, f):
            continue
        row = layout.row(align=True)
        row.prop(pg, "use_" + f.prop, text="")
        sub = row.row()
        sub.enabled = getattr(pg, "use_" + f.prop)
        sub.prop(pg, f.prop)
    if adf.kind == "SOFT_BODY":
        layout.prop(adf, "density")
        if pg.mass_note and not pg.mass_typed:
            layout.label(text=pg.mass_note, icon="ERROR")
        elif pg.use_mass and not pg.mass_typed:
            layout.label(text="Mass from density × volume of the mesh with its modifiers", icon="INFO")
        if obj.type == "MESH":
            layout.prop_search(pg, "fixed_group", obj, "vertex_groups", text="Fixed nodes")
            layout.operator("adf.fix_selected_nodes")
            if pg.fixed_group not in obj.vertex_groups:
                layout.label(text="No such vertex group: no fixed nodes written", icon="INFO")
        else:
            layout.label(text="A soft body needs a mesh: its vertices are the nodes", icon="ERROR")
    if adf.kind == "BODY":
        if not pg.use_mass:
            layout.label(text="No mass: AMBF warns and uses 1 kg with an estimated inertia", icon="ERROR")
        elif pg.mass_note and not pg.mass_typed:
            layout.label(text=pg.mass_note, icon="ERROR")
        elif not pg.mass_typed:
            layout.label(text="Mass from density × volume (type a mass to keep it)", icon="INFO")
        try:
            fields.parse_groups(pg.collision_groups)
        except ValueError as exc:
            layout.label(text=str(exc), icon="ERROR")
        layout.prop(adf, "density")
        col = layout.column(align=True)
        col.operator("adf.estimate_inertia")
        col.operator("adf.generate_collision")
        col.operator_menu_enum("adf.fit_collision_primitive", "shape")
        col.operator_menu_enum("adf.add_collision_primitive", "shape")
        row = col.row(align=True)
        row.operator("adf.show_collision", text="Show its collision").selected_only = True
        op = row.operator("adf.show_collision", text="Hide its collision")
        op.show, op.selected_only = False, True
        col.operator("adf.add_grasp")
    if adf.kind == "JOINT":
        layout.prop(pg, "axis")
        col = layout.column(align=True)
        col.operator("adf.estimate_gains", text="Estimate gains of the selected joints").selected_only = True
        col.operator("adf.rename_joints", text="Name the selected joints after their bodies").selected_only = True
        rbc = obj.rigid_body_constraint
        if rbc is None or rbc.object1 is None or rbc.object2 is None:
            external = [e for e in str(obj.get("adf_external_ends", "")).split(",") if e]
            missing = [r for r, o in (("parent", rbc and rbc.object1), ("child", rbc and rbc.object2)) if o is None]
            if missing and set(missing) <= set(external):
                layout.label(
                    text=f"The {' and '.join(missing)} body is in another file: exported as written", icon="INFO"
                )
            else:
                layout.label(
                    text="Set the constraint's parent (Object 1) and child (Object 2) bodies: "
                    "export refuses the joint until then",
                    icon="ERROR",
                )
    if adf.kind == "SENSOR":
        layout.label(text=f"{len(pg.rays)} rays")
        for r in pg.rays:
            row = layout.row()
            row.prop(r, "offset", text="")
            row.prop(r, "direction", text="")


class ADF_PT_object(bpy.types.Panel):
    bl_label = "ADF"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        return context.object is not None

    def draw(self, context):
        draw_object(self.layout, context.object)


#: The model-level keys the sidebar shows, each with its "write it" switch.
MODEL_KEYS = ("namespace", "gravity", "ignore_inter_collision")


class ADF_PT_sidebar(bpy.types.Panel):
    bl_label = "ADF"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "ADF"

    def draw(self, context):
        lay = self.layout
        sc = context.scene.adf
        col = lay.column(align=True)
        col.operator("adf.import_model")
        col.operator("adf.export_model")
        col.operator("adf.check")
        for key in MODEL_KEYS:
            row = lay.row(align=True)
            row.prop(sc, "use_" + key, text="")
            sub = row.row()
            sub.enabled = getattr(sc, "use_" + key)
            sub.prop(sc, key)
        box = lay.box()
        box.label(text="Export")
        box.prop(sc, "precision")
        box.prop(sc, "apply_modifiers")
        box.prop(sc, "low_res_ratio")
        box.prop(sc, "mesh_format")
        box.prop(sc, "meshes_path")
        row = box.row(align=True)
        for key in ("save_high_res", "save_low_res", "save_textures"):
            row.prop(sc, key, toggle=True)
        row = box.row(align=True)
        row.operator("adf.add_low_res_modifiers", text="Low-res modifiers")
        row.operator("adf.toggle_low_res_modifiers", text="Show/hide")
        row.operator("adf.remove_low_res_modifiers", text="Remove")
        col = lay.column(align=True)
        col.operator("adf.estimate_all")
        col.operator_menu_enum("adf.fit_all_collision", "shape")
        col.operator("adf.estimate_gains")
        row = col.row(align=True)
        row.operator("adf.show_joints", text="Show joints").show = True
        row.operator("adf.show_joints", text="Hide joints").show = False
        op = row.operator("adf.show_joints", text="Hide passive")
        op.show, op.passive_only = False, True
        row = col.row(align=True)
        row.operator("adf.show_collision", text="Show collision").show = True
        row.operator("adf.show_collision", text="Hide collision").show = False
        col.operator("adf.rename_joints")
        col.operator("adf.strip_namespaces")
        col.operator("adf.cleanup")
        col.operator("adf.strip")
        box = lay.box()
        box.label(text="Thread")
        box.prop(sc, "rope_count")
        box.prop(sc, "rope_length")
        box.prop(sc, "rope_radius")
        box.prop(sc, "rope_mass")
        box.operator("adf.create_rope")
        lay.operator("adf.add_ghost")
        lay.operator("adf.add_hole_pair")
        lay.operator("adf.add_volume")
        lay.operator_menu_enum("adf.add_joint", "joint_type")
        for line in sc.findings.splitlines()[:12]:
            lay.label(text=line, icon="ERROR" if line.startswith("ERROR") else "INFO")
        if context.object is not None:
            draw_object(lay.box(), context.object)


CLASSES = (ADF_PT_object, ADF_PT_sidebar)


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
