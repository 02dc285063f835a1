"""MJCF → scene model, through MuJoCo's own parser and compiler.

The file is first checked by ``safexml`` (no DTD or entities). MuJoCo then resolves what
MJCF leaves implicit (default classes, `childclass`, `fromto`, euler sequences and degrees,
includes, mesh recentring) and we read the compiled model at ``qpos0``: body frames become
ADF body frames, principal inertias and their frames become `inertia` and `inertial offset`
directly, hinge/slide joints become revolute/prismatic joints whose ADF value equals MuJoCo's
``qpos`` (the `ref` of a joint is the initial value the bodies' `location`s show).
"""

from __future__ import annotations

import math
from pathlib import Path

from ..diagnostics import AdfError, error
from ..model.common import RGBA, Geometry, ShapeEntry
from ..model.files import ModelFile
from ..model.objects import Body, Inertia, Joint, JointLimits
from ..model.pose import Pose, Quat, Vec3
from ..model.semantics import inertial_joint_twist, shortest_arc
from .losses import Loss, axis_tilt
from .mjcf_cameras import read_cameras, read_lights
from .mjcf_source import Source, load
from .urdf import _unique

# mjtGeom / mjtJoint values (MuJoCo's enums, stable across 2.x-4.x)
PLANE, HFIELD, SPHERE, CAPSULE, ELLIPSOID, CYLINDER, BOX, MESH = range(8)
FREE, BALL, SLIDE, HINGE = range(4)
_GEOM_NAMES = {PLANE: "plane", HFIELD: "height field", ELLIPSOID: "ellipsoid", 8: "sdf"}


def _pose(pos, quat_wxyz) -> Pose:
    w, x, y, z = (float(v) for v in quat_wxyz)
    return Pose(Vec3(*(float(v) for v in pos)), Quat(x, y, z, w).normalized())


def _compile(source: Source, path: Path):
    import mujoco

    try:
        # the merged text when the file has includes (resolved by mjcf_source), else the file
        spec = mujoco.MjSpec.from_string(source.text) if source.text is not None else mujoco.MjSpec.from_file(str(path))
        model = spec.compile()
    except (ValueError, mujoco.FatalError) as exc:  # "XML Error: ...\nElement 'geom', line N"
        text = str(exc).strip()
        first = text.splitlines()[0] if text else type(exc).__name__
        if "XML_ELEMENT_DEPTH_EXCEEDED" in text:
            first = "elements nested too deep for MuJoCo's XML parser (at most 499 levels)"
        raise AdfError(
            error(
                "mjcf-compile",
                f"MuJoCo cannot load the file: {first}",
                source.locate(text),
                "fix what MuJoCo names; `python -m mujoco.viewer` shows the same message",
            )
        ) from None
    return mujoco, spec, model


def _mesh_files(spec, path: Path) -> list[tuple[str | None, float | None]]:
    """(file, uniform scale) of every mesh asset, in the compiled model's order."""
    base = path.parent / (getattr(spec, "meshdir", "") or "")
    out = []
    for mesh in spec.meshes:
        f = mesh.file
        if not f:
            out.append((None, None))
            continue
        s = [float(v) for v in mesh.scale]
        scale = s[0] if max(s) - min(s) < 1e-12 else None
        out.append((str((base / f).resolve()), scale))
    return out


