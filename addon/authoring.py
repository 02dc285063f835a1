"""Authoring actions behind the operators (Blender-level; geometry work is adfkit.geometry's).

Each function raises :class:`adfkit.diagnostics.AdfError` with a readable message for bad
input, so operators and scripts report the same thing.
"""

from __future__ import annotations

import math

import bpy
from mathutils import Matrix, Quaternion, Vector

from adfkit.diagnostics import AdfError, SourceLocation, error
from adfkit.model.pose import Pose, Quat, Vec3, quat_to_rpy

from . import exact, gather, meshes, precision
from .elements import _link, add_collision_primitive, digits, exported_evaluated, mass_from_density
from .precision import rounded, snapped, typed


def _fail(rule: str, msg: str, obj=None, hint: str | None = None):
    raise AdfError(error(rule, msg, SourceLocation(f"blender:{obj.name}") if obj is not None else None, hint))


GEOMETRY_PACKAGES = "trimesh, manifold3d, coacd, scipy"


def geometry(module: str):
    """``adfkit.geometry.<module>``, or a readable AdfError when its packages are missing
    (an extension built without the geometry wheels, a Blender with an older numpy)."""
    import importlib

    try:
        return importlib.import_module(f"adfkit.geometry.{module}")
    except ImportError as exc:
        missing = getattr(exc, "name", None) or str(exc)
        raise AdfError(
            error(
                "geometry-unavailable",
                f"this needs the geometry package '{missing}', which is not installed in Blender's Python",
                None,
                f"install the adfkit extension built with its geometry wheels ({GEOMETRY_PACKAGES}; "
                "see the README, 'Blender add-on')",
            )
        ) from None


def mark(obj, kind: str) -> None:
    """Make ``obj`` an ADF object of ``kind`` with sensible first values: a body's mass
    from its density and mesh volume, a light's shadow quality."""
    obj.adf.kind = kind
    if kind in ("BODY", "SOFT_BODY"):
        pg = obj.adf.body if kind == "BODY" else obj.adf.soft
        if not pg.use_mass:
            pg.use_mass = True
            mass_from_density(obj)
    if kind == "LIGHT" and not obj.adf.light.use_shadow_quality:
        obj.adf.light.use_shadow_quality, obj.adf.light.shadow_quality = True, 5
    if kind == "SOFT_BODY" and obj.type == "MESH" and obj.adf.soft.fixed_group not in obj.vertex_groups:
        obj.vertex_groups.new(name=obj.adf.soft.fixed_group)


def fix_selected_nodes(obj, replace: bool = True) -> list[int]:
    """Put the mesh's selected vertices in the soft body's fixed-node vertex group (Edit Mode
    selection; the object is switched to Object Mode to read it). Returns the vertex indices."""
    if obj.type != "MESH":
        _fail("no-mesh", f"'{obj.name}' is not a mesh", obj, "a soft body's nodes are its mesh's vertices")
    if obj.mode == "EDIT":
        obj.update_from_editmode()
    name = obj.adf.soft.fixed_group
    grp = obj.vertex_groups.get(name) or obj.vertex_groups.new(name=name)
    picked = [v.index for v in obj.data.vertices if v.select]
    if replace:
        grp.remove(list(range(len(obj.data.vertices))))
    if picked:
        grp.add(picked, 1.0, "REPLACE")
    return picked


def _trimesh_of(obj):
    """The mesh export writes for the object (its modifiers applied, with *Apply modifiers*),
    as a trimesh in float64 with the coordinates as typed (precision.typed)."""
    geometry("meshio")  # the geometry packages, or a readable error
    import trimesh

    if obj.type != "MESH" or not len(obj.data.polygons):
        _fail("no-mesh", f"'{obj.name}' has no mesh faces", obj, "select a mesh object")
    arr = meshes.mesh_arrays(obj, evaluated=exported_evaluated())
    if not len(arr.tris):
        _fail("no-mesh", f"'{obj.name}' has no mesh faces", obj, "select a mesh object")
    return trimesh.Trimesh(vertices=typed(arr.co), faces=arr.tris, process=True, validate=False)


