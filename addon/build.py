"""adfkit model -> Blender scene (import). Each object keeps its exact ADF text (snapshot)
so an unchanged scene exports back to the same file."""

from __future__ import annotations

import json
from pathlib import Path

import bpy
from mathutils import Matrix, Quaternion, Vector

from adfkit.adf import collision_mesh_path, read_file, visual_mesh_path
from adfkit.adf.writer import file_to_plain
from adfkit.diagnostics import AdfError, Diagnostic, Severity, warning
from adfkit.model import ModelFile, Pose
from adfkit.model.files import ObjectList
from adfkit.model.semantics import JointKind, collision_primitives, joint_frames, joint_kind
from adfkit.model.spec import adf_fields

from . import fields, gather, mesh_import, meshes
from .properties import GROUP_OF, write_group

RBC_TYPE = {
    JointKind.REVOLUTE: "HINGE",
    JointKind.PRISMATIC: "SLIDER",
    JointKind.FIXED: "FIXED",
    JointKind.P2P: "POINT",
    JointKind.CONE_TWIST: "GENERIC",
    JointKind.SIX_DOF: "GENERIC",
}


def _matrix(p: Pose, scale: float = 1.0) -> Matrix:
    q = p.orientation
    m = Quaternion((q.w, q.x, q.y, q.z)).to_matrix().to_4x4()
    m.translation = Vector(p.position)
    return m @ Matrix.Scale(scale, 4) if scale != 1.0 else m


def _link(scene, obj):
    scene.collection.objects.link(obj)
    return obj


def ensure_rigidbody_world(scene) -> None:
    if scene.rigidbody_world is None:
        bpy.ops.rigidbody.world_add()


def _snapshot(obj, x) -> None:
    obj.adf.snapshot = fields.snapshot_text(x)
    obj.adf.identifier = x.identifier
    table = fields.TABLES[obj.adf.kind][1]
    pg = getattr(obj.adf, GROUP_OF[obj.adf.kind])
    write_group(pg, table, {f.prop: fields.get_value(x, f) for f in table})


def _shape_child(body_obj, prim, i, scene):
    from .elements import add_collision_primitive

    g = prim.geometry
    shape = prim.kind.name if prim.kind.name in ("BOX", "SPHERE", "CYLINDER", "CAPSULE", "CONE") else "BOX"
    size = (g.x, g.y or 0.0, g.z or 0.0) if g.x is not None else (0.1, 0.1, 0.1)
    e = add_collision_primitive(
        body_obj,
        shape,
        size=size,
        radius=g.radius if g.radius is not None else 0.05,
        height=g.height if g.height is not None else 0.1,
        axis=g.axis if g.axis in tuple("xyzXYZ") else "z",
        name=f"{body_obj.name}.collision{i}",
    )
    e.matrix_world = body_obj.matrix_world @ _matrix(prim.pose)
    return e


def _geometry(obj, x, doc, scene) -> None:
    vis = visual_mesh_path(doc, x) if x.mesh else None
    prims = collision_primitives(x) or []
    if any(p.kind.name not in ("BOX", "SPHERE", "CYLINDER", "CAPSULE", "CONE") for p in prims):
        return  # a plane (or another shape the panel does not offer): kept exactly in the snapshot
    if prims:
        for i, p in enumerate(prims):
            _shape_child(obj, p, i, scene)
        return
    col = collision_mesh_path(doc, x) if (x.collision_mesh or x.mesh) else None
    if col is None or not col.is_file() or (vis is not None and col.resolve() == vis.resolve()):
        return
    parts = mesh_import.import_file(col, scene)
    for i, c in enumerate(parts):
        c.name = f"{obj.name}.collision{i}"
        c.adf.kind = "COLLISION_MESH"
        c.display_type = "WIRE"
        c.hide_render = True
        c.parent = obj
        c.matrix_parent_inverse = Matrix.Identity(4)
        c.matrix_basis = Matrix.Identity(4)
    obj.adf.collision_source = str(col)