def read(path: Path) -> tuple[ModelFile, list[Loss]]:
    path = Path(path)
    source = load(path)  # safe XML, includes resolved inside the model's folder tree
    doc = source.doc
    if doc.root.tag != "mujoco":
        raise AdfError(
            error(
                "mjcf-root",
                f"the root element is <{doc.root.tag}>, not <mujoco>",
                doc.where(doc.root),
                "an MJCF file holds one <mujoco> element",
            )
        )
    mujoco, spec, m = _compile(source, path)
    d = mujoco.MjData(m)
    d.qpos[:] = m.qpos0
    mujoco.mj_kinematics(m, d)
    meshes = _mesh_files(spec, path)
    losses: list[Loss] = []
    model = ModelFile()
    names: dict[int, str] = {}
    world_pose: dict[int, Pose] = {}
    frames: dict[int, Pose] = {}
    for b in range(1, m.nbody):
        name = m.body(b).name or f"body{b}"
        names[b] = name
        frames[b] = _visual_mesh_frame(m, b, meshes)
        world_pose[b] = _pose(d.xpos[b], d.xquat[b]) * frames[b]
    bodies: dict[int, Body] = {}
    flex = _flex_vertex_bodies(m, losses)  # MuJoCo's bodies for flex vertices: not ADF bodies
    # the world body becomes a static ADF body when something is attached to it
    needs_world = any(m.geom_bodyid[g] == 0 for g in range(m.ngeom)) or any(
        m.body_parentid[b] == 0 and m.body_jntnum[b] > 0 and m.jnt_type[m.body_jntadr[b]] != FREE
        for b in range(1, m.nbody)
        if b not in flex
    )
    if needs_world:
        names[0], frames[0], world_pose[0] = "world", Pose(), Pose()
        bodies[0] = Body(identifier="BODY world", name="world", location=Pose(), mass=0.0)
        _read_geoms(m, 0, bodies[0], meshes, losses, Pose())
        model.bodies.append(bodies[0])
    for b in range(1, m.nbody):
        if b in flex:
            continue
        who = f"BODY {names[b]}"
        body = Body(identifier=who, name=names[b], location=world_pose[b])
        body.mass = float(m.body_mass[b])
        ix, iy, iz = (float(v) for v in m.body_inertia[b])
        body.inertia = Inertia(ix=ix, iy=iy, iz=iz)
        body.inertial_offset = frames[b].inverse() * _pose(m.body_ipos[b], m.body_iquat[b])
        _read_geoms(m, b, body, meshes, losses, frames[b])
        bodies[b] = body
        model.bodies.append(body)
    for b in range(1, m.nbody):
        if b in flex:
            continue
        _read_joint(m, b, names, bodies, world_pose, frames, model, losses)
    _read_equalities(m, names, bodies, world_pose, frames, model, losses)
    mujoco.mj_comPos(m, d)
    mujoco.mj_camlight(m, d)  # cameras and lights where they are at qpos0, tracking modes included
    model.cameras = read_cameras(m, d, names, world_pose, losses)
    model.lights = read_lights(m, d, names, world_pose, losses)
    for kind, count, label in (
        ("actuator", m.nu, "actuator"),
        ("sensor", m.nsensor, "sensor"),
        ("tendon", m.ntendon, "tendon"),
        ("site", m.nsite, "site"),
    ):
        for i in range(count):
            nm = getattr(m, kind)(i).name or f"{label} {i}"
            losses.append(Loss(nm, label, "not converted to ADF"))
    model.present_lists.update({"bodies", "joints"} | {k for k in ("cameras", "lights") if getattr(model, k)})
    return model, sorted(set(losses))


def _flex_vertex_bodies(m, losses) -> set[int]:
    """Bodies MuJoCo made for flex vertices (flexcomp), each flex a named loss: an ADF soft
    body needs a mesh file, which a reader does not write."""
    import mujoco

    out: set[int] = set()
    for f in range(getattr(m, "nflex", 0)):
        adr, num = int(m.flex_vertadr[f]), int(m.flex_vertnum[f])
        out.update(int(b) for b in m.flex_vertbodyid[adr : adr + num] if int(b) > 0)
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_FLEX, f) or f"flex {f}"
        losses.append(
            Loss(
                name,
                "flex",
                f"a MuJoCo flex ({num} vertices) is not read: "
                "an ADF soft body needs a mesh file; export the flex as OBJ and list it in 'soft bodies'",
            )
        )
    return out


def _visual_mesh_frame(m, b: int, meshes) -> Pose:
    """The file frame of the body's only visual mesh (ADF draws a mesh at the body frame),
    else the identity."""
    found = []
    for g in range(m.body_geomadr[b], m.body_geomadr[b] + m.body_geomnum[b]):
        if int(m.geom_type[g]) == MESH and m.geom_contype[g] == 0 and m.geom_conaffinity[g] == 0:
            mid = int(m.geom_dataid[g])
            if 0 <= mid < len(meshes) and meshes[mid][0] is not None:
                found.append(_mesh_file_frame(m, g))
    return found[0] if len(found) == 1 else Pose()


