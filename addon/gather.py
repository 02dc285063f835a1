"""Blender scene -> adfkit model: one small gatherer per ADF object kind.

Blender-level code only reads Blender data here; ADF semantics come from adfkit and
:mod:`.fields`. Mesh files are not written here: gatherers return *mesh jobs* that the
exporter runs only after the model has been validated.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from adfkit.diagnostics import Diagnostic, SourceLocation, error, info, warning
from adfkit.model import Actuator, Body, Camera, Ghost, Joint, Light, ModelFile, Pose, Sensor
from adfkit.model.common import Geometry, ShapeEntry
from adfkit.model.objects import Ray, SoftBody
from adfkit.model.pose import Quat, Vec3

from . import exact, fields, joint_frames, lowres, meshes, meshformat
from .properties import read_group

MESH_DIRS = ("meshes/high_res/", "meshes/low_res/")


@dataclass
class MeshJob:
    directory: str  # relative to the output directory
    filename: str
    digest: str
    parts: list | None = None  # MeshArrays to write, or None to copy ``source``
    source: Path | None = None
    whole: bool = False  # a soft body's mesh: never split into several 3DS objects (its node numbering)
    low: bool = False  # a low-resolution (collision) mesh, not a visual one


@dataclass
class Options:
    apply_modifiers: bool = True  # export the evaluated mesh (depsgraph)
    low_res_ratio: float = 1.0  # decimate collision meshes made from the visual one
    mesh_format: str = "OBJ"  # format of the meshes written ('OBJ', 'STL', 'PLY', '3DS')


@dataclass
class Gathered:
    model: ModelFile
    jobs: list[MeshJob] = field(default_factory=list)
    diagnostics: list[Diagnostic] = field(default_factory=list)
    options: Options = field(default_factory=Options)


def where(obj) -> SourceLocation:
    return SourceLocation(f"blender:{obj.name}")


def identifier(obj) -> str:
    return obj.adf.identifier or fields.PREFIX.get(obj.adf.kind, "") + obj.name


def matrix_key(obj) -> str:
    return json.dumps([round(float(v), 9) for row in obj.matrix_world for v in row])


def unchanged(obj) -> bool:
    """True while the object sits where it was at import (exact snapshot poses apply)."""
    return bool(obj.adf.snapshot_matrix) and obj.adf.snapshot_matrix == matrix_key(obj)


def world_pose(obj) -> Pose:
    loc, rot, _ = obj.matrix_world.decompose()
    return Pose(Vec3(*map(fields.tidy, loc)), Quat(float(rot.x), float(rot.y), float(rot.z), float(rot.w)).normalized())


def uniform_scale(obj) -> float:
    s = obj.matrix_world.to_scale()
    return float(sum(s) / 3.0)


def relative_pose(obj, parent) -> Pose:
    if parent is None:
        return world_pose(obj)
    p = world_pose(parent).inverse() * world_pose(obj)
    return Pose(Vec3(*(round(c, 12) + 0.0 for c in p.position)), p.orientation)


def adf_parent(obj):
    p = obj.parent
    while p is not None and p.adf.kind != "BODY":
        p = p.parent
    return p


# --- bodies and ghosts ---------------------------------------------------------------------


def gather_body(obj, out: Gathered, paths: tuple[str, str]) -> Body:
    b = fields.from_snapshot(Body, obj.adf.snapshot, f"blender:{obj.name}")
    b.identifier = identifier(obj)
    if b.name is None:
        b.name = obj.name
    values = exact.applied(obj, read_group(obj.adf.body, fields.BODY))
    if values.get("mass") is None:
        # refused when authored here; a file imported without mass is carried through as AMBF loads it
        out.diagnostics.append(
            (warning if obj.adf.snapshot and b.mass is None else error)(
                "body-mass",
                f"body '{obj.name}' has no mass",
                where(obj),
                "tick 'Write Mass' in the ADF Body panel (0 makes it static)",
            )
        )
    try:
        fields.merge(b, fields.BODY, values)
    except ValueError as exc:
        out.diagnostics.append(error("body-value", f"body '{obj.name}': {exc}", where(obj)))
    _pose_and_scale(obj, b)
    _gather_geometry(obj, b, out, paths)
    return b


def _pose_and_scale(obj, b) -> None:
    if not unchanged(obj):  # unchanged: the location as the file wrote it (or left it out)
        b.location = world_pose(obj)
    s = uniform_scale(obj)
    old = b.scale if b.scale is not None else 1.0
    if not unchanged(obj) and abs(s - old) > 1e-6 * max(1.0, abs(old)):  # matrix decomposition noise
        b.scale = round(s, 9)


def gather_ghost(obj, out: Gathered, paths: tuple[str, str]) -> Ghost:
    g = fields.from_snapshot(Ghost, obj.adf.snapshot, f"blender:{obj.name}")
    g.identifier = identifier(obj)
    if g.name is None:
        g.name = obj.name
    fields.merge(g, fields.GHOST, read_group(obj.adf.ghost, fields.GHOST))
    parent = adf_parent(obj)
    g.parent = _parent_ref(g.parent, parent)
    if not unchanged(obj):
        g.location = relative_pose(obj, parent)
    _gather_geometry(obj, g, out, paths)
    if not (g.collision_shape or g.compound_collision_shape or g.collision_mesh or g.mesh):
        out.diagnostics.append(
            error(
                "ghost-collision",
                f"ghost '{obj.name}' has no collision geometry",
                where(obj),
                "add a collision primitive or mesh; AMBF skips a ghost without one",
            )
        )
    return g


def _parent_ref(old: str | None, parent) -> str | None:
    if parent is None:
        return old  # a parent in another file (or not found at import) is carried through
    ident = identifier(parent)
    return old if old and (old in ident or old.endswith("/" + ident)) else ident


def _gather_geometry(obj, b, out: Gathered, paths: tuple[str, str]) -> None:
    hi, lo = paths
    visual = None
    first_name = b.mesh
    if obj.type == "MESH" and len(obj.data.polygons):
        # a soft body's nodes are the vertices written (its fixed nodes index the same mesh)
        arr = meshes.mesh_arrays(obj, evaluated=out.options.apply_modifiers)
        digest = meshes.digest([arr])
        fmt = out.options.mesh_format
        name = b.mesh if b.mesh else meshes.with_format(obj.name, fmt)
        src = Path(obj.adf.mesh_source) if obj.adf.mesh_source else None
        if digest == obj.adf.mesh_hash and src is not None and src.is_file():
            job = MeshJob(hi, name, digest, source=src)
        else:
            name = meshes.with_format(name, fmt)
            job = MeshJob(hi, name, digest, parts=[arr], whole=isinstance(b, SoftBody))
            out.diagnostics += meshformat.findings(obj, arr, fmt, soft=isinstance(b, SoftBody))
        b.mesh = name
        out.jobs.append(job)
        visual = job
    _gather_collision(obj, b, out, lo, visual, first_name)


def _shape_entry(child, body_obj) -> ShapeEntry:
    s = child.adf.shape
    geo = Geometry()
    tidy = fields.tidy  # Blender keeps these in single precision: the shortest decimal, not 0.0099999997...
    v = exact.applied(child, {"size": tuple(s.size), "radius": s.radius, "height": s.height})
    if s.shape == "BOX":
        geo.x, geo.y, geo.z = (tidy(x) for x in v["size"])
    elif s.shape == "SPHERE":
        geo.radius = tidy(v["radius"])
    else:
        geo.radius, geo.height, geo.axis = tidy(v["radius"]), tidy(v["height"]), s.axis
    placed = exact.offset(child)  # where a fit put it, while it has not been moved
    if placed is None:
        offset = relative_pose(child, body_obj)
    else:
        offset = Pose(Vec3(*(fields.tidy(c * uniform_scale(body_obj)) for c in placed.position)), placed.orientation)
    return ShapeEntry(shape=s.shape.title(), geometry=geo, offset=offset)


def _entry_key(e: ShapeEntry):
    g = e.geometry
    rpy = e.offset.rpy() if e.offset is not None else (0, 0, 0)
    pos = tuple(e.offset.position) if e.offset is not None else (0, 0, 0)
    return ((e.shape or "").upper(), g.x, g.y, g.z, g.radius, g.height, (g.axis or "z").lower(), *pos, *rpy)


def _gather_collision(obj, b, out: Gathered, lo: str, visual: MeshJob | None, first_name: str | None) -> None:
    kids = sorted(obj.children, key=lambda c: c.name)
    shapes = [c for c in kids if c.adf.kind == "COLLISION_SHAPE"]
    parts = [c for c in kids if c.adf.kind == "COLLISION_MESH" and c.type == "MESH"]
    if shapes:
        entries = [_shape_entry(c, obj) for c in shapes]
        if b.collision_shape and len(entries) == 1:
            old = ShapeEntry(shape=b.collision_shape, geometry=b.collision_geometry, offset=b.collision_offset)
            if not fields.close(_entry_key(old), _entry_key(entries[0])):
                b.collision_shape, b.collision_geometry = entries[0].shape, entries[0].geometry
                b.collision_offset = entries[0].offset
        else:
            old = b.compound_collision_shape or []
            same = len(old) == len(entries) and all(
                fields.close(_entry_key(x), _entry_key(y)) for x, y in zip(old, entries)
            )
            if not same:
                b.collision_shape = b.collision_geometry = b.collision_offset = None
                b.compound_collision_shape = entries
        return
    if parts:
        body_inv = np.array(obj.matrix_world.inverted(), dtype=np.float64)
        arrays = []
        for c in parts:
            a = meshes.mesh_arrays(c, evaluated=out.options.apply_modifiers)
            m = body_inv @ np.array(c.matrix_world, dtype=np.float64)
            if not np.allclose(m, np.eye(4), atol=1e-7):
                co = a.co.astype(np.float64) @ m[:3, :3].T + m[:3, 3]
                a.co = co.astype(np.float32)
            arrays.append(a)
        digest = meshes.digest(arrays)
        fmt = meshformat.collision_format(obj, len(arrays), out)
        name = b.collision_mesh or (
            first_name if first_name and obj.adf.collision_source else meshes.with_format(f"{obj.name}_collision", fmt)
        )
        src = Path(obj.adf.collision_source) if obj.adf.collision_source else None
        if digest == obj.adf.collision_hash and src is not None and src.is_file():
            out.jobs.append(MeshJob(lo, name, digest, source=src, low=True))
        else:
            name = meshes.with_format(name, fmt)
            out.jobs.append(MeshJob(lo, name, digest, parts=arrays, low=True))
            if b.collision_mesh_type is None:
                b.collision_mesh_type = "CONVEX_HULL" if len(arrays) > 1 else None
        if name != b.mesh or b.collision_mesh is not None:
            b.collision_mesh = name
        return
    if visual is not None and not (b.collision_shape or b.compound_collision_shape):
        # no collision of its own: AMBF looks the visual file name up in the low-res folder
        name = b.collision_mesh or visual.filename
        low = None
        if obj.type == "MESH" and b.collision_mesh is None and not isinstance(b, SoftBody):
            if lowres.modifiers(obj):  # the modeller's low-res modifiers make it
                low = meshes.mesh_arrays(obj, evaluated=True, low_res=True)
                low.uv, low.materials, low.material_index = None, [], None
            elif out.options.low_res_ratio < 1.0:
                low = meshes.decimated_arrays(obj, out.options.low_res_ratio)
        if low is not None:
            if name != meshes.with_format(name, out.options.mesh_format):
                name = meshes.with_format(name, out.options.mesh_format)
                b.collision_mesh = name
            out.jobs.append(MeshJob(lo, name, meshes.digest([low]), parts=[low], low=True))
            return
        out.jobs.append(MeshJob(lo, name, visual.digest, parts=visual.parts, source=visual.source, low=True))


# --- joints --------------------------------------------------------------------------------


def gather_joint(obj, out: Gathered) -> Joint | None:
    j = fields.from_snapshot(Joint, obj.adf.snapshot, f"blender:{obj.name}")
    j.identifier = identifier(obj)
    if j.name is None:
        j.name = obj.name
    fields.merge(j, fields.JOINT, read_group(obj.adf.joint, fields.JOINT))
    rbc = obj.rigid_body_constraint
    p = rbc.object1 if rbc is not None else None
    c = rbc.object2 if rbc is not None else None
    external = set(str(obj.get("adf_external_ends", "")).split(","))
    cleared = [
        r for r, o, ref in (("parent", p, j.parent), ("child", c, j.child)) if o is None and ref and r not in external
    ]
    if cleared:
        # the end was a body of this scene at import (or set by hand), and has been cleared since
        out.diagnostics.append(
            error(
                "joint-reference",
                f"joint '{obj.name}': its {cleared[0]} was cleared (it was '{getattr(j, cleared[0])}')",
                where(obj),
                f"set the rigid body constraint's {'first' if cleared[0] == 'parent' else 'second'}"
                " object to an ADF body, or delete the joint",
            )
        )
        return None
    if (p is None and j.parent) or (c is None and j.child):
        # imported with a body that lives in another file: carried through as written
        out.diagnostics.append(
            warning(
                "joint-reference",
                f"joint '{obj.name}': {'parent' if p is None else 'child'} body is not in this scene; kept as written",
                where(obj),
            )
        )
        if p is not None:
            j.parent = _parent_ref(j.parent, p)
        if c is not None:
            j.child = _parent_ref(j.child, c)
        return j
    for role, o in (("parent", p), ("child", c)):
        if o is None or o.adf.kind not in ("BODY", "SOFT_BODY"):
            what = "no object" if o is None else f"'{o.name}', which is not an ADF body"
            out.diagnostics.append(
                error(
                    "joint-reference",
                    f"joint '{obj.name}': its {role} is {what}",
                    where(obj),
                    f"set the rigid body constraint's {'first' if role == 'parent' else 'second'}"
                    " object to an ADF body",
                )
            )
            return None
    if p == c:
        out.diagnostics.append(error("joint-reference", f"joint '{obj.name}' joins '{p.name}' to itself", where(obj)))
        return None
    j.parent = _parent_ref(j.parent, p)
    j.child = _parent_ref(j.child, c)
    if not obj.adf.snapshot:  # authored here: say what AMBF would do with what it lacks
        out.diagnostics += joint_findings(obj, j, c)
    axis = obj.adf.joint.axis
    keep = unchanged(obj) and unchanged(p) and unchanged(c) and j.parent_pivot is not None and axis == "DEFAULT"
    if not keep:
        d = joint_frames.derive(
            j.type, world_pose(p), world_pose(c), joint_frame(obj, j.type), uniform_scale(p), uniform_scale(c)
        )
        for k, v in d.items():
            if k in ("offset", "joint_offset") and v == 0.0 and getattr(j, k) is None:
                continue
            setattr(j, k, v)
        if j.child_offset is not None and j.offset is None:
            j.child_offset = None
    return j


def joint_frame(obj, joint_type: str | None) -> Pose:
    """The joint frame of a joint's Empty, turned so that the axis chosen in its panel (X, Y
    or Z of the Empty) is the reference axis of its type (adf-format §8.1: z, x for prismatic)."""
    from adfkit.model.semantics import JointKind, joint_kind, reference_axis, shortest_arc

    frame = world_pose(obj)
    axis = obj.adf.joint.axis
    if axis == "DEFAULT":
        return frame
    chosen = Vec3(*(1.0 if a == axis else 0.0 for a in "XYZ"))
    turn = shortest_arc(reference_axis(joint_kind(joint_type) or JointKind.REVOLUTE), chosen)
    return Pose(frame.position, (frame.orientation * turn).normalized())


def joint_findings(obj, j: Joint, child) -> list[Diagnostic]:
    """A driven joint without a controller (AMBF then drives it by velocity, with no gains of
    this model), and a six-dof spring without the limits, stiffness or damping that hold its
    child (AMBF's defaults: ±1.2 on every axis, stiffness 1, which let a child fall)."""
    from adfkit.model.semantics import JointKind, joint_kind

    kind = joint_kind(j.type)
    out = []
    if kind in (JointKind.REVOLUTE, JointKind.PRISMATIC) and not j.passive and j.controller is None:
        out.append(
            info(
                "joint-controller",
                f"joint '{obj.name}' has no controller gains; AMBF drives it by velocity",
                where(obj),
                "Estimate joint controller gains sets P, I and D from what the joint moves",
            )
        )
    if kind is JointKind.SIX_DOF_SPRING:
        lim = j.joint_limits
        lacks = [
            what
            for what, given in (
                ("limits", lim is not None and lim.linear is not None and lim.angular is not None),
                ("stiffness", j.stiffness is not None),
                ("damping", j.damping is not None),
            )
            if not given
        ]
        if lacks:
            out.append(
                warning(
                    "spring-joint-defaults",
                    f"six-dof spring '{obj.name}' has no {' or '.join(lacks)}: AMBF's defaults "
                    f"(±1.2 m and rad, stiffness 1, damping 0.7) do not hold '{child.name}'",
                    where(obj),
                    "tick the joint's limits, stiffness and damping (a new spring joint gets values that hold its child)",
                )
            )
    return out


# --- sensors, actuators, cameras, lights ---------------------------------------------------


def _attached(obj, x, out: Gathered, what: str):
    parent = adf_parent(obj)
    if parent is None and x.parent:
        # imported with a parent in another file (or not found): carried through as written
        out.diagnostics.append(
            warning(
                f"{what}-parent",
                f"{what} '{obj.name}': parent '{x.parent}' is not in this scene; kept as written",
                where(obj),
            )
        )
        if not unchanged(obj):
            x.location = world_pose(obj)
            x.extras.pop("location", None)
        return x
    if parent is None:
        out.diagnostics.append(
            error(
                f"{what}-parent",
                f"{what} '{obj.name}' is not parented to an ADF body",
                where(obj),
                "parent it to the body it is mounted on",
            )
        )
    x.parent = _parent_ref(x.parent, parent)
    if not unchanged(obj):  # unchanged: the location as the file wrote it (or left it out)
        x.location = relative_pose(obj, parent)
        x.extras.pop("location", None)
    return x


def gather_sensor(obj, out: Gathered) -> Sensor:
    s = fields.from_snapshot(Sensor, obj.adf.snapshot, f"blender:{obj.name}")
    s.identifier, s.name = identifier(obj), s.name or obj.name
    fields.merge(s, fields.SENSOR, read_group(obj.adf.sensor, fields.SENSOR))
    rays = [
        Ray(offset=Vec3(*map(fields.tidy, r.offset)), direction=Vec3(*map(fields.tidy, r.direction)))
        for r in obj.adf.sensor.rays
    ]
    old = [(*r.offset, *r.direction) for r in (s.array or []) if r.offset is not None and r.direction is not None]
    if rays and not fields.same32(old, [(*r.offset, *r.direction) for r in rays]):
        s.array = rays
    if not (s.array or s.mesh or s.parametric):
        out.diagnostics.append(
            (warning if obj.adf.snapshot else error)(
                "sensor-rays",
                f"sensor '{obj.name}' has no rays",
                where(obj),
                "add rays in the ADF Sensor panel; AMBF skips a sensor without them",
            )
        )
    return _attached(obj, s, out, "sensor")


def gather_actuator(obj, out: Gathered) -> Actuator:
    a = fields.from_snapshot(Actuator, obj.adf.snapshot, f"blender:{obj.name}")
    a.identifier, a.name = identifier(obj), a.name or obj.name
    fields.merge(a, fields.ACTUATOR, read_group(obj.adf.actuator, fields.ACTUATOR))
    return _attached(obj, a, out, "actuator")


def _vec_in_parent(obj, local, point: bool):
    parent = adf_parent(obj)
    v = obj.matrix_world @ local if point else obj.matrix_world.to_3x3() @ local
    if parent is not None:
        inv = parent.matrix_world.inverted()
        v = inv @ v if point else inv.to_3x3() @ v
    return Vec3(*(round(fields.tidy(c), 9) + 0.0 for c in v))


def gather_camera(obj, out: Gathered) -> Camera:
    from mathutils import Vector

    c = fields.from_snapshot(Camera, obj.adf.snapshot, f"blender:{obj.name}")
    c.identifier, c.name = identifier(obj), c.name or obj.name
    fields.merge(c, fields.CAMERA, read_group(obj.adf.camera, fields.CAMERA))
    parent = adf_parent(obj)
    c.parent = _parent_ref(c.parent, parent)
    if not unchanged(obj):
        dist = 1.0
        if c.location is not None and c.look_at is not None:
            dist = max((Vec3(*c.look_at) - Vec3(*c.location)).norm(), 1e-6)
        c.location = _vec_in_parent(obj, Vector((0, 0, 0)), True)
        c.look_at = _vec_in_parent(obj, Vector((0, 0, -dist)), True)
        c.up = _vec_in_parent(obj, Vector((0, 1, 0)), False)
    if obj.type == "CAMERA":
        cam = obj.data
        if not fields.same32(c.field_view_angle, cam.angle_y):
            c.field_view_angle = fields.tidy(cam.angle_y)
        from adfkit.model.objects import ClippingPlane

        cp = c.clipping_plane or ClippingPlane()
        if not fields.same32((cp.near, cp.far), (cam.clip_start, cam.clip_end)):
            c.clipping_plane = ClippingPlane(near=fields.tidy(cam.clip_start), far=fields.tidy(cam.clip_end))
    return c


def gather_light(obj, out: Gathered) -> Light:
    from mathutils import Vector

    li = fields.from_snapshot(Light, obj.adf.snapshot, f"blender:{obj.name}")
    li.identifier, li.name = identifier(obj), li.name or obj.name
    fields.merge(li, fields.LIGHT, read_group(obj.adf.light, fields.LIGHT))
    parent = adf_parent(obj)
    li.parent = _parent_ref(li.parent, parent)
    if not unchanged(obj):
        li.location = _vec_in_parent(obj, Vector((0, 0, 0)), True)
        li.direction = _vec_in_parent(obj, Vector((0, 0, -1)), False)
    if obj.type == "LIGHT" and obj.data.type == "SPOT":
        if not fields.same32(li.cutoff_angle, obj.data.spot_size / 2.0):
            li.cutoff_angle = fields.tidy(obj.data.spot_size) / 2.0
    if li.shadow_quality is None:
        out.diagnostics.append(
            warning(
                "light-shadow",
                f"light '{obj.name}' has no shadow quality",
                where(obj),
                "AMBF leaves it uninitialised; set it (0-5)",
            )
        )
    return li


GATHER = {
    "SENSOR": ("sensors", gather_sensor),
    "ACTUATOR": ("actuators", gather_actuator),
    "CAMERA": ("cameras", gather_camera),
    "LIGHT": ("lights", gather_light),
}
