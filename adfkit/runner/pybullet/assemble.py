"""How the PyBullet world builds the scene (the Assembly half of PyBulletWorld): bodies as
maximal-coordinate bodies or multibody links (articulation.py), the joints that close loops as
constraints plus per-step spring forces (joints.py, spring_forces.py), collision filters, soft bodies, volumes,
ghosts, actuators, sensors and cameras, and the floor."""

from __future__ import annotations

import math

import numpy as np
import pybullet as pb

from ...model.semantics import JointKind, joint_kind, pose_or_identity
from .. import ambf_bodies
from ..cameras import build_cameras
from ..collisions import HULL_OVERLAP, collision_masks, hull_overlaps, one_hull
from ..names import Registry, merge_namespace
from ..plan import (
    ALL_GROUPS,
    SPRING_KINDS,
    holds_nothing,
    is_hole,
    joint_ends,
    key_of,
    loaded_so_far,
    not_played,
    played_actuators,
    played_sensors,
    resolve_parent,
    warn_unheld,
)
from ..resistance import RayState, ResistanceParams
from ..rotations import invert, matrix_to_pq, pose_to_matrix
from ..springs import spring_alone
from . import articulation, egl
from .bodies import SimBody, body_gravity, make_sim_body, refresh_inertia, set_dynamics
from .cone_limits import ConeLimits
from .damping import LinkDamping
from .ghost_pass import GhostPass
from .interact import SimActuator, SimGhost, SimSensor
from .joints import ConstraintRefused, com_frames, make_constraint, spring_joint
from .limit_rows import LimitRows
from .loops import close_loops
from .meshfiles import pybullet_reads_quietly
from .shapes import collision_parts, create_collision, create_visual
from .spring_forces import SpringSet
from .vehicles import PyBulletVehicles
from .volumes import build_volumes