def _mesh_file_frame(m, g: int) -> Pose:
    """Where the mesh file's own frame sits in the body: MuJoCo recentres a mesh on its COM
    and principal axes and moves the geom frame to match; undo it."""
    mid = int(m.geom_dataid[g])
    return _pose(m.geom_pos[g], m.geom_quat[g]) * _pose(m.mesh_pos[mid], m.mesh_quat[mid]).inverse()


def _read_geoms(m, b: int, body: Body, meshes, losses, frame: Pose) -> None:
    who = body.identifier
    to_body = frame.inverse()
    collision: list[ShapeEntry] = []
    visual: list[ShapeEntry] = []
    for g in range(m.body_geomadr[b], m.body_geomadr[b] + m.body_geomnum[b]):
        gtype = int(m.geom_type[g])
        pose = to_body * _pose(m.geom_pos[g], m.geom_quat[g])
        visual_only = m.geom_contype[g] == 0 and m.geom_conaffinity[g] == 0
        size = [float(v) for v in m.geom_size[g]]
        entry = None
        if gtype == SPHERE:
            entry = ShapeEntry(shape="sphere", geometry=Geometry(radius=size[0]), offset=pose)
        elif gtype == CAPSULE:
            entry = ShapeEntry(
                shape="capsule",
                geometry=Geometry(radius=size[0], height=2 * size[1] + 2 * size[0], axis="z"),
                offset=pose,
            )
        elif gtype == CYLINDER:
            entry = ShapeEntry(
                shape="cylinder", geometry=Geometry(radius=size[0], height=2 * size[1], axis="z"), offset=pose
            )
        elif gtype == BOX:
            entry = ShapeEntry(shape="box", geometry=Geometry(x=2 * size[0], y=2 * size[1], z=2 * size[2]), offset=pose)
        elif gtype == MESH:
            mid = int(m.geom_dataid[g])
            fn, scale = meshes[mid] if 0 <= mid < len(meshes) else (None, None)
            if fn is None:
                losses.append(Loss(who, "inline mesh", "a mesh given by vertices in the XML has no file for ADF"))
                continue
            at = to_body * _mesh_file_frame(m, g)
            if at.position.norm() > 1e-9 or at.orientation.angle_to(Quat(0, 0, 0, 1)) > 1e-9:
                losses.append(Loss(who, "mesh offset", "ADF meshes sit at the body frame; this one is offset"))
            if scale is None:
                losses.append(Loss(who, "mesh scale", "non-uniform mesh scale; ADF scales uniformly"))
            if visual_only:
                if body.mesh is None:
                    body.mesh, body.scale = fn, (scale if scale not in (None, 1.0) else None)
                    rgba = [float(v) for v in m.geom_rgba[g]]
                    body.color_rgba = RGBA(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3])
                else:
                    losses.append(Loss(who, "visual mesh", "ADF has one visual mesh per body; extra dropped"))
            elif body.collision_mesh is None and not collision:
                body.collision_mesh = fn
                if body.mesh is None:
                    body.mesh = fn
            else:
                losses.append(Loss(who, "collision mesh", "ADF has one collision mesh per body; extra dropped"))
            continue
        else:
            losses.append(Loss(who, f"collision {_GEOM_NAMES.get(gtype, str(gtype))}", "no ADF shape for it"))
            continue
        (visual if visual_only else collision).append(entry)
    if collision and body.collision_mesh is not None:
        losses.append(Loss(who, "collision mesh", "ADF takes primitives or a mesh, not both; mesh dropped"))
        body.collision_mesh = None
    if collision:
        body.compound_collision_shape = collision
    if visual:
        body.compound_shape = visual


def _angle_about(axis: Vec3, q: Quat) -> float:
    return 2.0 * math.atan2(q.x * axis[0] + q.y * axis[1] + q.z * axis[2], q.w)