def _body(b, doc, scene, diags):
    vis = visual_mesh_path(doc, b) if b.mesh else None
    if vis is not None and not vis.is_file():
        diags.append(
            warning("missing-mesh", f"mesh {vis} of '{b.identifier}' not found; imported as an empty", b.where("mesh"))
        )
    obj = mesh_import.mesh_object(b.name or b.identifier, vis, scene)
    obj.adf.kind = "BODY"
    if obj.type == "MESH":
        obj.adf.mesh_source = str(vis)
    _snapshot(obj, b)
    obj.matrix_world = _matrix(b.location or Pose(), b.scale if b.scale is not None else 1.0)
    return obj


def _soft_mesh_object(name: str, path: Path | None, scene):
    """A soft body's mesh built from the nodes AMBF makes of its file (vertex i = node i, so
    `fixed nodes` index the Blender vertices); Blender's importer when that reader is missing."""
    if path is None or not path.is_file():
        return mesh_import.mesh_object(name, path, scene)
    try:
        from adfkit.geometry.softmesh import load_soft_mesh

        sm = load_soft_mesh(path)
    except (ImportError, AdfError):
        return mesh_import.mesh_object(name, path, scene)
    me = bpy.data.meshes.new(name)
    me.from_pydata(sm.nodes.tolist(), [], sm.triangles.tolist())
    me.update()
    return _link(scene, bpy.data.objects.new(name, me))


def _soft_body(sb, doc, scene, diags):
    path = collision_mesh_path(doc, sb) if sb.mesh else None
    if path is not None and not path.is_file():
        diags.append(
            warning(
                "missing-mesh", f"mesh {path} of '{sb.identifier}' not found; imported as an empty", sb.where("mesh")
            )
        )
    obj = _soft_mesh_object(sb.name or sb.identifier, path, scene)
    obj.adf.kind = "SOFT_BODY"
    if obj.type == "MESH":
        obj.adf.mesh_source = str(path)
        grp = obj.vertex_groups.new(name=obj.adf.soft.fixed_group)
        fixed = [
            i
            for i in (sb.config.fixed_nodes if sb.config is not None and sb.config.fixed_nodes else [])
            if 0 <= i < len(obj.data.vertices)
        ]
        if fixed:
            grp.add(fixed, 1.0, "REPLACE")
    _snapshot(obj, sb)
    obj.matrix_world = _matrix(sb.location or Pose(), sb.scale if sb.scale is not None else 1.0)
    return obj


def _find(objs: dict, ref: str | None):
    """The object a reference names: its identifier, a unique part of it, or a full name
    with a namespace (`/ambf/env/BODY ExoRightFoot`, as AMBF resolves it)."""
    if not ref:
        return None
    if ref in objs:
        return objs[ref]
    hits = [k for k in objs if ref in k]
    if len(hits) == 1:
        return objs[hits[0]]
    tail = [k for k in objs if ref.endswith("/" + k)]
    if len(tail) == 1:
        return objs[tail[0]]
    short = ref.rsplit("/", 1)[-1]
    return objs.get(short) if short != ref else None


def _attach(obj, parent, local: Matrix) -> None:
    obj.parent = parent
    obj.matrix_world = (parent.matrix_world @ local) if parent is not None else local


def _look_matrix(loc, look_at, up, forward_axis) -> Matrix:
    loc, look_at = Vector(loc or (0, 0, 0)), Vector(look_at or (1, 0, 0))
    d = look_at - loc
    if d.length < 1e-12:
        d = Vector((1, 0, 0))
    up = Vector(up or (0, 0, 1))
    q = d.to_track_quat(forward_axis, "Y" if forward_axis == "-Z" else "Z")
    if up.cross(d).length > 1e-9:
        z = -d.normalized()
        x = up.cross(z).normalized()
        y = z.cross(x)
        m = Matrix((x, y, z)).transposed()
        q = m.to_quaternion()
    m = q.to_matrix().to_4x4()
    m.translation = loc
    return m