class Assembly:
    def _build(self) -> None:
        models = self.scene.all_models()
        records = []
        not_played(self, models, "pybullet")
        self._model_bodies: dict[int, list[SimBody]] = {}
        for m in models:
            ns = m.namespace or ""
            mine = []
            for b in m.bodies:
                sb = make_sim_body(merge_namespace(ns, b.namespace) + b.identifier, b, m)
                sb.cid = self.cid
                sb.gravity = body_gravity(b, m, self.gravity)
                sb._parts = collision_parts(
                    m, b, sb.ref_in_body, b.scale or 1.0, sb.static, self.diagnostics, self.soft is not None
                )
                if sb._parts is None:
                    self.skipped.append(sb.key)
                    continue
                sb._parts_frame = sb.ref_in_body  # the frame the parts are placed in
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
                ends = joint_ends(self.registry, local, ns, j)
                if None in ends:
                    self._warn("runner-joint-body", f"{j.identifier}: parent or child body not found; skipped", j)
                    continue
                if ends[0] is ends[1]:  # AMBF keeps it, and it moves nothing (World.inert_joints)
                    self._warn("runner-joint-body", f"{j.identifier}: joins a body to itself; nothing made", j)
                    continue
                if holds_nothing(ends[0].body, j):  # AMBF keeps it, and it holds nothing (World.inert_joints)
                    warn_unheld(self, j, ends[0].key)
                    continue
                records.append((j, kind, ends[0], ends[1]))
        self.joints_made = [(j, parent, child) for j, _kind, parent, child in records]
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
            with pybullet_reads_quietly([(sb.model, sb.body) for sb in [root] + [r[3] for r in recs]]):
                art = articulation.build(root, recs, self._shapes_for, self.dt, self.cid, self_coll)
            self.articulations.append(art)
            self.joint_names.extend(art.joint_names)
            for sb in [root] + [r[3] for r in recs]:
                set_dynamics(sb, self._ambf_dt)
            if self._ambf_dt is not None:  # AMBF's bodies' speed (ambf_bodies.py); PyBullet keeps one
                # for the whole multibody, and given with a link's mass or inertia it sets them on the base
                speed = ambf_bodies.JOINT_SPEED_TURN / self._ambf_dt
                pb.changeDynamics(art.uid, -1, maxJointVelocity=speed, physicsClientId=self.cid)
        self._collision_filters(records)
        if self.soft is not None:
            self.soft.build(models)
        springs = []
        for _root, recs in trees:  # limited springs in a multibody: their limits are its joints'
            for j, kind, parent, child in recs:
                if kind in SPRING_KINDS:
                    sj = spring_alone(spring_joint(j, kind, parent, child, *com_frames(j, parent, child)))
                    springs += [sj] if sj is not None else []
        self.fixed_frames = []  # (joint name, parent, child, joint frame rotation in each)
        for j, kind, parent, child in leftover:
            fa, fb = com_frames(j, parent, child)
            self.joint_names.append(j.identifier)
            sj = None
            if kind in SPRING_KINDS:
                sj = spring_joint(j, kind, parent, child, fa, fb)
                springs.append(sj)
                sj.free_pivot = self.opt.springs == "ambf" and ConeLimits.frees_pivot(sj, leftover)
                if sj.free_pivot:  # Bullet's pivot rows played by the springs (cone_limits.py)
                    self.constraints.append((j.identifier, None, parent, child, fa[:3, 3], fb[:3, 3], None))
                    continue
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
                made = make_constraint(self.cid, kind_c, parent, child, fa, fb, 1e5, self._ambf_dt is not None)
            except ConstraintRefused as exc:
                self._warn("runner-constraint", f"{j.identifier}: {exc}; the joint is left out", j)
                self.joints_made = [r for r in self.joints_made if r[0] is not j]
                continue
            for c, pa, pbv, axis in made:
                self.constraints.append((j.identifier, c, parent, child, pa, pbv, axis))
            if kind_c is JointKind.FIXED:  # its relative orientation is held too (joint_angle_error)
                self.fixed_frames.append((j.identifier, parent, child, fa[:3, :3], fb[:3, :3]))
        self.loop_gaps = close_loops(self)  # by multibody: its loops' pivot gaps before
        self.springs = SpringSet(springs, self.cid, self.gravity, self.opt.springs)
        self.link_damping = LinkDamping(self)
        self.limit_rows = LimitRows(self)
        build_volumes(self, models)
        known = None
        for m in models:
            known = loaded_so_far(known, self._model_bodies.get(id(m), []))
            self._build_ghosts(m)
            self._build_actuators(m, known)
            self._build_sensors(m, known)
        self.vehicles = PyBulletVehicles(self, models)
        self.cameras = build_cameras(self)
        self._floor_z = self._floor()
        self.ground_z = None
        if self.scene.world is None and self.scene.environment is None:
            if self.opt.ground:
                self._add_ground()
            else:  # --no-ground: nothing to fall through
                self._floor_z = -math.inf
        self.initial_positions = {sb.key: np.array(sb.com_position()) for sb in self.bodies}
        self._lookup = {(sb.uid, link): sb for sb in self.bodies for link in sb.links}
        self._hull_overlaps()
        self._dynamic_lookup = {k: sb for k, sb in self._lookup.items() if not sb.static}
        self._pairs_epoch = 0  # counts changes of collision pairs and grasps (interact.py's distance answers)
        self._parting: list = []  # (uid, link, body): a released grasp, collisions back once apart
        self._gravity_overrides = self._group_gravity_overrides()
        self._friction_ghosts = [g for g in self.ghosts if g.friction]
        # the ghosts that act on what is inside them each control step (Options.ghosts)
        self._acting_ghosts = self.ghosts if self.opt.ghosts == "ambf" else self._friction_ghosts
        self._manifold_place, self._manifold_made = None, {}  # interact._manifold_points' last pass
        self._ghost_pass = GhostPass(self)  # where that pass is run (ghost_pass.py)
        if self._ambf_dt is not None and self.soft is None:  # AMBF's bodies turn by their inertia from the start
            refresh_inertia(self.cid)

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

    def _hull_overlaps(self) -> None:
        """Bodies whose shapes overlap at the start where one is a concave mesh PyBullet takes the
        hull of (a dynamic one; collisions.hull_overlaps)."""
        pb.performCollisionDetection(physicsClientId=self.cid)
        pairs: dict = {}
        for c in pb.getContactPoints(physicsClientId=self.cid):
            if c[8] > -HULL_OVERLAP:
                continue
            a, b = self._lookup.get((c[1], c[3])), self._lookup.get((c[2], c[4]))
            if a is None or b is None:
                continue
            hull = [_hulled(s) for s in (a, b)]
            if any(hull):
                pair = (a, b) if hull[0] and (not hull[1] or b.static) else (b, a)
                pairs[pair] = max(pairs.get(pair, 0.0), -float(c[8]))
        hull_overlaps(self, pairs, "PyBullet")

    def _add_ground(self) -> None:
        """A model played without a world gets what AMBF's worlds give it: a floor, here a
        static plane 1 mm below the lowest point of every body with a collision shape (a body
        without one has no extent: its bounds are its origin's, wherever the file puts it)."""
        lows = [
            pb.getAABB(sb.uid, sb.link, physicsClientId=self.cid)[0][2]
            for sb in self.bodies
            if sb.uid is not None and not self._shapeless(sb)
        ]
        if self.soft is not None and self.soft.items:
            lows.append(self.soft.lowest_z())
        if not lows:
            return
        self.ground_z = min(lows) - 1e-3 if self.opt.ground_z is None else self.opt.ground_z
        if self.soft is None:
            shape = pb.createCollisionShape(pb.GEOM_PLANE, physicsClientId=self.cid)
            vis = egl.plane_visual(self.cid, (0, 0, 1), 0.0) if self.renderer == "egl" else -1
            self.ground_uid = pb.createMultiBody(0.0, shape, vis, [0.0, 0.0, self.ground_z], physicsClientId=self.cid)
        else:  # soft bodies stop centimetres above a static plane: a thick slab instead
            self.ground_uid = self.soft.ground_slab(self.ground_z)
        # the floor stands in for a world's, which has no collision groups: it meets every body,
        # whatever its groups (Bullet's static default met only the bodies of the second group)
        pb.setCollisionFilterGroupMask(self.ground_uid, -1, ALL_GROUPS, ALL_GROUPS, physicsClientId=self.cid)
        self._floor_z = self.ground_z

    def _shapes_for(self, sb: SimBody, frame_in_body) -> tuple[int, int]:
        b, m = sb.body, sb.model
        # a multibody link's frame is its joint's frame (articulation.build sets ref_in_body to
        # it before asking): its parts are made again in that frame, unless Options.link_shapes
        # keeps them made in the COM frame (the link's shapes then sit as if its frame were that)
        made_in = sb.ref_in_body if self.opt.link_shapes == "com" else getattr(sb, "_parts_frame", None)
        if frame_in_body is not made_in or sb._parts is None:
            sb._parts = collision_parts(
                m, b, frame_in_body, b.scale or 1.0, sb.static, self.diagnostics, self.soft is not None
            )
            sb._parts_frame = frame_in_body
        ambf = self.opt.bodies == "ambf"  # AMBF's compound shapes (shapes.create_collision)
        col = create_collision(sb._parts, self.cid, b, self.diagnostics, ambf) if sb._parts is not None else -1
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
        with pybullet_reads_quietly([(sb.model, sb.body)]):
            sb.uid = pb.createMultiBody(
                sb.mass, col, vis, pos, orn, useMaximalCoordinates=True, physicsClientId=self.cid
            )
        sb.link = -1
        set_dynamics(sb, self._ambf_dt)

    def _collision_filters(self, records) -> None:
        masks = collision_masks(self, [sb.body for sb in self.bodies])
        for sb in self.bodies:
            mask = masks[id(sb.body)]
            pb.setCollisionFilterGroupMask(sb.uid, sb.link, mask, mask, physicsClientId=self.cid)
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

    def _build_ghosts(self, m) -> None:
        ns = m.namespace or ""
        for gh in m.ghost_objects:
            parts = collision_parts(m, gh, np.eye(4), gh.scale or 1.0, True, self.diagnostics)
            if parts is None or (not parts.types and parts.plane is None):
                self._warn("runner-ghost", f"{gh.identifier}: no collision geometry; ghost skipped", gh)
                continue
            parent = resolve_parent(self, gh.parent, ns, gh) if gh.parent else None
            loc = pose_to_matrix(pose_or_identity(gh.location))
            rel = invert(parent.com_in_body) @ loc if parent is not None else loc
            col = create_collision(parts, self.cid, gh, self.diagnostics)
            vis = (
                create_visual(m, gh, np.eye(4), gh.scale or 1.0, self.cid, self.diagnostics) if self.opt.visuals else -1
            )
            vis = self._plane_visual(parts, col, vis)
            world = (self._frame(parent) @ rel) if parent is not None else rel
            pos, orn = matrix_to_pq(world)
            with pybullet_reads_quietly([(m, gh)]):
                uid = pb.createMultiBody(0, col, vis, pos, orn, useMaximalCoordinates=True, physicsClientId=self.cid)
            pb.setCollisionFilterGroupMask(uid, -1, 0, 0, physicsClientId=self.cid)
            friction = is_hole(gh, self.opt)
            key = self.registry.add(key_of(ns, gh), None)
            moves = parent is not None and not parent.static
            self.ghosts.append(
                SimGhost(key, gh, uid, parent, rel, friction, pq_in_parent=matrix_to_pq(rel), moves=moves, parts=parts)
            )

    def _build_actuators(self, m, known) -> None:
        for g in played_actuators(self, m, known=known):
            self.actuators.append(SimActuator(g.key, g.actuator, g.parent, g.location))

    def _build_sensors(self, m, known) -> None:
        for r in played_sensors(self, m, known=known, resistance=self.opt.bodies == "ambf"):
            s = SimSensor(r.key, r.sensor, r.parent, r.location, r.starts, r.ends)
            if r.resistance:  # AMBF's resistance forces (resistance.py)
                s.resist, s.states = ResistanceParams.of(r.sensor), [RayState() for _ in r.starts]
            self.sensors.append(s)

    def _floor(self) -> float:
        zs = []
        for sb in self.bodies:
            if sb.static:
                if sb._parts is not None and sb._parts.plane is not None:
                    zs.append(sb.body_world_matrix[2, 3] + sb._parts.plane[1])
                else:
                    zs.append(pb.getAABB(sb.uid, sb.link, physicsClientId=self.cid)[0][2])
        return min(zs) if zs else -math.inf


def _hulled(sb) -> bool:
    """PyBullet collides the body's concave mesh as convex hulls (a dynamic body not played as
    convex parts; a static one is its exact triangles unless beside soft bodies: shapes.py)."""
    parts = sb._parts
    exact = parts is not None and any(kw.get("flags") == pb.GEOM_FORCE_CONCAVE_TRIMESH for kw in parts.kwargs)
    return parts is not None and bool(parts.types) and not exact and one_hull(sb)