def _read_joint(m, b: int, names, bodies, world_pose, frames, model: ModelFile, losses) -> None:
    parent_id = int(m.body_parentid[b])
    child = bodies[b]
    n, adr = int(m.body_jntnum[b]), int(m.body_jntadr[b])
    if n == 0:
        if parent_id == 0 and 0 not in bodies:
            if child.mass:
                losses.append(
                    Loss(
                        child.identifier,
                        "mass",
                        "welded to the world: an ADF body fixed to the world is static (mass 0)",
                    )
                )
            child.mass = 0.0
            return
        _add_joint(
            model,
            f"{names[parent_id]}-{names[b]}",
            "fixed",
            bodies[parent_id],
            child,
            world_pose[parent_id].inverse() * world_pose[b],
            Vec3(),
            Vec3(0.0, 0.0, 1.0),
            0.0,
            None,
            losses,
        )
        return
    if int(m.jnt_type[adr]) == FREE:
        return  # a free body: no ADF joint (MuJoCo allows a free joint only alone)
    # Several joints on one body act in order, each about axes of the frame the previous ones
    # turned, and at qpos0 every one of them is the identity (MuJoCo applies qpos - qpos0): so
    # they are a chain through bodies that all sit at the body frame at qpos0. ADF joins two
    # bodies by one joint, and a dynamic ADF body needs a mass: the added ones get 1 %.
    body_frame = world_pose[b] * frames[b].inverse()
    used = {x.name for x in model.bodies} if n > 1 else set()  # names for the added chain bodies
    previous, previous_pose = bodies[parent_id], world_pose[parent_id]
    added = []
    for k, j in enumerate(range(adr, adr + n)):
        jname = m.joint(j).name or (f"{names[b]}_joint" if n == 1 else f"{names[b]}_joint{k}")
        if k == n - 1:
            nxt, nxt_pose, to_body = child, world_pose[b], frames[b].inverse()
        else:
            nxt = _chain_body(m, b, _unique(f"{names[b]}_{jname}", used), body_frame)
            model.bodies.append(nxt)
            added.append(nxt.name)
            nxt_pose, to_body = body_frame, Pose()
        _read_one_joint(m, j, jname, previous, nxt, previous_pose.inverse() * nxt_pose, to_body, model, losses)
        previous, previous_pose = nxt, nxt_pose
    if added:
        losses.append(
            Loss(
                child.identifier,
                "joints",
                f"{n} joints on one body; ADF joins two bodies by one joint: "
                f"built as a chain through {', '.join(added)} (1 % of the "
                "body's mass and inertia each)",
            )
        )


def _chain_body(m, b: int, name: str, frame: Pose) -> Body:
    """A shapeless body between two of a multi-joint body's joints, at the body frame."""
    mass = max(0.01 * float(m.body_mass[b]), 1e-6)
    i = max(0.01 * float(sum(m.body_inertia[b])) / 3.0, 1e-9)
    return Body(
        identifier=f"BODY {name}",
        name=name,
        location=frame,
        mass=mass,
        inertia=Inertia(ix=i, iy=i, iz=i),
        inertial_offset=Pose(),
    )


