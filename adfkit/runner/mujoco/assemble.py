"""How the MuJoCo world builds the scene (the Assembly half of MujocoWorld): the MjSpec from
build.py compiled, the engine's bodies, articulations driven by joint equalities (drives.py),
ghosts, actuators, sensors, cameras and the floor."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from ...model.semantics import JointKind, ReversedJoint, effective_mass, inertial_offset
from ...model.tree import ONE_DOF
from ..collisions import HULL_OVERLAP, hull_overlaps, one_hull
from ..plan import ALL_GROUPS
from ..rotations import pose_to_matrix
from .build import GHOST_GROUP, build_plan
from .contacts import bullet_pairs, ground_pairs, set_contacts
from .cross_joints import file_anchors
from .damping import BodyDamping
from .drives import DriveLimits, drive_limit
from .integrator import integrator_for
from .limits import ambf_limits
from .objects import MjActuator, MjArticulation, MjBody, MjGhost, MjSensor
from .resist import MujocoResistance
from .spec import compile_spec
from .spring_rows import SpringRows, capped_joints, spring_dofs
from .start import six_dof_start
from .vehicles import MujocoVehicles, weld_wheels

SOLVER_TOLERANCE = 1e-6
WAKE_FORCE = 1e-12  # N
# MuJoCo's 1e-3 puts a mm-scale chain to sleep 2 mm short of its rest pose, 3e-4 0.6 mm short;
# at 1e-4 the suturing thread lying on the phantom never sleeps (its contacts jitter above it)
SLEEP_TOLERANCE = 3e-4
SPRING_LIMIT = 0.25  # k ≤ SPRING_LIMIT·M_ii/dt²: the PyBullet runner's clamp for explicit springs


class Assembly:
    def _build(self) -> None:
        plan = build_plan(self)
        weld_wheels(self, plan)  # AMBF's vehicles' wheel bodies are static (vehicles.py)
        spec = plan.spec
        spec.option.timestep = self.dt
        spec.option.gravity = self.gravity
        # implicit-fast for rigid scenes; MuJoCo 4 integrates a flex's elasticity implicitly only
        # in its discrete integrator (implicit/implicitfast refuse a flex: "no longer integrated")
        spec.option.integrator = (
            mujoco.mjtIntegrator.mjINT_DISCRETE if spec.flexes else mujoco.mjtIntegrator.mjINT_IMPLICITFAST
        )
        # Newton stops at a 1e-6 relative improvement (MuJoCo's 1e-8 costs 1.8x the time here);
        # dense or sparse algebra: jacobian_for, once the model is compiled
        spec.option.tolerance = SOLVER_TOLERANCE
        # elliptic friction cones (Coulomb's, as Bullet's friction): Newton converges in fewer
        # iterations on the thread lying on the phantom than with the pyramidal default, so the
        # settling seconds play 1.4x faster (bench/speed.py) and the thread sleeps as early
        spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
        if self.sleep:
            spec.option.enableflags |= mujoco.mjtEnableBit.mjENBL_SLEEP
            spec.option.sleep_tolerance = SLEEP_TOLERANCE
        if self.opt.solver_iterations:
            spec.option.iterations = max(self.opt.solver_iterations, 1)
        from .render import prepare_cameras

        cams = prepare_cameras(self, plan)
        ground = self.opt.ground and self.scene.world is None and self.scene.environment is None
        self._plan = plan  # (compile_spec finds the ADF body of what MuJoCo refuses in it)
        if self.opt.bodies == "ambf":
            # AMBF never applies a hinge's or a slider's `damping` (afJoint::applyDamping is not
            # called); the MJCF writer keeps it, as MJCF means it
            for _j, kind, _p, _c, names in plan.joints:
                if kind in ONE_DOF:
                    for name in names:
                        spec.joint(name).damping = [0.0, 0.0, 0.0]
        ghost_gravity = self.opt.ghosts == "ambf" and bool(plan.ghosts)
        if ghost_gravity:
            # AMBF's ghosts switch a body's gravity off: by MuJoCo's gravity compensation, which a
            # resting tree sleeps under (a force in xfrc_applied wakes it every control step); the
            # model counts the bodies that may have it when compiled, so every body is one, then 0
            for b in spec.bodies[1:]:
                b.gravcomp = 1.0
        self._compile(spec, ghost_gravity)
        bullet = self.opt.bodies == "ambf" and self.soft is None  # Bullet's frictions (contacts.py)
        own = bullet_pairs(spec, self.model, self.model.geom_group == GHOST_GROUP) if bullet else []
        self.ground_z = None
        if ground and (plan.bodies or (self.soft is not None and self.soft.items)):
            self.ground_z = self._lowest_point() - 1e-3 if self.opt.ground_z is None else self.opt.ground_z
            # the floor stands in for a world's, which has no collision groups: every bit, so
            # that it meets every body whatever its groups (the default bit met group 0's only)
            floor = spec.worldbody.add_geom(
                type=mujoco.mjtGeom.mjGEOM_PLANE,
                size=[0, 0, 1],
                pos=[0, 0, self.ground_z],
                name="adfkit:ground",
                contype=ALL_GROUPS,
                conaffinity=ALL_GROUPS,
            )
            if bullet:
                ground_pairs(spec, floor, self.model, ALL_GROUPS)
        if self.ground_z is not None or own:  # the floor, the frictions and pairs compiled in
            for g, fr, prio in own:
                g.friction, g.priority = fr, prio
            self._compile(spec, ghost_gravity)
        self._plan = plan
        if self.soft is not None:
            self.soft.bind(spec)
        m, d = self.model, self.data
        set_contacts(m, self.dt, ranked=bool(own))  # rigid, frictions combined as Bullet does (contacts.py)
        self.bodies: list[MjBody] = []
        by_plan = {}
        for bp in plan.bodies:
            bid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, bp.mjname)
            mass = effective_mass(bp.body)
            sb = MjBody(
                bp.key,
                bp.body,
                bp.model,
                max(mass, 0.0),
                pose_to_matrix(inertial_offset(bp.body)),
                pose_to_matrix(bp.link.frame_in_body),
                bid,
                self,
            )
            sb.has_collision = bool(np.any((m.geom_bodyid == bid) & _colliding(m)))
            if bid > 0 and m.body_weldid[bid] == 0:
                sb.mass = 0.0  # welded to the world: static whatever the file says
            self.registry.items[bp.key] = sb
            self.bodies.append(sb)
            by_plan[id(bp)] = sb
        for vs, name in plan.volumes:  # static iso-surface bodies (build._volumes)
            key = self.registry.add(vs.key, None)
            bid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)
            sb = MjBody(key, vs.body, vs.model, 0.0, np.eye(4), np.eye(4), bid, self)
            sb.surface = vs.surface  # what a viewer draws of it (its own frame)
            self.registry.items[key] = sb
            self.bodies.append(sb)
            self.volumes.append(vs.report)
        self._by_plan = by_plan
        self.joint_names = [j.identifier for j, *_ in plan.joints] + [j.identifier for j, *_ in plan.loops]
        made = [(j, by_plan[id(p)], by_plan[id(c)]) for j, _k, p, c, *_ in plan.joints + plan.loops]
        # as the file has them: a joint the tree took reversed (ReversedJoint) listed by its file joint
        self.joints_made = [(j.joint, c, p) if isinstance(j, ReversedJoint) else (j, p, c) for j, p, c in made]
        self._build_articulations(plan, by_plan)
        # AMBF's springs (Options.springs "ambf"): Bullet's spring rows at every physics step where
        # a damper acts, but on the springs Bullet caps (spring_rows.py)
        capped = capped_joints(m, self.data, plan.joints, self.dt)  # (the file's gains, before the clamp)
        self._drive_limits_and_springs()
        self.spring_rows = SpringRows(self, plan.joints, capped) if self.opt.springs == "ambf" else None
        self._spring_dofs = spring_dofs(m, plan.joints)  # a limited spring's free axis (spring_effort)
        if self.spring_rows is not None and not np.any(self.spring_rows.c):
            self.spring_rows = None
        if self.opt.bodies == "ambf" and six_dof_start(m, self.data, plan.joints):
            mujoco.mj_forward(m, self.data)
        if self.opt.bodies == "ambf":
            ambf_limits(m, plan.joints, self.dt, capped)
        self._gravity_overrides()
        self._base_xfrc = np.array(d.xfrc_applied)
        # every writer of xfrc_applied beyond this base (damping, hole ghosts, wake, a body's
        # force or torque) sets the flag; step() puts the base back after the physics only then
        self._xfrc_dirty = False
        self.ghosts = []
        for gp in plan.ghosts:
            ids = np.array([mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n) for n in gp.geoms])
            parent = by_plan.get(id(gp.parent)) if gp.parent is not None else None
            self.ghosts.append(MjGhost(gp.key, gp.ghost, parent, ids, gp.friction, pose_in_parent=gp.location))
            self.registry.items[gp.key] = None
        self._friction_ghosts = [g for g in self.ghosts if g.friction]
        self._collider_key, self._collider_made = None, {}  # ghosts._collider_points' last pass
        self._friction_geoms = np.array([gid for g in self._friction_ghosts for gid in g.geoms], dtype=int)
        self._friction_owner = [g for g in self._friction_ghosts for _ in g.geoms]
        self.actuators = [
            MjActuator(
                g.key,
                g.actuator,
                by_plan[id(g.parent)],
                mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, weld),
                g.location,
            )
            for g, weld in plan.actuators
        ]
        self.sensors = [
            MjSensor(r.key, r.sensor, by_plan[id(r.parent)], r.location, r.starts, r.ends) for r in plan.sensors
        ]
        # rays see collision geoms (groups 0 and 3), not visuals (1) or ghosts (4)
        self._ray_groups = np.array([1, 0, 1, 1, 0, 0], dtype=np.uint8)
        self._ray_hit = np.zeros(1, dtype=np.int32)
        self._body_of_id = {sb.id: sb for sb in self.bodies}
        self.vehicles = MujocoVehicles(self)
        self.resistance = MujocoResistance(self)  # AMBF's resistance sensors' forces (resist.py)
        file_anchors(m, plan.loops)
        self.constraints = [
            (j.identifier, None, by_plan[id(p)], by_plan[id(c)], pa, pb_, None) for j, kind, p, c, pa, pb_ in plan.loops
        ]
        self.springs_count = plan.springs
        # the bodies the hole ghosts and grasps look for: dynamic ones with collision geoms
        dyn = [i for i, sb in enumerate(self.bodies) if not sb.static and sb.has_collision]
        self._cand_bodies = [self.bodies[i] for i in dyn]
        gids = np.nonzero(_colliding(m))[0].tolist()
        body_of = {sb.id: sb for sb in self._cand_bodies}
        self._cand_geoms = np.array([g for g in gids if m.geom_bodyid[g] in body_of], dtype=int)
        self._cand_geom_body = [body_of[m.geom_bodyid[g]] for g in self._cand_geoms]
        self._cand_rbound = np.array(m.geom_rbound[self._cand_geoms])
        self._cand_geom_bodyid = np.array(m.geom_bodyid[self._cand_geoms], dtype=int)
        self._all_cand = np.arange(len(self._cand_geoms))
        self._geom_xpos, self._body_awake = d.geom_xpos, d.body_awake
        self._AWAKE = int(mujoco.mjtSleepState.mjS_AWAKE)
        self._fg_rbound = np.array(m.geom_rbound[self._friction_geoms])[:, None]
        self._fg_key, self._awake_key, self._awake = None, None, None  # world.py's control() caches
        self._fg_centre, self._fg_radius, self._overlaps_cleared = np.zeros(3), 0.0, False
        self._fg_bodyid, self._fg_asleep = np.array(m.geom_bodyid[self._friction_geoms], dtype=int), False
        g = np.asarray(self.gravity, dtype=float)
        self._up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
        self._geom_label = np.full(m.ngeom, -1, dtype=np.int32)
        for i, sb in enumerate(self.bodies):
            if sb.id > 0:
                self._geom_label[m.geom_bodyid == sb.id] = i
        self._floor_z = self._floor()
        self.cameras = cams.finish(self)
        self.damping = BodyDamping(self)
        self.initial_positions = {sb.key: np.array(sb.com_position()) for sb in self.bodies}
        self._hull_overlaps()
        plan.tmp.cleanup()

    def _hull_overlaps(self) -> None:
        """Bodies whose shapes overlap at the start where one is a mesh's hull (collisions.hull_overlaps)."""
        m, d = self.model, self.data
        by_id = {sb.id: sb for sb in self.bodies}
        pairs: dict = {}
        for c in d.contact[: d.ncon]:
            if c.dist > -HULL_OVERLAP:
                continue
            g = (c.geom1, c.geom2)
            a, b = (by_id.get(int(m.geom_bodyid[x])) for x in g)
            if a is None or b is None:
                continue
            mesh = [m.geom_type[x] == mujoco.mjtGeom.mjGEOM_MESH and one_hull(s) for x, s in zip(g, (a, b))]
            if not any(mesh):
                continue
            hull, other = (a, b) if mesh[0] and (not mesh[1] or b.static) else (b, a)
            pairs[(hull, other)] = max(pairs.get((hull, other), 0.0), -float(c.dist))
        hull_overlaps(self, pairs, "MuJoCo")

    def _compile(self, spec, ghost_gravity: bool) -> None:
        """``spec`` compiled into the world's model and data: the gravity compensation the ghosts
        may switch on back to 0 (see above), the algebra and the integrator chosen for the model
        (jacobian_for, integrator_for), the poses worked out."""
        self.model = compile_spec(self, spec)
        if ghost_gravity:
            self.model.body_gravcomp[:] = 0.0
        self.model.opt.jacobian = jacobian_for(self.model)
        self.model.opt.integrator = integrator_for(self.model)
        self.data = mujoco.MjData(self.model)
        mujoco.mj_forward(self.model, self.data)

    def _lowest_point(self) -> float:
        m = self.model
        z = [self._geom_bottom(g) for g in range(m.ngeom) if m.geom_group[g] != 4 and m.geom_rbound[g] > 0]
        if m.nflexvert:  # soft bodies' nodes, less their radius
            z.append(float(np.min(self.data.flexvert_xpos[:, 2] - np.repeat(m.flex_radius, m.flex_vertnum))))
        return min(z) if z else 0.0

    def _geom_bottom(self, g: int) -> float:
        """Lowest z of a geom: a mesh's lowest vertex (as PyBullet's bounds of its hull, so that
        a model played alone gets its floor at one height in both engines), else of its world
        bounding box (its local AABB turned into the world)."""
        m, d = self.model, self.data
        r = d.geom_xmat[g].reshape(3, 3)
        mesh = m.geom_dataid[g] if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH else -1
        if mesh >= 0:
            first = m.mesh_vertadr[mesh]
            verts = m.mesh_vert[first : first + m.mesh_vertnum[mesh]]
            return float(np.min(verts @ r[2]) + d.geom_xpos[g][2])
        c, h = m.geom_aabb[g, :3], m.geom_aabb[g, 3:]
        return float((r @ c + d.geom_xpos[g])[2] - np.abs(r[2]) @ h)

    def _build_articulations(self, plan, by_plan) -> None:
        """Roots of one-DOF trees and their fixed/revolute/prismatic descendants, as SimWorld groups them."""
        m = self.model
        kids: dict[int, list] = {}
        for j, kind, p, c, jn in plan.joints:
            kids.setdefault(id(p), []).append((j, kind, p, c, jn))
        has_dof = set()
        for _j, kind, p, _c, _jn in plan.joints:
            if kind in ONE_DOF:
                has_dof.add(id(p))
        self.articulations = []
        child_ids = {id(c) for _, k, _, c, _ in plan.joints if k in ONE_DOF or k is JointKind.FIXED}
        for bp in plan.bodies:
            if id(bp) in child_ids or id(bp) not in has_dof:
                continue
            recs, stack = [], list(reversed(kids.get(id(bp), [])))
            while stack:
                j, kind, p, c, jn = stack.pop()
                if kind not in ONE_DOF and kind is not JointKind.FIXED:
                    continue
                if kind is JointKind.FIXED and effective_mass(c.body) == 0.0:
                    continue
                jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, jn[0]) if jn else -1
                eid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, f"drive:{jn[0]}") if jn else -1
                recs.append((j, kind, by_plan[id(p)], by_plan[id(c)], jid, eid))
                stack.extend(reversed(kids.get(id(c), [])))
            if any(r[1] in ONE_DOF for r in recs):
                art = MjArticulation(self, by_plan[id(bp)], [r for r in recs])
                art.records = [r[:4] for r in recs]
                by_plan[id(bp)].articulation = art
                for r in recs:
                    r[3].articulation = art
                self.articulations.append(art)
                art.retarget()
                art.free()
        # a drive no articulation holds (its tree hangs from a body fixed to a static one) is never
        # commanded: off, as AMBF's motors are until a command turns them on
        owned = {int(e) for a in self.articulations for e in a.eqs if e >= 0}
        for e in range(m.neq):
            if e not in owned and (mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_EQUALITY, e) or "").startswith("drive:"):
                self.data.eq_active[e] = 0

    def _drive_limits_and_springs(self) -> None:
        """The drives' force limits (drives.DriveLimits); spring stiffness clamped like the
        PyBullet runner's explicit springs (k ≤ SPRING_LIMIT·M_ii/dt², M at the initial pose)."""
        m, dt = self.model, self.dt
        drives = []
        for art in self.articulations:
            for (j, _kind, _p, _c), e in zip(art.records, art.eqs):
                if e >= 0:
                    drives.append((int(e), j.identifier, drive_limit(j)))
        self.drive_limits = DriveLimits(self, drives)
        diag = np.array(m.dof_M0)  # the diagonal of M at qpos0, armature included
        clamped = []
        for j in range(m.njnt):
            if m.jnt_stiffness[j] > 0:
                v = m.jnt_dofadr[j]
                cap = SPRING_LIMIT * diag[v] / dt**2
                if m.jnt_stiffness[j] > cap:
                    clamped.append(m.joint(j).name)
                    m.jnt_stiffness[j] = cap
        if clamped:
            joint = next((j for j, *_r, names in self._plan.joints if clamped[0] in names), None)
            self._warn(
                "runner-spring-clamp",
                f"{len(clamped)} spring axes stiffer than an explicit {dt * 1e3:g} ms "
                f"step keeps stable were softened to 0.25·M/dt² (e.g. {clamped[0]})",
                joint,
            )

    def _gravity_overrides(self) -> None:
        d = self.data
        for sb in self.bodies:
            if sb.static:
                continue
            g = sb.body.gravity if sb.body.mass is not None and sb.body.gravity is not None else sb.model.gravity
            if g is not None and not np.allclose(g, self.gravity):
                sb.gravity = np.array(g, float)
                d.xfrc_applied[sb.id][:3] += self.model.body_mass[sb.id] * (sb.gravity - self.gravity)

    def _floor(self) -> float:
        m, d = self.model, self.data
        zs = []
        colliding = _colliding(m)
        for g in range(m.ngeom):
            b = m.geom_bodyid[g]
            if m.body_weldid[b] != 0 or not colliding[g]:
                continue
            zs.append(d.geom_xpos[g][2] if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE else self._geom_bottom(g))
        return min(zs) if zs else -math.inf


