"""SimWorld: an ADF scene (adfkit.model.Scene) built in PyBullet and stepped.

Bodies joined by revolute/prismatic trees become multibodies (exact joints, native limits and
position motors); every other body is a maximal-coordinate rigid body and every other joint a
createConstraint plus per-step forces (joints.py). docs/runner.md says why.
"""

from __future__ import annotations

import contextlib
import math
import time
from dataclasses import dataclass, field

import numpy as np
import pybullet as pb

from ..diagnostics import Diagnostic, warning
from ..model.semantics import (
    ACTUATOR_TYPES,
    DEFAULT_ACTUATOR_MAX_IMPULSE,
    DEFAULT_GRAVITY,
    DEFAULT_SENSOR_RANGE,
    SENSOR_TYPES,
    JointKind,
    joint_frames,
    joint_kind,
    pose_or_identity,
)
from . import articulation, egl, stability
from .bodies import SimBody, body_gravity, make_sim_body, set_dynamics
from .cameras import choose_renderer
from .joints import ConstraintRefused, SpringSet, make_constraint, spring_joint
from .names import Registry, merge_namespace
from .neutral import EngineNeutral
from .options import Options  # noqa: F401 - the world's options, imported from here by callers
from .rotations import invert, matrix_to_pq, pose_matrix, pose_to_matrix
from .shapes import collision_parts, create_collision, create_visual
from .softbodies import SoftBodies, enable_deformable_world
from .softbodies import in_scene as soft_in_scene
from .world_state import WorldState

GRASP_SPAN = 0.005  # m between the three point constraints of a grasp (SimWorld.actuate)
SPRING_KINDS = (
    JointKind.SIX_DOF,
    JointKind.SIX_DOF_SPRING,
    JointKind.CONE_TWIST,
    JointKind.LINEAR_SPRING,
    JointKind.TORSION_SPRING,
)


@dataclass(eq=False)
class SimGhost:
    key: str
    ghost: object
    uid: int
    parent: SimBody | None
    pose_in_parent: np.ndarray  # ghost COM frame in the parent's PyBullet frame (or world)
    friction: bool = False
    overlapping: list = field(default_factory=list)
    pq_in_parent: tuple = ()  # pose_in_parent as PyBullet (position, quaternion)
    moves: bool = False  # a dynamic parent: the ghost follows it every step


@dataclass(eq=False)
class SimActuator:
    key: str
    actuator: object
    parent: SimBody
    location: np.ndarray  # in the parent body frame
    max_force: float
    constraint: list | None = None  # the grasp's constraint ids (see SimWorld.actuate)
    target: SimBody | None = None


@dataclass(eq=False)
class SimSensor:
    key: str
    sensor: object
    parent: SimBody
    location: np.ndarray
    starts: np.ndarray
    ends: np.ndarray
    sensed: list = field(default_factory=list)