def _read_one_joint(m, j: int, jname: str, parent: Body, child: Body, rel: Pose, to_body: Pose, model, losses) -> None:
    """MuJoCo joint ``j`` between ``parent`` and ``child`` (``rel``: child frame in the parent
    frame at qpos0; ``to_body``: MuJoCo body coordinates → the child's ADF frame)."""
    jtype = int(m.jnt_type[j])
    pivot = to_body.transform(Vec3(*(float(v) for v in m.jnt_pos[j])))
    axis = to_body.orientation.rotate(Vec3(*(float(v) for v in m.jnt_axis[j]))).normalized()
    if jtype == BALL:
        _add_joint(model, jname, "p2p", parent, child, rel, pivot, axis, 0.0, None, losses)
        return
    ref = float(m.qpos0[m.jnt_qposadr[j]])
    # the ADF zero configuration is MuJoCo's qpos = 0: undo the reference value
    undo = (
        Pose(axis.scaled(-ref))
        if jtype == SLIDE
        else Pose(pivot) * Pose(Vec3(), Quat.from_axis_angle(axis, -ref)) * Pose(pivot.scaled(-1.0))
    )
    limits = None
    if m.jnt_limited[j]:
        lo, hi = (float(v) for v in m.jnt_range[j])
        limits = JointLimits(low=lo, high=hi)
    joint = _add_joint(
        model,
        jname,
        "revolute" if jtype == HINGE else "prismatic",
        parent,
        child,
        rel * undo,
        pivot,
        axis,
        ref,
        limits,
        losses,
    )
    damping = float(m.dof_damping[m.jnt_dofadr[j]])
    if damping:
        joint.damping = damping
    for attr, label in (
        ("jnt_stiffness", "stiffness"),
        ("dof_armature", "armature"),
        ("dof_frictionloss", "friction loss"),
    ):
        arr = getattr(m, attr)
        idx = j if attr.startswith("jnt") else m.jnt_dofadr[j]
        if float(arr[idx]) != 0.0:
            losses.append(Loss(joint.identifier, label, "ADF revolute/prismatic joints have no such property"))


def _add_joint(
    model, name, jtype, parent: Body, child: Body, rel0: Pose, pivot: Vec3, axis: Vec3, ref, limits, losses
) -> Joint:
    """An ADF joint whose frames put ``child`` at ``rel0`` (in the parent body frame) at value 0,
    rotating about ``axis`` through ``pivot`` (both in the child body frame)."""
    who = f"JOINT {name}"
    a = rel0.orientation.rotate(axis)
    pa = rel0.transform(pivot)
    twist = rel0.orientation * shortest_arc(axis, a).inverse()
    offset = _angle_about(a, twist)
    joint = Joint(
        identifier=who,
        name=name,
        parent=parent.identifier,
        child=child.identifier,
        type=jtype,
        parent_pivot=pa,
        parent_axis=a,
        child_pivot=pivot,
        child_axis=axis,
        joint_limits=limits,
    )
    # AMBF builds the joint's frames in the bodies' inertial frames: a turned one turns the
    # joint's zero, which the offset takes back
    offset += inertial_joint_twist(joint, parent, child)
    tilt = axis_tilt(joint, parent, child)
    if tilt is not None:
        losses.append(tilt)
    if abs(offset) > 1e-12:
        joint.offset = offset
    model.joints.append(joint)
    return joint


def _read_equalities(m, names, bodies, world_pose, frames, model, losses) -> None:
    import mujoco

    for e in range(m.neq):
        etype = int(m.eq_type[e])
        b1, b2 = int(m.eq_obj1id[e]), int(m.eq_obj2id[e])
        name = m.eq(e).name or f"equality{e}"
        if (
            etype == int(mujoco.mjtEq.mjEQ_CONNECT)
            and b1 > 0
            and b2 > 0
            and m.eq_objtype[e] == mujoco.mjtObj.mjOBJ_BODY
        ):
            anchor1 = frames[b1].inverse().transform(Vec3(*(float(v) for v in m.eq_data[e][0:3])))
            rel = world_pose[b2].inverse() * world_pose[b1]
            _add_joint(
                model,
                name,
                "p2p",
                bodies[b1],
                bodies[b2],
                rel.inverse(),
                rel.transform(anchor1),
                Vec3(0.0, 0.0, 1.0),
                0.0,
                None,
                losses,
            )
        elif etype == int(mujoco.mjtEq.mjEQ_WELD) and b1 > 0 and b2 > 0 and m.eq_objtype[e] == mujoco.mjtObj.mjOBJ_BODY:
            _add_joint(
                model,
                name,
                "fixed",
                bodies[b1],
                bodies[b2],
                world_pose[b1].inverse() * world_pose[b2],
                Vec3(),
                Vec3(0.0, 0.0, 1.0),
                0.0,
                None,
                losses,
            )
        else:
            losses.append(Loss(name, "equality", "only body connect/weld equalities map to ADF joints"))
