"""Blender soft body -> adfkit SoftBody: its keys, its evaluated mesh (through gather's geometry)
and its `fixed nodes`, numbered on the mesh export writes as AMBF numbers that file."""

from __future__ import annotations

import numpy as np

from adfkit.diagnostics import error
from adfkit.model.objects import SoftBody

from . import exact, fields, gather
from .properties import read_group


def fixed_nodes(obj, evaluated: bool = False, corners: bool = False) -> list[int] | None:
    """Node indices of the vertices in the soft body's fixed-node vertex group (None: no group),
    counted on the mesh export writes: with ``evaluated``, the one its modifiers make (a
    Solidify copies the group to the new shell's vertices, so both faces of a fixed rim stay);
    with ``corners``, numbered as a file of triangle corners (STL) gives its vertices."""
    grp = obj.vertex_groups.get(obj.adf.soft.fixed_group) if obj.type == "MESH" else None
    if grp is None:
        return None
    eo = me = None
    if evaluated and len(obj.modifiers):
        import bpy

        eo = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        me = eo.to_mesh()
    try:
        data = me if me is not None else obj.data
        members = [v.index for v in data.vertices if any(g.group == grp.index and g.weight > 0 for g in v.groups)]
        if not members:
            return []
        from adfkit.geometry.softmesh import nodes_at, unique_nodes

        co = np.empty(len(data.vertices) * 3, np.float32)
        data.vertices.foreach_get("co", co)
        co = co.reshape(-1, 3).astype(np.float64)
        seen = co
        if corners:
            data.calc_loop_triangles()
            t = np.empty(len(data.loop_triangles) * 3, np.int32)
            data.loop_triangles.foreach_get("vertices", t)
            seen = co[t]
        # AMBF's numbering: unique vertex positions in order of first appearance
        return nodes_at(unique_nodes(seen, np.zeros((0, 3), dtype=np.int64)), co[members])
    finally:
        if eo is not None:
            eo.to_mesh_clear()


def gather_soft_body(obj, out: gather.Gathered, paths: tuple[str, str]) -> SoftBody:
    from adfkit.model.objects import SoftBodyConfig

    sb = fields.from_snapshot(SoftBody, obj.adf.snapshot, f"blender:{obj.name}")
    sb.identifier = gather.identifier(obj)
    if sb.name is None:
        sb.name = obj.name
    try:
        fields.merge(sb, fields.SOFT, exact.applied(obj, read_group(obj.adf.soft, fields.SOFT)))
    except ValueError as exc:
        out.diagnostics.append(error("body-value", f"soft body '{obj.name}': {exc}", gather.where(obj)))
    gather._pose_and_scale(obj, sb)
    gather._gather_geometry(obj, sb, out, paths)
    from adfkit.geometry.meshwrite import VERTEX_ORDER_KEPT, format_of

    corners = bool(sb.mesh) and format_of(sb.mesh) not in (None, *VERTEX_ORDER_KEPT)
    fixed = fixed_nodes(obj, evaluated=out.options.apply_modifiers, corners=corners)
    old = sb.config.fixed_nodes if sb.config is not None else None
    if fixed is not None and sorted(set(old or [])) != fixed and not (fixed == [] and old is None):
        if sb.config is None:
            sb.config = SoftBodyConfig()
        sb.config.fixed_nodes = fixed
    if obj.type != "MESH" and not sb.mesh:
        out.diagnostics.append(
            error(
                "soft-body-mesh",
                f"soft body '{obj.name}' has no mesh",
                gather.where(obj),
                "a soft body's nodes are its mesh's vertices: make it a mesh object",
            )
        )
    return sb
