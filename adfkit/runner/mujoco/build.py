"""An ADF scene as one MuJoCo model: every model file through the project's MJCF writer
(bodies, joints, loops as equalities, lights), attached under its own prefix, plus what the
runner adds (docs/mujoco.md): joints to another model's bodies (cross_joints.py);

- six-dof-family joints (the thread, the phantom's hole bodies) join the kinematic tree and
  get one slide per free linear axis and one hinge per free angular axis, with the ADF
  stiffness, damping, equilibrium and limits as MuJoCo joint stiffness/damping/springref/range;
- a joint equality on every revolute/prismatic tree joint with a motor (AMBF's joint motors,
  held at the file's initial value, re-targeted each control step);
- ghost objects as contact-free geoms (conaffinity 0; contype 0, or bit 31 under AMBF's rule; group 4, never drawn);
- one inactive weld equality per constraint actuator (the grasp), re-targeted when grasping;
- collision groups as contype/conaffinity bits, `ignore inter collision` as excluded pairs;
- each volume's iso-surface (runner/volumes.py) as a static mesh geom on a body of its own.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import mujoco
import numpy as np

from ... import scratch
from ...converters.mjcf_write import LOOP_KINDS, to_mjcf
from ...model.semantics import JointKind, ShapeKind, body_joint_frames, collision_primitives, pose_or_identity
from ...model.tree import ONE_DOF
from .. import plan as scene_rules
from ..plan import SPRING_KINDS, is_hole, key_of, loaded_so_far, not_played, played_actuators, played_sensors
from ..rotations import matrix_to_quat, pose_to_matrix
from ..volumes import volume_surfaces
from .collision import GHOST_CONTYPE, GHOST_GROUP, collision_filters, warn_losses
from .cross_joints import cross_model_joints, stiff_static_hinges
from .drives import add_drive, drive_limit
from .free_hinges import hold_free_hinge, is_free_hinge
from .inertia import ambf_inertia
from .spec import _parse_spec, _resolve_meshes
from .textures import apply_textures

TREE_KINDS = (JointKind.REVOLUTE, JointKind.PRISMATIC, JointKind.FIXED) + SPRING_KINDS
# the grasp weld's time constant in physics steps: 2, MuJoCo's stiffest stable setting. With the
# joint drives as constraints (drives.py) the grasp holds at 4 steps as well (the needle within
# 0.13 mm of the jaws through pair 1, seed 0; the 13 mm slide measured there before was the
# wrist's PD servos giving way, not the weld); at 10 it moved 1.1 mm and the pull left the
# wrist's reach
WELD_TIMECONST_STEPS = 2
WELD_DAMPING_RATIO = 1.0


@dataclass
class BodyPlan:
    key: str  # namespace + identifier, as every engine keys it
    body: object  # ADF Body
    model: object  # ADF ModelFile
    mjname: str  # MJCF body name ("world" for ADF's world stand-in)
    link: object  # model.tree.Link
    spring: tuple | None = None  # (joint, kind) of a six-dof-family joint to its parent
    prefix: str = ""  # the model's MJCF prefix (a "world" body's geoms are the worldbody's with it)

    def geoms(self, spec) -> list:
        """The MjsGeoms the MJCF writer made of this body."""
        if self.mjname == "world":
            return [g for g in spec.worldbody.geoms if g.name.startswith(self.prefix)]
        return list(spec.body(self.mjname).geoms)


#: kg·m² added to each hinge of a six-dof spring: a thread element's turn about its own axis has
#: 5e-10 kg·m² (the bundled suture's), the needle at its root 0.5 kg, and in one generalized mass
#: matrix MuJoCo found it singular and reset the state as the thread was drawn through two holes;
#: 1e-9 is 2 % of the last element's bending inertia about its joint (Bullet's maximal
#: coordinates give each element its own inertia and never meet the span)
SPRING_HINGE_ARMATURE = 1e-9


@dataclass
class GhostPlan:
    key: str
    ghost: object
    parent: BodyPlan | None
    geoms: list[str] = field(default_factory=list)
    friction: bool = False
    location: np.ndarray | None = None  # the ghost's frame in its parent's ADF body frame (or the world)


@dataclass
class Plan:
    spec: object
    bodies: list[BodyPlan]
    ghosts: list[GhostPlan]
    actuators: list[tuple]  # (plan.Grasper with a BodyPlan parent, weld name)
    joints: list[tuple]  # (ADF joint, kind, parent BodyPlan, child BodyPlan, MJCF joint names)
    loops: list[tuple]  # (ADF joint, kind, parent BodyPlan, child BodyPlan, pivot in parent link, pivot in child link)
    springs: int = 0
    losses: list = field(default_factory=list)
    tmp: object = None
    sensors: list = field(default_factory=list)  # plan.SensorRays with BodyPlan parents
    volumes: list = field(default_factory=list)  # (runner.volumes.VolumeSurface, MJCF body name)


def _spring_axes(joint, kind):
    """[(slide|hinge, axis index, low, high, stiffness, damping, equilibrium)] of a six-dof-family joint."""
    from ..springs import spring_joint

    sj = spring_joint(joint, kind, None, None, np.eye(4), np.eye(4))
    out = []
    for tag, lo, hi, k, c, eq in (
        ("slide", sj.lin_low, sj.lin_high, sj.k_lin, sj.c_lin, sj.eq_lin),
        ("hinge", sj.ang_low, sj.ang_high, sj.k_ang, sj.c_ang, sj.eq_ang),
    ):
        for i in range(3):
            if hi[i] - lo[i] > 1e-12:
                out.append((tag, i, float(lo[i]), float(hi[i]), float(k[i]), float(c[i]), float(eq[i])))
    return out


def _ghost_geoms(body_el, gh, pose_in_link: np.ndarray, name: str, warn, sensing: bool = False) -> list[str]:
    prims = collision_primitives(gh)
    if not prims:
        warn(
            "runner-ghost", f"{gh.identifier}: only primitive ghost shapes are played by the MuJoCo engine; skipped", gh
        )
        return []

    out = []
    for n, p in enumerate(prims):
        t = pose_in_link @ pose_to_matrix(p.pose)
        g = p.geometry
        kw = dict(contype=GHOST_CONTYPE if sensing else 0, conaffinity=0, group=GHOST_GROUP, pos=t[:3, 3])
        kw.update(rgba=[0, 1, 0, 0.2], name=f"{name}#{n}")
        if p.kind is ShapeKind.BOX:
            kw.update(type=mujoco.mjtGeom.mjGEOM_BOX, size=[(g.x or 0) / 2, (g.y or 0) / 2, (g.z or 0) / 2])
        elif p.kind is ShapeKind.SPHERE:
            kw.update(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[g.radius or 0.0, 0, 0])
        elif p.kind in (ShapeKind.CYLINDER, ShapeKind.CAPSULE):
            ax = (g.axis or "z").lower()
            turn = {
                "x": np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]]),
                "y": np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]]),
            }
            r = t[:3, :3] @ turn[ax].T if ax in turn else t[:3, :3]
            t = t.copy()
            t[:3, :3] = r
            half = (
                (g.height or 0) / 2 if p.kind is ShapeKind.CYLINDER else max((g.height or 0) / 2 - (g.radius or 0), 0)
            )
            kw.update(
                type=mujoco.mjtGeom.mjGEOM_CYLINDER if p.kind is ShapeKind.CYLINDER else mujoco.mjtGeom.mjGEOM_CAPSULE,
                size=[g.radius or 0.0, half, 0],
            )
        else:
            warn("runner-ghost", f"{gh.identifier}: ghost shape {p.kind.value} not played by the MuJoCo engine", gh)
            continue
        q = matrix_to_quat(t[:3, :3])
        kw["quat"] = [q[3], q[0], q[1], q[2]]
        body_el.add_geom(**kw)
        out.append(kw["name"])
    return out


def build_plan(world) -> Plan:
    """The MjSpec of ``world.scene`` (not compiled) and the tables the MuJoCo world reads."""
    from ..names import Registry, merge_namespace

    scene, opt = world.scene, world.opt
    tmp = scratch.temporary_directory("adfkit-mj-")
    out_dir = Path(tmp.name)
    spec = mujoco.MjSpec()
    spec.compiler.degree = False
    bodies: list[BodyPlan] = []
    registry: Registry = world.registry
    plans_by_model = []
    losses = []
    not_played(world, scene.all_models(), "mujoco")
    for i, m in enumerate(scene.all_models()):
        ns = m.namespace or ""
        mine = {}
        uncreated = scene_rules.uncreated_bodies(world, m)  # skipped, warned about, with the joints naming them
        soft = world.soft is not None and any(sb.defined for sb in m.soft_bodies)
        if len(uncreated) < len(m.bodies) or soft:
            names, flexes = {}, {}  # type: ignore[var-annotated]
            unheld = scene_rules.unheld_joints(m, world)  # AMBF keeps them, holding nothing; warned about
            text, ls = to_mjcf(
                replace(m, joints=[j for j in m.joints if j.identifier not in unheld]) if unheld else m,
                out_dir,
                f"m{i}",
                tree_kinds=TREE_KINDS,
                names_out=names,
                volumes=False,
                leave_out=uncreated,
                lights=False,
                flexes_out=flexes,
                breadth_first=True,  # the PyBullet runner's tree, its loops closed at the same joints
            )
            losses += ls
            warn_losses(world, m, ls)
            if soft:
                world.soft.plan(m, f"m{i}/", flexes, ls)
            child = _parse_spec(text, m)
            _resolve_meshes(world, child, out_dir, m)
            prefix = f"m{i}/"
            spec.attach(child, frame=spec.worldbody.add_frame(), prefix=prefix)
            tree = names.pop("")
            for b in m.bodies:
                if b.identifier not in names:
                    continue
                mjname, link = names[b.identifier]
                key = registry.add(merge_namespace(ns, b.namespace) + b.identifier, None)
                bp = BodyPlan(key, b, m, mjname if mjname == "world" else prefix + mjname, link, prefix=prefix)
                registry.items[key] = bp
                if link.parent is not None and link.kind in SPRING_KINDS:
                    bp.spring = (link.joint, link.kind)
                mine[b.identifier] = bp
                bodies.append(bp)
            plans_by_model.append((m, mine, tree))
        else:
            plans_by_model.append((m, mine, None))
    joints, loops, springs = [], [], 0
    for _m, mine, tree in plans_by_model:
        if tree is None:
            continue
        for lk in tree.ordered():
            if lk.parent is None:
                continue
            child, parent = mine[lk.body.identifier], mine[lk.parent.body.identifier]
            jn = []
            if lk.kind in ONE_DOF:
                mj = spec.body(child.mjname)
                jn = [j.name for j in mj.joints]
            elif lk.kind in SPRING_KINDS:
                springs += 1
                mj = spec.body(child.mjname)
                for _n, (tag, ax, lo, hi, k, c, eq) in enumerate(_spring_axes(lk.joint, lk.kind)):
                    axis = [0.0, 0.0, 0.0]
                    axis[ax] = 1.0
                    j = mj.add_joint(
                        type=mujoco.mjtJoint.mjJNT_SLIDE if tag == "slide" else mujoco.mjtJoint.mjJNT_HINGE,
                        axis=axis,
                        name=f"{child.mjname}#{tag}{'xyz'[ax]}",
                        stiffness=k,
                        damping=c,
                        springref=eq,
                        armature=SPRING_HINGE_ARMATURE if tag == "hinge" else 0.0,
                    )
                    if np.isfinite(lo) and np.isfinite(hi) and (tag == "slide" or hi - lo < 2 * np.pi):
                        j.limited = mujoco.mjtLimited.mjLIMITED_TRUE
                        j.range = [lo, hi]
                    if is_free_hinge(j, tag, k, c):  # light elements joined by limits alone (free_hinges.py)
                        hold_free_hinge(j, world.dt)
                    jn.append(j.name)
            joints.append((lk.joint, lk.kind, parent, child, jn))
        for j, kind, pb_, cb in tree.loops:
            parent, child = mine[pb_.identifier], mine[cb.identifier]
            if kind in LOOP_KINDS:
                a, b = body_joint_frames(j, pb_, cb)
                pa = np.array(parent.link.in_link(a).position, float)
                pbv = np.array(child.link.in_link(b).position, float)
                loops.append((j, kind, parent, child, pa, pbv))
            else:
                world._warn(
                    "runner-loop",
                    f"{j.identifier}: a {kind.value} joint closing a loop is not played by the MuJoCo engine; skipped",
                    j,
                )
    stiff_static_hinges(spec, loops, world.dt, WELD_TIMECONST_STEPS, WELD_DAMPING_RATIO)
    loops += cross_model_joints(world, spec, plans_by_model, BodyPlan)  # a joint to another model's body
    ambf_inertia(opt, spec, bodies, world._warn)
    if world.soft is not None:
        world.soft.attach(spec, scene.all_models(), {bp.key: bp for bp in bodies})
    _lights(world, spec)
    collision_filters(world, spec, bodies, joints + loops, plans_by_model)
    apply_textures(world, spec, bodies)
    ghosts, actuators, sensors = [], [], []
    known = None
    for m, mine, _tree in plans_by_model:
        known = loaded_so_far(known, mine.values())
        ns = m.namespace or ""
        for gh in m.ghost_objects:
            parent = scene_rules.resolve_parent(world, gh.parent, ns, gh, BodyPlan) if gh.parent else None
            loc = location = pose_to_matrix(pose_or_identity(gh.location))
            if parent is not None:
                loc = np.linalg.inv(pose_to_matrix(parent.link.frame_in_body)) @ loc
            key = registry.add(key_of(ns, gh), None)
            body_el = spec.worldbody if parent is None or parent.mjname == "world" else spec.body(parent.mjname)
            gp = GhostPlan(
                key,
                gh,
                parent,
                _ghost_geoms(body_el, gh, loc, f"ghost:{key}", world._warn, sensing=opt.ghosts == "ambf"),
                is_hole(gh, opt),
                location,
            )
            if gp.geoms:
                ghosts.append(gp)
        sensors += played_sensors(world, m, BodyPlan, known, resistance=opt.bodies == "ambf")
        for g in played_actuators(world, m, BodyPlan, known):
            parent, key = g.parent, g.key
            weld = f"grasp:{key}"
            spec.add_equality(
                type=mujoco.mjtEq.mjEQ_WELD,
                name=weld,
                name1=parent.mjname,
                name2="world",
                objtype=mujoco.mjtObj.mjOBJ_BODY,
                active=False,
                solref=[WELD_TIMECONST_STEPS * world.dt, WELD_DAMPING_RATIO],
            )
            actuators.append((g, weld))
    for j, kind, _pa, child, jn in joints:
        if kind in ONE_DOF and jn and drive_limit(j) > 0:
            add_drive(spec, jn[0], child.mjname, world.dt)
    volumes = _volumes(world, spec, scene.all_models())
    return Plan(spec, bodies, ghosts, actuators, joints, loops, springs, losses, tmp, sensors, volumes)


def _volumes(world, spec, models) -> list[tuple]:
    """Each playable volume as a static body: its iso-surface as one mesh geom that is drawn
    and does not collide, and convex parts, one per block of voxels the surface crosses
    (geometry.surface_parts), that collide with every body (as a body without collision groups
    does) and are not drawn. MuJoCo collides a mesh as its convex hull: the parts keep the
    contact on the surface up to concavities smaller than a block (``not_played`` says so)."""
    from ...geometry.surface_parts import PART_BLOCK

    out = []
    for i, vs in enumerate(volume_surfaces(world, models, BodyPlan)):
        name = f"adfkit:volume{i}"
        spec.add_mesh(name=name, uservert=vs.vertices.astype(float).ravel(), userface=vs.faces.astype(int).ravel())
        el, frame = spec.worldbody, vs.location
        if vs.parent is not None:  # a child of the parent's MJCF body, moving with it
            frame = np.linalg.inv(pose_to_matrix(vs.parent.link.frame_in_body)) @ frame
            if vs.parent.mjname != "world":
                el = spec.body(vs.parent.mjname)
        q = matrix_to_quat(frame[:3, :3])
        body = el.add_body(name=name, pos=frame[:3, 3], quat=[q[3], q[0], q[1], q[2]])
        body.add_geom(
            type=mujoco.mjtGeom.mjGEOM_MESH,
            meshname=name,
            name=name,
            rgba=list(vs.rgba),
            group=0,
            contype=0,
            conaffinity=0,
            density=0.0,  # adds no mass to a parent it hangs from
        )
        parts = vs.convex_parts()
        for k, points in enumerate(parts):
            spec.add_mesh(name=f"{name}:part{k}", uservert=points.astype(float).ravel())
            body.add_geom(
                type=mujoco.mjtGeom.mjGEOM_MESH,
                meshname=f"{name}:part{k}",
                group=3,
                density=0.0,
                contype=(1 << 31) - 1,
                conaffinity=(1 << 31) - 1,
            )
        vs.report["convex_parts"] = len(parts)
        world.not_played.append(
            {
                "object": vs.volume.identifier,
                "what": "concave collision",
                "why": f"MuJoCo collides a mesh as its convex hull: the volume collides by {len(parts)} convex parts "
                f"of at most {PART_BLOCK}³ voxels, so a cavity smaller than a part is solid to contacts",
            }
        )
        out.append((vs, name))
    return out


def _lights(world, spec) -> None:
    """The world's and the model files' spot lights, each in the MJCF body at the root of its
    parents (a body, through parent cameras: runner.frames), without shadows: a shadow map is
    a render pass per light per camera."""
    import math

    from ...converters.mjcf_cameras import ADF_CUTOFF, ADF_SPOT_EXPONENT
    from ..frames import resolve_frame

    w = world.scene.world
    placed = [(w.namespace or "", light) for light in (w.lights if w is not None else [])]
    placed += [(m.namespace or "", light) for m in world.scene.all_models() for light in m.lights]
    for ns, light in placed:
        el, to_link = spec.worldbody, np.eye(4)
        parent, t = resolve_frame(world, light.parent, ns, light, BodyPlan)
        if parent is not None:
            to_link = np.linalg.inv(pose_to_matrix(parent.link.frame_in_body))
            if parent.mjname != "world":
                el = spec.body(parent.mjname)
        to_link = to_link @ t
        d = np.array(light.direction if light.direction is not None else (1.0, 0.0, 0.0), float)
        if np.linalg.norm(d) == 0:
            d = np.array([1.0, 0.0, 0.0])
        pos = to_link[:3, :3] @ np.array(light.location or (0.0, 0.0, 0.0), float) + to_link[:3, 3]
        el.add_light(
            pos=list(pos),
            dir=list(to_link[:3, :3] @ (d / np.linalg.norm(d))),
            cutoff=math.degrees(light.cutoff_angle if light.cutoff_angle is not None else ADF_CUTOFF),
            exponent=light.spot_exponent if light.spot_exponent is not None else ADF_SPOT_EXPONENT,
            castshadow=False,
        )