class SimWorld(EngineNeutral, WorldState):
    def __init__(self, scene, options: Options | None = None, gui: bool = False) -> None:
        self.scene = scene
        self.opt = options or Options()
        self.diagnostics: list[Diagnostic] = []
        self.gui = gui
        self.cid = pb.connect(pb.GUI if gui else pb.DIRECT)
        self.soft = SoftBodies(self) if soft_in_scene(scene) else None  # soft bodies: a deformable world
        if self.soft is not None:
            enable_deformable_world(self.cid)
        has_cameras = bool(scene.world is not None and scene.world.cameras) or any(
            m.cameras for m in scene.all_models()
        )
        self._mj_view = None
        self.renderer, self.renderer_note = choose_renderer(
            self.opt.renderer, self.cid, has_cameras, self.soft is not None, gui
        )
        self.dt = 1.0 / self.opt.physics_hz
        w = scene.world
        g = self.opt.gravity or (tuple(w.gravity) if w is not None and w.gravity is not None else DEFAULT_GRAVITY)
        self.gravity = np.array(g, dtype=float)
        self.max_substeps = w.max_iterations if w is not None and w.max_iterations else 10
        pb.setGravity(*self.gravity, physicsClientId=self.cid)
        # PyBullet: each stepSimulation advances fixedTimeStep, split into numSubSteps internal steps
        params = dict(fixedTimeStep=self.dt * self.opt.control_substeps, numSubSteps=self.opt.control_substeps)
        if self.opt.solver_iterations:
            params["numSolverIterations"] = self.opt.solver_iterations
        if self.opt.contact_threshold is not None:
            # AABBs grow by it and contact points are made within (a size-scaled share of) it;
            # a millimetre-sized scene plays ~1.4x faster at 0.001 (bench/run_suturing.py)
            params["contactBreakingThreshold"] = self.opt.contact_threshold
        pb.setPhysicsEngineParameter(physicsClientId=self.cid, **params)
        self.registry = Registry()
        self.bodies: list[SimBody] = []
        self.constraints: list[
            tuple
        ] = []  # (joint name, constraint id, parent, child, pivot a, pivot b, slide axis in a | None)
        self.articulations: list = []
        self.ghosts: list[SimGhost] = []
        self.actuators: list[SimActuator] = []
        self.sensors: list[SimSensor] = []
        self.cameras: list = []
        self.joint_names: list[str] = []
        self.skipped: list[str] = []
        self.steps = 0
        self.sim_time = 0.0
        self.wall_time = 0.0
        self.watch = stability.Watch()
        self._next_stability_check = 0.0
        self.volumes: list[dict] = []  # volumes played as iso-surface bodies (runner/volumes.py)
        self.not_played: list[dict] = []  # every part of the scene not played, with why
        pb.setPhysicsEngineParameter(enableFileCaching=1, physicsClientId=self.cid)
        self._build()

    # ---- building ------------------------------------------------------------------------
    def _build(self) -> None:
        models = self.scene.all_models()
        records = []
        self._model_bodies: dict[int, list[SimBody]] = {}
        for m in models:
            ns = m.namespace or ""
            mine = []
            for kind, objs in (("vehicle", m.vehicles),):
                for o in objs:
                    self._warn(
                        f"runner-{kind.replace(' ', '-')}",
                        f"{o.identifier}: {kind}s are not played by the PyBullet runner; skipped",
                        o,
                        "play this object in AMBF itself",
                    )
            for b in m.bodies:
                sb = make_sim_body(merge_namespace(ns, b.namespace) + b.identifier, b, m)
                sb.cid = self.cid
                sb.gravity = body_gravity(b, m, self.gravity)
                sb._parts = collision_parts(m, b, sb.ref_in_body, b.scale or 1.0, sb.static, self.diagnostics)
                if sb._parts is None:
                    self.skipped.append(sb.key)
                    continue
                sb.key = self.registry.add(sb.key, sb)
                mine.append(sb)
                self.bodies.append(sb)
            self._model_bodies[id(m)] = mine
            local = Registry()
            for sb in mine:
                local.items[sb.key] = sb
            for j in m.joints:
                if self.soft is not None and self.soft.claim(m, j):
                    continue  # joins a soft body: anchors, made with the soft bodies
                kind = joint_kind(j.type)
                if kind is None:
                    self._warn("runner-joint-type", f"{j.identifier}: unknown joint type {j.type!r}; skipped", j)
                    continue
                jns = merge_namespace(ns, j.namespace)
                ends = []
                for ref in (j.parent, j.child):
                    key, hit = local.find(ref)
                    if key is None:
                        key, hit = local.find(jns + (ref or ""))
                    if key is None:
                        key, hit = self.registry.find(jns + (ref or ""))
                    if key is None:
                        key, hit = self.registry.find(ref)
                    ends.append(hit if key is not None else None)
                if None in ends:
                    self._warn("runner-joint-body", f"{j.identifier}: parent or child body not found; skipped", j)
                    continue
                records.append((j, kind, ends[0], ends[1]))
        trees, leftover = articulation.components(records)
        in_tree = set()
        for root, recs in trees:
            in_tree.add(id(root))
            in_tree.update(id(r[3]) for r in recs)
        for sb in self.bodies:
            if id(sb) not in in_tree:
                self._create_free(sb)
        for root, recs in trees:
            self_coll = not all(r[3].model.ignore_inter_collision for r in recs)
            art = articulation.build(root, recs, self._shapes_for, self.dt, self.cid, self_coll)
            self.articulations.append(art)
            self.joint_names.extend(art.joint_names)
            for sb in [root] + [r[3] for r in recs]:
                set_dynamics(sb)
        self._collision_filters(records)
        if self.soft is not None:
            self.soft.build(models)
        springs = []
        for j, kind, parent, child in leftover:
            ps = parent.body.scale or 1.0
            cs = child.body.scale or 1.0
            a, b = joint_frames(j, ps, cs)
            fa = invert(parent.com_in_body) @ pose_to_matrix(a)
            fb = invert(child.com_in_body) @ pose_to_matrix(b)
            self.joint_names.append(j.identifier)
            sj = None
            if kind in SPRING_KINDS:
                sj = spring_joint(j, kind, parent, child, fa, fb)
                springs.append(sj)
                if not sj.linear_constrained:
                    continue
                kind_c = JointKind.P2P
            else:
                kind_c = kind
            if kind is JointKind.PRISMATIC and not (parent.articulation and child.articulation):
                # PyBullet slides only between multibody links (btMultiBodySliderConstraint)
                self._warn(
                    "runner-prismatic-loop",
                    f"{j.identifier}: a prismatic joint closing a loop through "
                    "a maximal-coordinate body is not supported by PyBullet's constraints; built as fixed",
                    j,
                )
                kind_c = JointKind.FIXED
            try:
                made = make_constraint(self.cid, kind_c, parent, child, fa, fb, 1e5)
            except ConstraintRefused as exc:
                self._warn("runner-constraint", f"{j.identifier}: {exc}; the joint is left out", j)
                continue
            for c, pa, pbv, axis in made:
                self.constraints.append((j.identifier, c, parent, child, pa, pbv, axis))
        self.springs = SpringSet(springs, self.cid)
        from .volumes import build_volumes

        build_volumes(self, models)
        for m in models:
            self._build_ghosts(m)
            self._build_actuators(m)
            self._build_sensors(m)
        from .cameras import build_cameras

        self.cameras = build_cameras(self)
        self._floor_z = self._floor()
        self.ground_z = None
        if self.scene.world is None and self.scene.environment is None:
            if self.opt.ground:
                self._add_ground()
            else:  # --no-ground: nothing to fall through
                self._floor_z = -math.inf
        self.initial_positions = {sb.key: np.array(sb.com_position()) for sb in self.bodies}
        self._lookup = {(sb.uid, sb.link): sb for sb in self.bodies}
        self._gravity_overrides = self._group_gravity_overrides()
        self._friction_ghosts = [g for g in self.ghosts if g.friction]

    def _group_gravity_overrides(self):
        """Bodies whose gravity differs from the world's, grouped per multibody so each control
        step reads their COMs with one getLinkStates call: [(uid, links, bodies, forces)]."""
        groups: dict[int, list] = {}
        for sb in self.bodies:
            if sb.gravity is not None and not sb.static:
                groups.setdefault(sb.uid, []).append(sb)
        out = []
        for uid, sbs in groups.items():
            out.append(
                (uid, [sb.link for sb in sbs], sbs, [(sb.mass * (sb.gravity - self.gravity)).tolist() for sb in sbs])
            )
        return out

    def _add_ground(self) -> None:
        """A model played without a world gets what AMBF's worlds give it: a floor, here a
        static plane 1 mm below the lowest point of every body."""
        lows = [pb.getAABB(sb.uid, sb.link, physicsClientId=self.cid)[0][2] for sb in self.bodies if sb.uid is not None]
        if self.soft is not None and self.soft.items:
            lows.append(self.soft.lowest_z())
        if not lows:
            return
        self.ground_z = min(lows) - 1e-3
        if self.soft is None:
            shape = pb.createCollisionShape(pb.GEOM_PLANE, physicsClientId=self.cid)
            vis = egl.plane_visual(self.cid, (0, 0, 1), 0.0) if self.renderer == "egl" else -1
            self.ground_uid = pb.createMultiBody(0.0, shape, vis, [0.0, 0.0, self.ground_z], physicsClientId=self.cid)
        else:  # soft bodies stop centimetres above a static plane: a thick slab instead
            self.ground_uid = self.soft.ground_slab(self.ground_z)
        self._floor_z = self.ground_z

    def _warn(self, rule, msg, obj, hint="") -> None:
        self.diagnostics.append(warning(rule, msg, getattr(obj, "source", None), hint or None))

    def _shapes_for(self, sb: SimBody, frame_in_body) -> tuple[int, int]:
        b, m = sb.body, sb.model
        if frame_in_body is not sb.ref_in_body or sb._parts is None:
            sb._parts = collision_parts(m, b, frame_in_body, b.scale or 1.0, sb.static, self.diagnostics)
        col = create_collision(sb._parts, self.cid, b, self.diagnostics) if sb._parts is not None else -1
        vis = create_visual(m, b, frame_in_body, b.scale or 1.0, self.cid, self.diagnostics) if self.opt.visuals else -1
        return col, self._plane_visual(sb._parts, col, vis)

    def _plane_visual(self, parts, col: int, vis: int) -> int:
        """The EGL plugin's crash on a lone PLANE without a visual, avoided (runner/egl.py)."""
        if (
            self.renderer == "egl"
            and vis == -1
            and col != -1
            and parts is not None
            and parts.plane is not None
            and not parts.types
        ):
            return egl.plane_visual(self.cid, *parts.plane)
        return vis

    def _create_free(self, sb: SimBody) -> None:
        col, vis = self._shapes_for(sb, sb.ref_in_body)
        pos, orn = matrix_to_pq(sb.body_world_matrix @ sb.ref_in_body)
        if sb._parts is not None and sb._parts.plane is not None and not sb.static:
            self._warn("runner-plane", f"{sb.key}: a PLANE shape on a dynamic body; made static", sb.body)
            sb.mass = 0.0
        sb.uid = pb.createMultiBody(sb.mass, col, vis, pos, orn, useMaximalCoordinates=True, physicsClientId=self.cid)
        sb.link = -1
        set_dynamics(sb)

    def _collision_filters(self, records) -> None:
        groups = sorted({g for sb in self.bodies for g in (sb.body.collision_groups or []) if 0 <= g <= 999})
        bit = {g: 1 << (i % 30) for i, g in enumerate(groups)}
        if len(groups) > 30:
            self._warn("runner-groups", "more than 30 collision groups: groups share mask bits", None)
        allbits = (1 << 31) - 1
        for sb in self.bodies:
            gs = [g for g in (sb.body.collision_groups or []) if 0 <= g <= 999]
            if gs:
                mask = 0
                for g in gs:
                    mask |= bit[g]
                pb.setCollisionFilterGroupMask(sb.uid, sb.link, mask, mask, physicsClientId=self.cid)
            else:
                pb.setCollisionFilterGroupMask(sb.uid, sb.link, allbits, allbits, physicsClientId=self.cid)
        for j, _kind, parent, child in records:
            if j.ignore_inter_collision is not False:
                self._no_collision(parent, child)
        for m in self.scene.all_models():
            if m.ignore_inter_collision:
                mine = self._model_bodies.get(id(m), [])
                for i, a in enumerate(mine):
                    for b in mine[i + 1 :]:
                        self._no_collision(a, b)

    def _no_collision(self, a: SimBody, b: SimBody) -> None:
        pb.setCollisionFilterPair(a.uid, b.uid, a.link, b.link, 0, physicsClientId=self.cid)

    def set_collision(self, a: SimBody, b: SimBody, enabled: bool) -> None:
        """Let two bodies collide or pass through each other (a task's choice, e.g. a needle
        through a tissue whose collision shape is a convex hull over its holes)."""
        pb.setCollisionFilterPair(a.uid, b.uid, a.link, b.link, int(enabled), physicsClientId=self.cid)
        pair = frozenset(((a.uid, a.link), (b.uid, b.link)))
        self._pairs_off = getattr(self, "_pairs_off", set())
        (self._pairs_off.discard if enabled else self._pairs_off.add)(pair)

    def move_base(self, sb: SimBody, body_world: np.ndarray) -> None:
        """Put the root of a multibody (e.g. a PSM's base, as its setup joints would) at a new
        world pose of its ADF body frame; its links follow."""
        pos, orn = matrix_to_pq(body_world @ sb.com_in_body)
        pb.resetBasePositionAndOrientation(sb.uid, pos, orn, physicsClientId=self.cid)

    def ghost_pose(self, g: SimGhost) -> np.ndarray:
        """World pose (4x4) of a ghost, following its parent."""
        return self._frame(g.parent) @ g.pose_in_parent if g.parent is not None else np.array(g.pose_in_parent)

    def _parent(self, ref: str | None, ns: str, obj):
        key, hit = self.registry.find(ref)
        if key is None and ref:
            key, hit = self.registry.find(ns + ref)
        if key is None:
            self._warn(
                "runner-parent",
                f"{obj.identifier}: parent {ref!r} not found" + (f" (matches: {', '.join(hit)})" if hit else ""),
                obj,
            )
            return None
        return hit

    def _build_ghosts(self, m) -> None:
        ns = m.namespace or ""
        for gh in m.ghost_objects:
            parts = collision_parts(m, gh, np.eye(4), gh.scale or 1.0, True, self.diagnostics)
            if parts is None or (not parts.types and parts.plane is None):
                self._warn("runner-ghost", f"{gh.identifier}: no collision geometry; ghost skipped", gh)
                continue
            parent = self._parent(gh.parent, ns, gh) if gh.parent else None
            loc = pose_to_matrix(pose_or_identity(gh.location))
            rel = invert(parent.com_in_body) @ loc if parent is not None else loc
            col = create_collision(parts, self.cid, gh, self.diagnostics)
            vis = (
                create_visual(m, gh, np.eye(4), gh.scale or 1.0, self.cid, self.diagnostics) if self.opt.visuals else -1
            )
            vis = self._plane_visual(parts, col, vis)
            world = (self._frame(parent) @ rel) if parent is not None else rel
            pos, orn = matrix_to_pq(world)
            uid = pb.createMultiBody(0, col, vis, pos, orn, useMaximalCoordinates=True, physicsClientId=self.cid)
            pb.setCollisionFilterGroupMask(uid, -1, 0, 0, physicsClientId=self.cid)
            name = (gh.name or gh.identifier).lower()
            friction = any(w in name for w in self.opt.hole_ghost_words)
            key = self.registry.add(merge_namespace(ns, gh.namespace) + gh.identifier, None)
            moves = parent is not None and not parent.static
            self.ghosts.append(
                SimGhost(key, gh, uid, parent, rel, friction, pq_in_parent=matrix_to_pq(rel), moves=moves)
            )

    def _build_actuators(self, m) -> None:
        ns = m.namespace or ""
        for a in m.actuators:
            if ACTUATOR_TYPES.get(a.type) != "constraint":
                self._warn("runner-actuator", f"{a.identifier}: actuator type {a.type!r} not supported; skipped", a)
                continue
            parent = self._parent(a.parent, ns, a)
            if parent is None:
                continue
            imp = a.max_impulse if a.max_impulse is not None else DEFAULT_ACTUATOR_MAX_IMPULSE
            key = merge_namespace(ns, a.namespace) + a.identifier
            self.actuators.append(
                SimActuator(key, a, parent, pose_to_matrix(pose_or_identity(a.location)), imp / self.dt)
            )

    def _build_sensors(self, m) -> None:
        ns = m.namespace or ""
        for s in m.sensors:
            if SENSOR_TYPES.get(s.type) != "proximity" or not s.array:
                self._warn(
                    "runner-sensor",
                    f"{s.identifier}: only proximity sensors with an `array` of rays are played; skipped",
                    s,
                )
                continue
            parent = self._parent(s.parent, ns, s)
            if parent is None:
                continue
            rng = s.range if s.range is not None else DEFAULT_SENSOR_RANGE
            starts = np.array([r.offset or (0, 0, 0) for r in s.array], dtype=float)
            dirs = np.array([r.direction or (1, 0, 0) for r in s.array], dtype=float)
            key = merge_namespace(ns, s.namespace) + s.identifier
            self.sensors.append(
                SimSensor(key, s, parent, pose_to_matrix(pose_or_identity(s.location)), starts, starts + dirs * rng)
            )

    def _frame(self, sb: SimBody) -> np.ndarray:
        """World pose of the PyBullet frame of a body."""
        p, q, _, _ = sb.state(velocity=False)
        return pose_matrix(p, q)

    def _floor(self) -> float:
        zs = []
        for sb in self.bodies:
            if sb.static:
                if sb._parts is not None and sb._parts.plane is not None:
                    zs.append(sb.body_world_matrix[2, 3] + sb._parts.plane[1])
                else:
                    zs.append(pb.getAABB(sb.uid, sb.link, physicsClientId=self.cid)[0][2])
        return min(zs) if zs else -math.inf

    # ---- queries -------------------------------------------------------------------------
    def body(self, text: str) -> SimBody:
        key, hit = self.registry.find(text)
        if key is None or not isinstance(hit, SimBody):
            raise KeyError(f"no unique body matches {text!r}")
        return hit

    def joint_state(self, art, idxs) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities of joints ``idxs`` (record indices) of an articulation."""
        st = pb.getJointStates(art.uid, list(idxs), physicsClientId=self.cid)
        return np.array([s[0] for s in st]), np.array([s[1] for s in st])

    def reset_joints(self, art, idxs, positions, velocities=None) -> None:
        """Put joints ``idxs`` of an articulation at ``positions`` (and ``velocities``, default 0) now."""
        vel = velocities if velocities is not None else [0.0] * len(idxs)
        for i, p, v in zip(idxs, positions, vel):
            pb.resetJointState(art.uid, i, float(p), float(v), physicsClientId=self.cid)

    def by_uid(self):
        """{(PyBullet uid, link): SimBody}"""
        return self._lookup

    # ---- stepping ------------------------------------------------------------------------
    def control(self) -> None:
        """Per-control-step forces: gravity overrides, springs, ghosts' viscous friction, sensors."""
        cdt = self.dt * self.opt.control_substeps
        cid = self.cid
        for uid, links, _sbs, forces in self._gravity_overrides:
            if links == [-1]:
                coms = [pb.getBasePositionAndOrientation(uid, physicsClientId=cid)[0]]
            else:
                coms = [
                    pb.getBasePositionAndOrientation(uid, physicsClientId=cid)[0] if k < 0 else s[0]
                    for k, s in zip(
                        links,
                        pb.getLinkStates(
                            uid, [max(k, 0) for k in links], computeForwardKinematics=1, physicsClientId=cid
                        ),
                    )
                ]
            for k, f, at in zip(links, forces, coms):
                pb.applyExternalForce(uid, k, f, at, pb.WORLD_FRAME, physicsClientId=cid)
        self.springs.apply(cdt)
        self._update_ghosts()
        for s in self.sensors:
            self._sense(s)

    def step(self, n: int = 1) -> None:
        """Advance n control steps (n·control_substeps physics steps of 1/physics_hz)."""
        t0 = time.perf_counter()
        sub = self.opt.control_substeps
        for _ in range(n):
            self.control()
            pb.stepSimulation(physicsClientId=self.cid)
        self.steps += n * sub
        self.sim_time = self.steps * self.dt
        if self.sim_time >= self._next_stability_check:  # NaN or a flung body, caught as it happens
            self._next_stability_check = self.sim_time + stability.CHECK_EVERY_S
            stability.check_pybullet(self, self.watch)
        self.wall_time += time.perf_counter() - t0

    # ---- ghosts, sensors, actuators -------------------------------------------------------
    def _update_ghosts(self) -> None:
        """Hole ghosts (the ones with viscous friction) sense every control step; the others
        only when asked (overlapping()): a moving ghost costs a pose reset and a distance query
        per nearby body, and the PSMs' finger ghosts are only read when grasping."""
        if self.gui:
            self.place_ghosts()
        parents: dict[int, tuple] = {}  # hole ghosts share their parent (the phantom): read it once
        cid = self.cid
        for g in self._friction_ghosts:
            if g.moves:
                pq = parents.get(id(g.parent))
                if pq is None:
                    pq = parents[id(g.parent)] = g.parent.state(velocity=False)[:2]
                pos, orn = pb.multiplyTransforms(pq[0], pq[1], *g.pq_in_parent)
                pb.resetBasePositionAndOrientation(g.uid, pos, orn, physicsClientId=cid)
            found = self._overlap(g)
            if found:
                self._viscous(g, found)

    def place_ghosts(self) -> None:
        """Move every ghost with a moving parent to it (before a picture is taken)."""
        for g in self.ghosts:
            self._place(g)

    def _place(self, g: SimGhost) -> None:
        if g.moves:
            p, q, _, _ = g.parent.state(velocity=False)
            pos, orn = pb.multiplyTransforms(p, q, *g.pq_in_parent)
            pb.resetBasePositionAndOrientation(g.uid, pos, orn, physicsClientId=self.cid)

    def overlapping(self, g: SimGhost) -> list[SimBody]:
        """The dynamic bodies inside ghost ``g`` now (moved to its parent first); also kept in
        ``g.overlapping``."""
        self._place(g)
        return self._overlap(g)

    def _overlap(self, g: SimGhost) -> list[SimBody]:
        """``overlapping`` with the ghost already where its parent is."""
        cid = self.cid
        lo, hi = pb.getAABB(g.uid, -1, physicsClientId=cid)
        found = []
        lookup = self._lookup
        for uid, link in pb.getOverlappingObjects(lo, hi, physicsClientId=cid) or ():
            sb = lookup.get((uid, link))
            if sb is None or sb.static or sb is g.parent:
                continue
            if pb.getClosestPoints(g.uid, uid, 0.0, -1, link, physicsClientId=cid):
                found.append(sb)
        g.overlapping = found
        return found

    def _viscous(self, g: SimGhost, found) -> None:
        """F = -K·(v_body - v_phantom) on every body inside a hole ghost (the paper's needle friction)."""
        k = self.opt.hole_friction
        cdt = self.dt * self.opt.control_substeps
        v_ref = np.array(g.parent.state()[2]) if g.parent is not None and not g.parent.static else np.zeros(3)
        for sb in found:
            v = np.array(sb.state()[2]) - v_ref
            # held for a control step, this force gives the exact exp(-K·t/m) decay of dv/dt = -K·v/m
            f = -sb.mass * v * (1.0 - math.exp(-k * cdt / sb.mass)) / cdt
            sb.force(f.tolist(), list(sb.com_position()))

    def _sense(self, s: SimSensor) -> None:
        t = self._frame(s.parent) @ invert(s.parent.com_in_body) @ s.location
        a = (t[:3, :3] @ s.starts.T).T + t[:3, 3]
        b = (t[:3, :3] @ s.ends.T).T + t[:3, 3]
        hits = pb.rayTestBatch(a.tolist(), b.tolist(), physicsClientId=self.cid)
        lookup = self._lookup
        s.sensed = []
        for h in hits:
            sb = lookup.get((h[0], h[1]))
            if sb is not None and sb is not s.parent and sb not in s.sensed:
                s.sensed.append(sb)

    def actuate(self, actuator: SimActuator, target: SimBody) -> None:
        """Fix ``target`` to the actuator's parent at their current relative pose.

        Three POINT2POINT constraints at non-collinear points (the actuator location and
        GRASP_SPAN along its x and y axes) rather than one JOINT_FIXED: PyBullet's fixed constraint
        between a multibody link and a maximal body drives the pair to a wrong relative
        orientation (measured: 120° off within 20 ms on the suturing PSM), while point pivots are
        exact, and three of them lock all six degrees of freedom."""
        self.release(actuator)
        pw = self._frame(actuator.parent)
        tw = self._frame(target)
        at_world = pw @ invert(actuator.parent.com_in_body) @ actuator.location
        fa = invert(pw) @ at_world
        fb = invert(tw) @ at_world
        ids = []
        for e in (np.zeros(3), np.array([GRASP_SPAN, 0, 0]), np.array([0, GRASP_SPAN, 0])):
            pa = fa[:3, :3] @ e + fa[:3, 3]
            pbv = fb[:3, :3] @ e + fb[:3, 3]
            c = pb.createConstraint(
                actuator.parent.uid,
                actuator.parent.link,
                target.uid,
                target.link,
                pb.JOINT_POINT2POINT,
                [0, 0, 0],
                pa.tolist(),
                pbv.tolist(),
                physicsClientId=self.cid,
            )
            pb.changeConstraint(c, maxForce=actuator.max_force, physicsClientId=self.cid)
            ids.append(c)
        actuator.constraint, actuator.target = ids, target
        for link in self._links(actuator.parent):  # the closed jaws would push the held body out
            if not self._pair_off(actuator.parent.uid, link, target):
                pb.setCollisionFilterPair(
                    actuator.parent.uid, target.uid, link, target.link, 0, physicsClientId=self.cid
                )

    def _pair_off(self, uid: int, link: int, b: SimBody) -> bool:
        return frozenset(((uid, link), (b.uid, b.link))) in getattr(self, "_pairs_off", ())

    def _links(self, sb: SimBody):
        art = sb.articulation
        return range(-1, len(art.records)) if art is not None else [sb.link]

    def release(self, actuator: SimActuator) -> None:
        if actuator.constraint is not None:
            for c in actuator.constraint:
                pb.removeConstraint(c, physicsClientId=self.cid)
            t = actuator.target
            for link in self._links(actuator.parent):
                if not self._pair_off(actuator.parent.uid, link, t):  # set_collision's choice stays
                    pb.setCollisionFilterPair(actuator.parent.uid, t.uid, link, t.link, 1, physicsClientId=self.cid)
        actuator.constraint, actuator.target = None, None

    # ---- measures -----------------------------------------------------------------------
    def contacts(self, sb: SimBody) -> list:
        """[(other SimBody, normal force N, world point)] of the contacts ``sb`` has after the last step."""
        out = []
        for c in pb.getContactPoints(bodyA=sb.uid, linkIndexA=sb.link, physicsClientId=self.cid) or ():
            other = self._lookup.get((c[2], c[4]))
            if other is not None and other is not sb:
                out.append((other, float(c[9]), c[5]))
        return out

    def constraint_error(self) -> float:
        """Largest distance, m, between the two pivots of any joint (constraints and springs
        with a locked linear range); multibody joints are exact."""
        worst = 0.0
        for _, _, parent, child, pa, pbv, axis in self.constraints:
            a = self._frame(parent)
            b = self._frame(child)
            gap = (a[:3, :3] @ pa + a[:3, 3]) - (b[:3, :3] @ pbv + b[:3, 3])
            if axis is not None:  # a slider: only the gap across its axis is an error
                u = a[:3, :3] @ axis
                gap = gap - np.dot(gap, u) * u
            worst = max(worst, float(np.linalg.norm(gap)))
        return worst

    def report(self) -> dict:
        fell, fast, nan, shapeless = [], [], [], []
        for sb in self.bodies:
            if sb.static:
                continue
            p, _, v, w = sb.state()
            if not np.all(np.isfinite(p)) or not np.all(np.isfinite(v)):
                nan.append(sb.key)
                continue
            parts = getattr(sb, "_parts", None)
            if parts is not None and not parts.types and parts.plane is None:
                # nothing to collide with: it falls freely under gravity, in AMBF too
                shapeless.append(sb.key)
                continue
            if math.isfinite(self._floor_z) and p[2] < self._floor_z - 0.1:
                fell.append(sb.key)
            if np.linalg.norm(v) > 10.0:
                fast.append(sb.key)
        soft = self.soft.report(self._floor_z) if self.soft is not None else ([], [], [], [])
        nan, fast, fell = nan + soft[1], fast + soft[2], fell + soft[3]
        return {
            "bodies": len(self.bodies),
            "skipped_bodies": self.skipped,
            "soft_bodies": soft[0],
            "joints": len(self.joint_names),
            "multibodies": len(self.articulations),
            "constraints": len(self.constraints),
            "spring_joints": len(self.springs.joints),
            "ghosts": len(self.ghosts),
            "sensors": len(self.sensors),
            "actuators": len(self.actuators),
            "cameras": [c.name for c in self.cameras],
            "renderer": self.renderer,
            **({"renderer_note": self.renderer_note} if self.renderer_note else {}),
            "steps": self.steps,
            "physics_hz": self.opt.physics_hz,
            "control_substeps": self.opt.control_substeps,
            "simulated_time_s": self.sim_time,
            "wall_time_s": self.wall_time,
            "real_time_factor": self.sim_time / self.wall_time if self.wall_time else None,
            "max_constraint_error_m": self.constraint_error(),
            "ground_plane_z": self.ground_z,
            "fell_through_floor": fell,
            "exploded": fast,
            "nan": nan,
            "without_collision_shape": shapeless,
            **self.watch.report(),
            "volumes": self.volumes,
            "not_played": self.not_played,
        }

    def mj_view(self):
        """The MuJoCo mirror that draws the cameras with ``renderer="mujoco"`` (runner/mjview.py),
        built on the first picture."""
        if self._mj_view is None:
            from .mjview import MjView

            self._mj_view = MjView(self)
        return self._mj_view

    def fall_back_to_tiny(self, why: str) -> None:
        """The renderer chosen could not start (MuJoCo could not build or open the scene):
        TinyRenderer from now on, the reason in the report and a warning."""
        self._warn("runner-renderer", f"{self.renderer} renderer unavailable ({why}); TinyRenderer instead", None)
        self.renderer, self.renderer_note = "tiny", why

    def close(self) -> None:
        if self._mj_view is not None:
            self._mj_view.close()
            self._mj_view = None
        if self.soft is not None:
            self.soft.close()
        if pb.isConnected(self.cid):
            with egl.quiet_stdout() if self.renderer == "egl" else contextlib.nullcontext():
                pb.disconnect(self.cid)