def generate_collision(obj, threshold: float = 0.05, max_hulls: int = 16, repair: bool = False) -> list:
    """CoACD convex hulls of a body's mesh as COLLISION_MESH children (CONVEX_HULL)."""
    dmod = geometry("decompose")
    DecompositionParams, decompose = dmod.DecompositionParams, dmod.decompose
    mesh = _trimesh_of(obj)
    if not mesh.is_watertight:
        if not repair:
            _fail(
                "mesh-not-manifold",
                f"'{obj.name}' is not a closed 2-manifold mesh "
                f"({len(mesh.faces)} faces with open or non-manifold edges); convex decomposition needs a closed mesh",
                obj,
                "close the mesh (Mesh > Clean Up > Fill Holes, 3D-Print toolbox) or use primitive collision",
            )
        mesh, _ = geometry("repair").repair_mesh(mesh)
    dec = decompose(mesh, DecompositionParams(threshold=threshold, max_hulls=max_hulls))
    for c in [c for c in obj.children if c.adf.kind in ("COLLISION_MESH", "COLLISION_SHAPE")]:
        bpy.data.objects.remove(c, do_unlink=True)
    made = []
    for i, h in enumerate(dec.hulls):
        me = bpy.data.meshes.new(f"{obj.name}.hull{i}")
        me.from_pydata([tuple(map(float, v)) for v in h.vertices], [], [tuple(map(int, f)) for f in h.faces])
        me.update()
        c = _link(bpy.data.objects.new(f"{obj.name}.hull{i}", me))
        c.adf.kind = "COLLISION_MESH"
        c.display_type = "WIRE"
        c.hide_render = True
        c.parent = obj
        c.matrix_parent_inverse = Matrix.Identity(4)
        made.append(c)
    obj.adf.body.use_collision_mesh_type = True
    obj.adf.body.collision_mesh_type = "CONVEX_HULL"
    return made


def _pose_matrix(pose) -> Matrix:
    q = pose.orientation
    m = Quaternion((q.w, q.x, q.y, q.z)).to_matrix().to_4x4()
    m.translation = Vector(tuple(pose.position))
    return m


def fit_collision_primitive(obj, shape: str = "CAPSULE", replace: bool = True):
    """Fit an oriented primitive around the body's mesh (adfkit.geometry.primitives; a cone
    takes the fitted cylinder's axis, base at the wider end) and add it as the body's collision.
    Its size and offset, rounded as :func:`estimate_inertia` rounds, are kept exactly (:mod:`.exact`)."""
    prim = geometry("primitives")
    mesh = _trimesh_of(obj)
    kind = shape.upper()
    if kind == "CONE":
        entry = prim.fit_cylinder(mesh)
        entry = _cone_from_cylinder(entry, mesh)
    else:
        entry = prim.FITTERS[kind.lower()](mesh)
    if replace:
        for c in [c for c in obj.children if c.adf.kind in ("COLLISION_SHAPE", "COLLISION_MESH")]:
            bpy.data.objects.remove(c, do_unlink=True)
    g, n = entry.geometry, min(digits(), precision.FLOAT32_DIGITS)  # what float32 coordinates hold
    size = tuple(rounded(v, n) for v in (g.x, g.y, g.z)) if kind == "BOX" else (0.1, 0.1, 0.1)
    radius, height = rounded(g.radius or 0.05, n), rounded(g.height or 0.1, n)
    pose = Pose(Vec3(*snapped(entry.offset.position, float(mesh.scale), n)), entry.offset.orientation)
    made = add_collision_primitive(
        obj, kind, size=size, radius=radius, height=height, axis=g.axis or "z", offset=_pose_matrix(pose)
    )
    exact.keep(made, size=size, radius=radius, height=height)
    exact.keep_offset(made, pose)
    bpy.context.view_layer.update()
    return made