def _xyzw(wxyz) -> np.ndarray:
    return np.array([wxyz[1], wxyz[2], wxyz[3], wxyz[0]])


#: the share of the joint-space inertia matrix filled above which the algebra is dense
DENSE_FILL = 0.95


def jacobian_for(model) -> int:
    """Dense or sparse constraint algebra, from how full the joint-space inertia matrix is.

    Dense below 60 dofs (MuJoCo's own rule) and for one serial chain and little else (the matrix
    at least DENSE_FILL full), sparse otherwise. Measured with MuJoCo 4.0 on this 2-core box: a
    120-hinge chain lying on the ground (1,300 contact rows, the matrix 100 % full) steps 2.4x
    faster dense; the bundled suturing scene (139 dofs, 79 % full: the thread's 123-dof chain
    beside the two arms) plays a four-pair suture 1.38x faster sparse (physics 83.0 -> 60.2 s,
    seed 5), the corpus suturing set (175 dofs, 51 %) settles its thread 1.15x faster sparse;
    with no contacts a chain steps as fast either way. Many shallow trees (free bodies joined by
    p2p joints) leave the matrix nearly empty, and dense algebra there grows with the square of
    the size: a chain of 300 p2p-joined bodies steps 19x faster sparse (bench/scaling.py)."""
    full = model.nv * (model.nv + 1) // 2
    if model.nv < 60 or model.nM >= DENSE_FILL * full:
        return mujoco.mjtJacobian.mjJAC_DENSE
    return mujoco.mjtJacobian.mjJAC_SPARSE


def _colliding(m) -> np.ndarray:
    """Which geoms are collision shapes: bits to collide with, and not a ghost's (build.GHOST_CONTYPE)."""
    return ((m.geom_contype != 0) | (m.geom_conaffinity != 0)) & (m.geom_group != GHOST_GROUP)