def import_model(path: str | Path, scene=None) -> tuple[list, list[Diagnostic]]:
    scene = scene or bpy.context.scene
    doc, diags = read_file(Path(path), kind="model")
    # the validator's severities: what AMBF loads anyway (duplicate keys, sb/cloth.yaml) is a warning
    from dataclasses import replace

    from adfkit.validator.engine import SEVERITY_OVERRIDES

    diags = [replace(d, severity=SEVERITY_OVERRIDES.get(d.rule, d.severity)) for d in diags]
    errors = [d for d in diags if d.severity >= Severity.ERROR]
    if errors:
        raise AdfError(errors)
    mesh_import.UNREADABLE.clear()
    bodies: dict[str, object] = {}
    made = []
    for b in doc.bodies:
        if b.identifier in bodies or not b.defined:
            continue
        obj = _body(b, doc, scene, diags)
        bodies[b.identifier] = obj
        made.append(obj)
    for sb in doc.soft_bodies:
        if sb.identifier in bodies or not sb.defined:
            continue
        obj = _soft_body(sb, doc, scene, diags)
        bodies[sb.identifier] = obj
        made.append(obj)
    bpy.context.view_layer.update()
    for b in doc.bodies:
        if b.identifier in bodies:
            _geometry(bodies[b.identifier], b, doc, scene)
    for g in doc.ghost_objects:
        vis = visual_mesh_path(doc, g) if g.mesh else None
        obj = mesh_import.mesh_object(g.name or g.identifier, vis, scene)
        obj.adf.kind = "GHOST"
        if obj.type == "MESH":
            obj.adf.mesh_source = str(vis)
        _snapshot(obj, g)
        _attach(obj, _find(bodies, g.parent), _matrix(g.location or Pose(), g.scale or 1.0))
        bpy.context.view_layer.update()
        _geometry(obj, g, doc, scene)
        made.append(obj)
    for kind, items in (("SENSOR", doc.sensors), ("ACTUATOR", doc.actuators)):
        for s in items:
            obj = _link(scene, bpy.data.objects.new(s.name or s.identifier, None))
            obj.adf.kind = kind
            obj.empty_display_type = "SINGLE_ARROW" if kind == "SENSOR" else "PLAIN_AXES"
            obj.empty_display_size = 0.01
            _snapshot(obj, s)
            if kind == "SENSOR":
                for r in s.array or []:
                    ray = obj.adf.sensor.rays.add()
                    ray.offset, ray.direction = tuple(r.offset or (0, 0, 0)), tuple(r.direction or (1, 0, 0))
            _attach(obj, _find(bodies, s.parent), _matrix(s.location or Pose()))
            made.append(obj)
    for c in doc.cameras:
        cam = bpy.data.cameras.new(c.name or c.identifier)
        cam.sensor_fit = "VERTICAL"
        cam.angle_y = c.field_view_angle if c.field_view_angle is not None else 0.7
        if c.clipping_plane is not None:
            cam.clip_start = c.clipping_plane.near or 0.1
            cam.clip_end = c.clipping_plane.far or 10.0
        obj = _link(scene, bpy.data.objects.new(c.name or c.identifier, cam))
        obj.adf.kind = "CAMERA"
        _snapshot(obj, c)
        _attach(obj, _find(bodies, c.parent), _look_matrix(c.location, c.look_at, c.up, "-Z"))
        made.append(obj)
    for li in doc.lights:
        data = bpy.data.lights.new(li.name or li.identifier, "SPOT")
        data.spot_size = 2 * (li.cutoff_angle if li.cutoff_angle is not None else 0.7)
        obj = _link(scene, bpy.data.objects.new(li.name or li.identifier, data))
        obj.adf.kind = "LIGHT"
        _snapshot(obj, li)
        loc = Vector(li.location or (0, 0, 0))
        d = Vector(li.direction or (0, 0, -1))
        m = (d.to_track_quat("-Z", "Y") if d.length > 1e-12 else Quaternion()).to_matrix().to_4x4()
        m.translation = loc
        _attach(obj, _find(bodies, li.parent), m)
        made.append(obj)
    bpy.context.view_layer.update()
    if doc.joints:
        ensure_rigidbody_world(scene)
    for j in doc.joints:
        p, c = _find(bodies, j.parent), _find(bodies, j.child)
        obj = _link(scene, bpy.data.objects.new(j.name or j.identifier, None))
        obj.adf.kind = "JOINT"
        obj.empty_display_type = "ARROWS"
        obj.empty_display_size = 0.02
        _snapshot(obj, j)
        if p is not None:
            frame_a, _ = joint_frames(j, _scale(p), 1.0)
            obj.matrix_world = p.matrix_world.normalized() @ _matrix(frame_a)
        _constraint(obj, j, p, c)
        made.append(obj)
    bpy.context.view_layer.update()
    for o in made:
        o.adf.snapshot_matrix = gather.matrix_key(o)
        if o.adf.kind in ("BODY", "GHOST", "SOFT_BODY") and o.type == "MESH":
            o.adf.mesh_hash = meshes.digest([meshes.mesh_arrays(o)])
        if o.adf.collision_source:
            parts = sorted((c for c in o.children if c.adf.kind == "COLLISION_MESH"), key=lambda c: c.name)
            o.adf.collision_hash = meshes.digest([meshes.mesh_arrays(c) for c in parts])
    _scene_snapshot(scene, doc)
    from .volumes import import_volumes

    # pictures of the volumes (kind NONE: export keeps them as written), in their parent body's frame
    import_volumes(doc, scene, diags, lambda ref: _find(bodies, ref))
    diags.extend(mesh_import.UNREADABLE)
    mesh_import.UNREADABLE.clear()
    return made, diags