def fit_all(scene, shape: str = "AUTO") -> tuple[list, list[str]]:
    """*Fit collision primitives* for every body with a mesh (AMBF's add-on: "estimate collision
    shapes"): each body's one primitive is fitted again in its own shape (``AUTO``; a box where
    it has none), or every body gets ``shape``. A body whose collision is a compound of
    primitives or a set of collision meshes (convex hulls) is left as the modeller made it.
    Returns (the primitives made, ["name: why not"])."""
    done, skipped = [], []
    for o in sorted((o for o in scene.objects if o.adf.kind == "BODY" and o.type == "MESH"), key=lambda o: o.name):
        prims = [c for c in o.children if c.adf.kind == "COLLISION_SHAPE"]
        if any(c.adf.kind == "COLLISION_MESH" for c in o.children):
            skipped.append(f"{o.name}: its collision is a set of collision meshes")
            continue
        if len(prims) > 1:
            skipped.append(f"{o.name}: its collision is a compound of {len(prims)} primitives")
            continue
        kind = shape if shape != "AUTO" else (prims[0].adf.shape.shape if prims else "BOX")
        try:
            done.append(fit_collision_primitive(o, kind))
        except AdfError as exc:
            skipped.append(f"{o.name}: {exc.diagnostics[0].message}")
    return done, skipped


def _cone_from_cylinder(entry, mesh):
    """A cone on the cylinder's axis and extent, its base at the end where the mesh is wider
    (Bullet's cone: apex at +height/2 along its axis)."""
    import numpy as np

    from adfkit.model.pose import Quat

    pose = entry.offset
    rot = np.array(Quat(*pose.orientation).matrix())
    axis = rot[:, "xyz".index((entry.geometry.axis or "z").lower())]
    rel = np.asarray(mesh.vertices) - np.array(tuple(pose.position))
    t = rel @ axis
    radial = np.linalg.norm(rel - np.outer(t, axis), axis=1)
    low = radial[t < 0].max(initial=0.0)
    high = radial[t >= 0].max(initial=0.0)
    if high > low:  # wider at +axis: turn the cone over (half a turn about a perpendicular axis)
        perp = rot[:, ("xyz".index((entry.geometry.axis or "z").lower()) + 1) % 3]
        flip = Quat.from_axis_angle(tuple(map(float, perp)), math.pi)
        entry.offset = type(pose)(pose.position, (flip * pose.orientation).normalized())
    entry.shape = "cone"
    return entry


def estimate_inertia(obj, mass: float | None = None, density: float | None = None) -> None:
    """Mass, principal inertia and inertial offset from the body's closed mesh: the mass is
    kept when given (typed by hand), else density × volume. Computed in float64 and rounded to
    the 7 digits float32 coordinates hold, at most the scene's Float digits (a symmetric body's
    centre of mass is 0, its axes its own); kept exactly beside Blender's float32 properties
    (:mod:`.exact`)."""
    gmass = geometry("mass")
    mesh = _trimesh_of(obj)
    if not mesh.is_watertight:
        _fail(
            "mesh-not-closed",
            f"'{obj.name}' is not closed; its volume and inertia are undefined",
            obj,
            "close the mesh, or give the inertia by hand",
        )
    if mass is None and density is None:
        density = obj.adf.density
    n = min(digits(), precision.FLOAT32_DIGITS)  # what float32 coordinates hold
    props = gmass.mesh_mass_properties(mesh, density=density, mass=mass)
    moments_, axes = precision.principal(props.inertia, n)
    com = snapped(props.com, float(mesh.scale), n)
    b = obj.adf.body
    typed_by_hand = b.mass_typed
    m = rounded(props.mass, n)
    moments = tuple(rounded(v, n) for v in moments_)
    pose = (*com, *quat_to_rpy(Quat.from_matrix(axes.tolist()).normalized()))
    b.use_mass, b.mass = True, m
    b.mass_typed = typed_by_hand and mass is not None
    b.use_inertia, b.inertia = True, moments
    b.use_inertial_offset, b.inertial_offset = True, pose
    b.mass_note = ""
    exact.keep(obj, mass=m, inertia=moments, inertial_offset=pose)


def estimate_body(obj) -> None:
    """What the "Estimate inertia" button does: keep a mass typed by hand, else use density. A
    soft body has no rigid inertia: its mass from density over its evaluated, closed volume."""
    if obj.adf.kind == "SOFT_BODY":
        pg = obj.adf.soft
        if pg.mass_typed:
            return
        if mass_from_density(obj) is None:
            _fail(
                "mesh-not-closed",
                f"soft body '{obj.name}': {pg.mass_note or 'no volume to take a mass from'}",
                obj,
                "give the sheet thickness with a Solidify modifier, or type the mass",
            )
        return
    b = obj.adf.body
    typed = b.use_mass and b.mass_typed
    estimate_inertia(obj, mass=b.mass if typed else None, density=None if typed else obj.adf.density)


def estimate_all(scene) -> tuple[list, list[str]]:
    """Estimate every ADF body with a closed mesh; returns (done, ["name: why not"])."""
    done, skipped = [], []
    for o in sorted(scene.objects, key=lambda o: o.name):
        if o.adf.kind != "BODY" or o.type != "MESH":
            continue
        if o.adf.body.use_mass and o.adf.body.mass == 0.0:
            skipped.append(f"{o.name}: static (mass 0)")
            continue
        try:
            estimate_body(o)
            done.append(o)
        except AdfError as exc:
            skipped.append(f"{o.name}: {exc.diagnostics[0].message}")
    return done, skipped


def add_joint(
    parent,
    child,
    joint_type: str = "revolute",
    frame: Matrix | None = None,
    name: str | None = None,
    spring_defaults: bool = True,
):
    """An Empty with a rigid body constraint between two bodies; the Empty is the joint frame
    (Z: axis of hinge/spring joints, X: axis of prismatic joints). A spring joint gets limits,
    stiffness and damping that hold its child (tuning.spring_defaults)."""
    from adfkit.model.semantics import joint_kind

    from .build import RBC_TYPE, ensure_rigidbody_world

    scene = bpy.context.scene
    ensure_rigidbody_world(scene)
    e = _link(bpy.data.objects.new(name or f"{parent.name}-{child.name}", None))
    e.empty_display_type, e.empty_display_size = "ARROWS", 0.02
    e.matrix_world = frame if frame is not None else Matrix.Translation(child.matrix_world.translation)
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    bpy.context.view_layer.objects.active = e
    e.select_set(True)
    bpy.ops.rigidbody.constraint_add(type=RBC_TYPE.get(joint_kind(joint_type), "GENERIC_SPRING"))
    e.rigid_body_constraint.object1, e.rigid_body_constraint.object2 = parent, child
    e.adf.kind = "JOINT"
    e.adf.joint.use_type, e.adf.joint.type = True, joint_type
    if spring_defaults:
        from .tuning import spring_defaults as defaults

        defaults(scene, e)
    return e


def _cylinder(name: str, radius: float, length: float, segments: int = 8):
    verts, faces = [], []
    for z in (-length / 2, length / 2):
        for i in range(segments):
            a = 2 * math.pi * i / segments
            verts.append((radius * math.cos(a), radius * math.sin(a), z))
    for i in range(segments):
        j = (i + 1) % segments
        faces.append((i, j, segments + j, segments + i))
    faces.append(tuple(range(segments - 1, -1, -1)))
    faces.append(tuple(range(segments, 2 * segments)))
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    me.update()
    return me