def _scale(obj) -> float:
    return gather.uniform_scale(obj)


def _constraint(obj, j, p, c) -> None:
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    kind = joint_kind(j.type)
    bpy.ops.rigidbody.constraint_add(type=RBC_TYPE.get(kind, "GENERIC_SPRING"))
    rbc = obj.rigid_body_constraint
    rbc.object1, rbc.object2 = p, c
    # which ends live in another file (kept as written on export); an end that was here and is
    # cleared later is the modeller's doing, and export refuses it
    obj["adf_external_ends"] = ",".join(r for r, o in (("parent", p), ("child", c)) if o is None)
    lim = j.joint_limits
    if kind == JointKind.REVOLUTE and lim is not None and lim.low is not None and lim.high is not None:
        rbc.use_limit_ang_z, rbc.limit_ang_z_lower, rbc.limit_ang_z_upper = True, lim.low, lim.high
    if kind == JointKind.PRISMATIC and lim is not None and lim.low is not None and lim.high is not None:
        rbc.use_limit_lin_x, rbc.limit_lin_x_lower, rbc.limit_lin_x_upper = True, lim.low, lim.high


KEPT_LISTS = {"vehicles": "vehicles", "volumes": "volumes"}


def _scene_snapshot(scene, doc: ModelFile) -> None:
    order = {}
    for f in adf_fields(doc):
        if isinstance(f.metadata["kind"], ObjectList):
            items = getattr(doc, f.name)
            if items:
                order[f.metadata["adf_key"]] = [o.identifier for o in items]
    level = ModelFile(
        **{f.name: getattr(doc, f.name) for f in adf_fields(doc) if not isinstance(f.metadata["kind"], ObjectList)}
    )
    level.extras = dict(doc.extras)
    import yaml

    from adfkit.adf.writer import _Dumper

    text = yaml.dump(file_to_plain(level), Dumper=_Dumper, sort_keys=False, allow_unicode=True, width=100)
    # sections the add-on does not edit (vehicles, volumes): carried through as written
    kept = {
        key: [[o.identifier, fields.snapshot_text(o)] for o in getattr(doc, attr) if o.defined]
        for key, attr in KEPT_LISTS.items()
        if getattr(doc, attr)
    }
    scene.adf.snapshot = json.dumps(
        {
            "keys": text if text.strip() != "{}" else "",
            "order": order,
            "present": sorted(doc.present_lists),
            "kept": kept,
            # the folder relative paths (shaders, volume slices) were written against
            "source_dir": str(Path(doc.path).resolve().parent) if doc.path else None,
        }
    )
    scene.adf.use_namespace = doc.namespace is not None
    scene.adf.use_gravity = doc.gravity is not None
    if doc.gravity is not None:
        scene.adf.gravity = tuple(doc.gravity)
    scene.adf.namespace = doc.namespace or ""
    scene.adf.use_ignore_inter_collision = doc.ignore_inter_collision is not None
    scene.adf.ignore_inter_collision = bool(doc.ignore_inter_collision)