def create_rope(
    name: str,
    count: int,
    length: float,
    radius: float,
    mass: float,
    origin=(0, 0, 0),
    stiffness: float = 0.5,
    damping: float = 0.05,
) -> tuple[list, list]:
    """A thread of ``count`` capsule bodies along +X joined by six-dof springs."""
    seg = length / count
    bodies, joints = [], []
    rot = Quaternion((0, 1, 0), math.pi / 2).to_matrix().to_4x4()  # segment axis Z -> world X
    for i in range(count):
        o = _link(bpy.data.objects.new(f"{name}_{i:03d}", _cylinder(f"{name}_{i:03d}", radius, seg)))
        o.matrix_world = Matrix.Translation(Vector(origin) + Vector(((i + 0.5) * seg, 0, 0))) @ rot
        mark(o, "BODY")
        b = o.adf.body
        b.mass = mass / count
        b.use_inertia = True
        m = mass / count
        ia = m * (3 * radius**2 + seg**2) / 12
        b.inertia = (ia, ia, m * radius**2 / 2)
        add_collision_primitive(o, "CAPSULE", radius=radius, height=seg + 2 * radius * 0.5, axis="z")
        bodies.append(o)
    bpy.context.view_layer.update()
    for i in range(count - 1):
        frame = Matrix.Translation(Vector(origin) + Vector(((i + 1) * seg, 0, 0))) @ rot
        j = add_joint(bodies[i], bodies[i + 1], "six dof spring", frame, f"{name}_{i:03d}-{i + 1:03d}", False)
        p = j.adf.joint
        for attr, val in (
            ("linear_low", (0.0,) * 3),
            ("linear_high", (0.0,) * 3),
            ("angular_low", (-0.6,) * 3),
            ("angular_high", (0.6,) * 3),
            ("stiffness_linear", (0.0,) * 3),
            ("stiffness_angular", (stiffness,) * 3),
            ("damping_linear", (0.0,) * 3),
            ("damping_angular", (damping,) * 3),
            ("equilibrium_linear", (0.0,) * 3),
            ("equilibrium_angular", (0.0,) * 3),
        ):
            setattr(p, "use_" + attr, True)
            setattr(p, attr, val)
        joints.append(j)
    return bodies, joints


def add_grasp(body, range_m: float = 0.01, rays: int = 3):
    """A proximity sensor and a constraint actuator on a gripper body, at its origin."""
    if body.adf.kind != "BODY":
        _fail("not-a-body", f"'{body.name}' is not an ADF body", body, "mark it as an ADF body first")
    made = []
    for kind, name in (("SENSOR", f"{body.name}_sensor"), ("ACTUATOR", f"{body.name}_actuator")):
        o = _link(bpy.data.objects.new(name, None))
        o.adf.kind = kind
        o.empty_display_type, o.empty_display_size = "SINGLE_ARROW", 0.01
        o.parent = body
        o.matrix_parent_inverse = Matrix.Identity(4)
        made.append(o)
    s = made[0].adf.sensor
    s.use_type, s.use_range, s.range = True, True, range_m
    for i in range(rays):
        r = s.rays.add()
        r.offset = (0.0, (i - (rays - 1) / 2) * 0.002, 0.0)
        r.direction = (0.0, 0.0, 1.0)
    made[1].adf.actuator.use_type = True
    return made


def add_ghost(name: str, radius: float = 0.005, parent=None, location=(0, 0, 0)):
    g = _link(bpy.data.objects.new(name, None))
    g.adf.kind = "GHOST"
    g.empty_display_type, g.empty_display_size = "SPHERE", radius
    if parent is not None:
        g.parent = parent
        g.matrix_parent_inverse = Matrix.Identity(4)
    g.location = location
    add_collision_primitive(g, "SPHERE", radius=radius)
    return g


def problems(scene) -> list[str]:
    """Readable findings for the UI (what export would refuse)."""
    from .export import check_scene

    return [f"{d.severity.name}: {d.message}" + (f" ({d.hint})" if d.hint else "") for d in check_scene(scene)]


__all__ = [
    "mark",
    "generate_collision",
    "add_collision_primitive",
    "estimate_inertia",
    "add_joint",
    "create_rope",
    "add_grasp",
    "add_ghost",
    "problems",
    "gather",
]
