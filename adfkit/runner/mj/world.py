"""MjWorld: an ADF scene played in MuJoCo behind the same public API as SimWorld (PyBullet):
step, run, body(name) with world_matrix/com_position/state/force/torque, grasp, overlapping,
place_ghosts, ghosts/actuators/sensors/cameras/articulations, joint_state/reset_joints,
report, constraint_error, close. The model comes from build.py; docs/mujoco.md says
what is approximated.
"""

from __future__ import annotations

import math
import time

import mujoco
import numpy as np

from ...diagnostics import Diagnostic, warning
from ...model.semantics import (
    DEFAULT_ACTUATOR_MAX_IMPULSE,
    DEFAULT_GRAVITY,
    DEFAULT_JOINT_MAX_MOTOR_IMPULSE,
    JointKind,
    effective_mass,
    inertial_offset,
)
from ...model.tree import ONE_DOF
from .. import stability
from ..names import Registry
from ..neutral import EngineNeutral
from ..rotations import invert, matrix_to_quat, pose_matrix, pose_to_matrix
from .build import EXCLUDE_SPARE, build_plan, compile_spec
from .objects import MjActuator, MjArticulation, MjBody, MjGhost, MjSensor

DRIVE_BANDWIDTH = 0.25  # ω·dt of the joint position servos (explicit stiffness is stable below 2)
SOLVER_TOLERANCE = 1e-6
WAKE_FORCE = 1e-12  # N
# MuJoCo's 1e-3 puts a mm-scale chain to sleep 2 mm short of its rest pose, 3e-4 0.6 mm short;
# at 1e-4 the suturing thread lying on the phantom never sleeps (its contacts jitter above it)
SLEEP_TOLERANCE = 3e-4
SPRING_LIMIT = 0.25  # k ≤ SPRING_LIMIT·M_ii/dt²: the PyBullet runner's clamp for explicit springs


class MjWorld(EngineNeutral):
    engine = "mujoco"

    def __init__(self, scene, options=None, gui: bool = False, sleep: bool = True) -> None:
        """``sleep``: MuJoCo's island sleeping (resting trees are not integrated until a contact,
        a force or a constraint with an awake tree wakes them; driven trees never sleep)."""
        from ..options import Options

        if gui:
            raise ValueError("the MuJoCo engine plays headless only (use --engine pybullet for --gui)")
        self.scene = scene
        self.opt = options or Options()
        self.diagnostics: list[Diagnostic] = []
        self.gui = False
        self.dt = 1.0 / self.opt.physics_hz
        w = scene.world
        g = self.opt.gravity or (tuple(w.gravity) if w is not None and w.gravity is not None else DEFAULT_GRAVITY)
        self.gravity = np.array(g, dtype=float)
        self.registry = Registry()
        self.steps = 0
        self.sim_time = 0.0
        self.wall_time = 0.0
        self.watch = stability.Watch()
        self.engine_warnings: list[str] = []  # MuJoCo's other warnings, with their time
        self.volumes: list[dict] = []  # (volumes are played by the PyBullet world only)
        self.not_played: list[dict] = []  # every part of the scene not played, with why
        stability.install_mujoco_handler()
        self.skipped: list[str] = []
        self.sleep = sleep and hasattr(mujoco.mjtEnableBit, "mjENBL_SLEEP")  # MuJoCo 4's island sleeping
        self._render = None
        self._vel6 = np.zeros(6)
        self._runtime_excludes: set[int] = set()
        self.camera_problem = ""
        self._build()

    def _warn(self, rule, msg, obj, hint="") -> None:
        self.diagnostics.append(warning(rule, msg, getattr(obj, "source", None), hint or None))

    # ---- building ------------------------------------------------------------------------
    def _build(self) -> None:
        plan = build_plan(self)
        spec = plan.spec
        spec.option.timestep = self.dt
        spec.option.gravity = self.gravity
        spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
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
        self.model = compile_spec(self, spec)
        self.model.opt.jacobian = jacobian_for(self.model)
        self.data = mujoco.MjData(self.model)
        mujoco.mj_forward(self.model, self.data)
        self.ground_z = None
        if ground and plan.bodies:
            self.ground_z = self._lowest_point() - 1e-3
            spec.worldbody.add_geom(
                type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 1], pos=[0, 0, self.ground_z], name="adfkit:ground"
            )
            self.model = compile_spec(self, spec)
            self.data = mujoco.MjData(self.model)
            mujoco.mj_forward(self.model, self.data)
        self._plan = plan
        m, d = self.model, self.data
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
            sb.has_collision = bool(
                np.any((m.geom_bodyid == bid) & ((m.geom_contype != 0) | (m.geom_conaffinity != 0)))
            )
            if bid > 0 and m.body_weldid[bid] == 0:
                sb.mass = 0.0  # welded to the world: static whatever the file says
            self.registry.items[bp.key] = sb
            self.bodies.append(sb)
            by_plan[id(bp)] = sb
        self._by_plan = by_plan
        self.joint_names = [j.identifier for j, *_ in plan.joints] + [j.identifier for j, *_ in plan.loops]
        self._build_articulations(plan, by_plan)
        self._tune_gains(plan)
        self._gravity_overrides()
        self._base_xfrc = np.array(d.xfrc_applied)
        self.ghosts = []
        for gp in plan.ghosts:
            ids = np.array([mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n) for n in gp.geoms])
            parent = by_plan.get(id(gp.parent)) if gp.parent is not None else None
            self.ghosts.append(MjGhost(gp.key, gp.ghost, parent, ids, gp.friction, pose_in_parent=gp.location))
            self.registry.items[gp.key] = None
        self._friction_ghosts = [g for g in self.ghosts if g.friction]
        self._friction_geoms = np.array([gid for g in self._friction_ghosts for gid in g.geoms], dtype=int)
        self._friction_owner = [g for g in self._friction_ghosts for _ in g.geoms]
        self.actuators = []
        for key, a, parent, weld in plan.actuators:
            imp = a.max_impulse if a.max_impulse is not None else DEFAULT_ACTUATOR_MAX_IMPULSE
            from ...model.semantics import pose_or_identity

            self.actuators.append(
                MjActuator(
                    key,
                    a,
                    by_plan[id(parent)],
                    mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, weld),
                    pose_to_matrix(pose_or_identity(a.location)),
                    imp / self.dt,
                )
            )
        from ...model.semantics import DEFAULT_SENSOR_RANGE, pose_or_identity

        self.sensors = []
        for key, sn, parent in plan.sensors:
            rng = sn.range if sn.range is not None else DEFAULT_SENSOR_RANGE
            starts = np.array([r.offset or (0, 0, 0) for r in sn.array], dtype=float)
            dirs = np.array([r.direction or (1, 0, 0) for r in sn.array], dtype=float)
            self.sensors.append(
                MjSensor(
                    key,
                    sn,
                    by_plan[id(parent)],
                    pose_to_matrix(pose_or_identity(sn.location)),
                    starts,
                    starts + dirs * rng,
                )
            )
        # rays see collision geoms (groups 0 and 3), not visuals (1) or ghosts (4)
        self._ray_groups = np.array([1, 0, 1, 1, 0, 0], dtype=np.uint8)
        self._ray_hit = np.zeros(1, dtype=np.int32)
        self._body_of_id = {sb.id: sb for sb in self.bodies}
        self.constraints = [
            (j.identifier, None, by_plan[id(p)], by_plan[id(c)], pa, pb_, None) for j, kind, p, c, pa, pb_ in plan.loops
        ]
        self.springs_count = plan.springs
        # the bodies the hole ghosts and grasps look for: dynamic ones with collision geoms
        dyn = [i for i, sb in enumerate(self.bodies) if not sb.static and sb.has_collision]
        self._cand_bodies = [self.bodies[i] for i in dyn]
        gids = [g for g in range(m.ngeom) if (m.geom_contype[g] or m.geom_conaffinity[g])]
        body_of = {sb.id: sb for sb in self._cand_bodies}
        self._cand_geoms = np.array([g for g in gids if m.geom_bodyid[g] in body_of], dtype=int)
        self._cand_geom_body = [body_of[m.geom_bodyid[g]] for g in self._cand_geoms]
        self._cand_rbound = np.array(m.geom_rbound[self._cand_geoms])
        self._cand_geom_bodyid = np.array(m.geom_bodyid[self._cand_geoms], dtype=int)
        self._all_cand = np.arange(len(self._cand_geoms))
        self._geom_xpos, self._body_awake = d.geom_xpos, d.body_awake
        self._AWAKE = int(mujoco.mjtSleepState.mjS_AWAKE)
        self._fg_rbound = np.array(m.geom_rbound[self._friction_geoms])[:, None]
        self._geom_label = np.full(m.ngeom, -1, dtype=np.int32)
        for i, sb in enumerate(self.bodies):
            if sb.id > 0:
                self._geom_label[m.geom_bodyid == sb.id] = i
        self._floor_z = self._floor()
        self.cameras = cams.finish(self)
        self.initial_positions = {sb.key: np.array(sb.com_position()) for sb in self.bodies}
        plan.tmp.cleanup()

    def _lowest_point(self) -> float:
        m = self.model
        z = [self._geom_bottom(g) for g in range(m.ngeom) if m.geom_group[g] != 4 and m.geom_rbound[g] > 0]
        return min(z) if z else 0.0

    def _geom_bottom(self, g: int) -> float:
        """Lowest z of a geom's world bounding box (its local AABB turned into the world)."""
        m, d = self.model, self.data
        r = d.geom_xmat[g].reshape(3, 3)
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
                aid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, f"motor:{jn[0]}") if jn else -1
                recs.append((j, kind, by_plan[id(p)], by_plan[id(c)], jid, aid))
                stack.extend(reversed(kids.get(id(c), [])))
            if any(r[1] in ONE_DOF for r in recs):
                art = MjArticulation(self, by_plan[id(bp)], [r for r in recs])
                art.records = [r[:4] for r in recs]
                by_plan[id(bp)].articulation = art
                for r in recs:
                    r[3].articulation = art
                self.articulations.append(art)
                art.drive()

    def _tune_gains(self, plan) -> None:
        """Servo gains from each joint's effective inertia (the diagonal of M at the initial
        pose): kp = (DRIVE_BANDWIDTH/dt)²·M_ii, critically damped (implicit in velocity), force
        capped at AMBF's max motor impulse / dt; spring stiffness clamped like the PyBullet runner's."""
        m, dt = self.model, self.dt
        diag = np.array(m.dof_M0)  # the diagonal of M at qpos0, armature included
        w = DRIVE_BANDWIDTH / dt
        by_joint = {}
        for art in self.articulations:
            for (j, _kind, _p, _c), vadr, act in zip(art.records, art.vadr, art.act):
                if act < 0:
                    continue
                mii = diag[vadr]
                kp = w * w * mii
                kv = 2.0 * w * mii
                m.actuator_gainprm[act, 0] = kp
                m.actuator_biasprm[act, 1] = -kp
                m.actuator_biasprm[act, 2] = -kv
                imp = j.max_motor_impulse if j.max_motor_impulse is not None else DEFAULT_JOINT_MAX_MOTOR_IMPULSE
                m.actuator_forcelimited[act] = 1
                m.actuator_forcerange[act] = (-imp / dt, imp / dt)
                by_joint[id(j)] = True
        clamped = []
        for j in range(m.njnt):
            if m.jnt_stiffness[j] > 0:
                v = m.jnt_dofadr[j]
                cap = SPRING_LIMIT * diag[v] / dt**2
                if m.jnt_stiffness[j] > cap:
                    clamped.append(m.joint(j).name)
                    m.jnt_stiffness[j] = cap
        if clamped:
            self._warn(
                "runner-spring-clamp",
                f"{len(clamped)} spring axes stiffer than an explicit {dt * 1e3:g} ms "
                f"step keeps stable were softened to 0.25·M/dt² (e.g. {clamped[0]})",
                None,
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
        for g in range(m.ngeom):
            b = m.geom_bodyid[g]
            if m.body_weldid[b] != 0 or not (m.geom_contype[g] or m.geom_conaffinity[g]):
                continue
            zs.append(d.geom_xpos[g][2] if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE else self._geom_bottom(g))
        return min(zs) if zs else -math.inf

    # ---- queries -------------------------------------------------------------------------
    def body(self, text: str) -> MjBody:
        key, hit = self.registry.find(text)
        if key is None or not isinstance(hit, MjBody):
            raise KeyError(f"no unique body matches {text!r}")
        return hit

    def joint_state(self, art, idxs) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities of joints ``idxs`` (record indices) of an articulation."""
        d = self.data
        return (np.array([d.qpos[art.qadr[i]] for i in idxs]), np.array([d.qvel[art.vadr[i]] for i in idxs]))

    def reset_joints(self, art, idxs, positions, velocities=None) -> None:
        """Put joints ``idxs`` at ``positions`` (and ``velocities``, default 0) now; poses follow."""
        d = self.data
        vel = velocities if velocities is not None else [0.0] * len(idxs)
        for i, p, v in zip(idxs, positions, vel):
            d.qpos[art.qadr[i]] = p
            d.qvel[art.vadr[i]] = v
        mujoco.mj_kinematics(self.model, d)
        mujoco.mj_comPos(self.model, d)

    # ---- stepping ------------------------------------------------------------------------
    def _sense(self, s: MjSensor) -> None:
        m, d = self.model, self.data
        t = s.parent.world_matrix() @ s.location
        a = s.starts @ t[:3, :3].T + t[:3, 3]
        b = s.ends @ t[:3, :3].T + t[:3, 3]
        s.sensed = []
        for p, q in zip(a, b):
            x = mujoco.mj_ray(m, d, p, q - p, self._ray_groups, 1, s.parent.id, self._ray_hit)
            if 0.0 <= x <= 1.0 and self._ray_hit[0] >= 0:
                sb = self._body_of_id.get(int(m.geom_bodyid[self._ray_hit[0]]))
                if sb is not None and sb not in s.sensed:
                    s.sensed.append(sb)

    def control(self) -> None:
        """Per-control-step forces and senses: proximity sensors' rays, hole ghosts' viscous friction.
        One bounding-sphere test of every hole-ghost geom against every candidate geom, then
        MuJoCo's exact distance only for the pairs that pass."""
        for s in self.sensors:
            self._sense(s)
        fg = self._friction_geoms
        cg = self._cand_geoms
        if not len(fg) or not len(cg):
            return
        m, d = self.model, self.data
        gx = self._geom_xpos  # views into MjData/MjModel, made once (attribute access costs)
        if self.sleep:  # a sleeping body does not move: no friction to apply
            idx = np.flatnonzero(self._body_awake[self._cand_geom_bodyid] == self._AWAKE)
        else:
            idx = self._all_cand
        diff = gx[cg[idx]][None, :, :] - self._fg_pos(gx)
        reach = (self._cand_rbound[idx][None, :] + self._fg_rbound) ** 2
        near = np.einsum("ijk,ijk->ij", diff, diff) <= reach
        if not near.any():
            for g in self._friction_ghosts:
                g.overlapping = []
            return
        cg = cg[idx]
        body_of = [self._cand_geom_body[i] for i in idx]
        hits: dict[int, list] = {}
        for i, k in zip(*np.nonzero(near)):
            g = self._friction_owner[i]
            sb = body_of[k]
            lst = hits.setdefault(id(g), [])
            if sb in lst or sb is g.parent:
                continue
            if mujoco.mj_geomDistance(m, d, int(fg[i]), int(cg[k]), 0.0, None) <= 0.0:
                lst.append(sb)
        for g in self._friction_ghosts:
            g.overlapping = hits.get(id(g), [])
            if g.overlapping:
                self._viscous(g, g.overlapping)

    def _fg_pos(self, gx) -> np.ndarray:
        return gx[self._friction_geoms][:, None, :]

    def step(self, n: int = 1) -> None:
        """Advance n control steps (n·control_substeps physics steps of 1/physics_hz)."""
        t0 = time.perf_counter()
        sub = self.opt.control_substeps
        m, d = self.model, self.data
        base = self._base_xfrc
        for k in range(n):
            self.control()
            mujoco.mj_step(m, d, sub)
            d.xfrc_applied[:] = base
            if stability.mujoco_pending():  # a warning: NaN and a state reset, a singular inertia...
                self.sim_time = (self.steps + (k + 1) * sub) * self.dt
                stability.drain_mujoco(self, self.watch)
        self.steps += n * sub
        self.sim_time = self.steps * self.dt
        self.wall_time += time.perf_counter() - t0

    # ---- ghosts and grasps ----------------------------------------------------------------
    def place_ghosts(self) -> None:
        """Ghost geoms ride on their parent bodies: nothing to move."""

    def overlapping(self, g: MjGhost) -> list[MjBody]:
        """The dynamic bodies inside ghost ``g`` now (bounding spheres first, then MuJoCo's
        exact geom distance); also kept in ``g.overlapping``."""
        m, d = self.model, self.data
        cg = self._cand_geoms
        found = []
        if len(cg):
            gx = d.geom_xpos
            near = np.zeros(len(cg), dtype=bool)
            for gid in g.geoms:
                dist = np.linalg.norm(gx[cg] - gx[gid], axis=1)
                near |= dist <= m.geom_rbound[cg] + m.geom_rbound[gid]
            seen = set()
            for k in np.nonzero(near)[0]:
                sb = self._cand_geom_body[k]
                if id(sb) in seen or sb is g.parent:
                    continue
                for gid in g.geoms:
                    if mujoco.mj_geomDistance(m, d, int(gid), int(cg[k]), 0.0, None) <= 0.0:
                        found.append(sb)
                        seen.add(id(sb))
                        break
        g.overlapping = found
        return found

    def _viscous(self, g: MjGhost, found) -> None:
        """F = -K·(v_body - v_phantom) on every body inside a hole ghost (held for a control
        step as the exact exp(-K·t/m) decay, as in the PyBullet runner)."""
        k = self.opt.hole_friction
        cdt = self.dt * self.opt.control_substeps
        v_ref = self._com_velocity(g.parent) if g.parent is not None and not g.parent.static else 0.0
        xf = self.data.xfrc_applied
        for sb in found:
            v = self._com_velocity(sb) - v_ref
            xf[sb.id, :3] -= sb.mass * v * (1.0 - math.exp(-k * cdt / sb.mass)) / cdt

    def _com_velocity(self, sb: MjBody) -> np.ndarray:
        v = self._vel6
        mujoco.mj_objectVelocity(self.model, self.data, mujoco.mjtObj.mjOBJ_BODY, sb.id, v, 0)
        return v[3:].copy()

    def actuate(self, actuator: MjActuator, target: MjBody) -> None:
        """Weld ``target`` to the actuator's parent at their current relative pose; the jaws'
        own geoms stop colliding with it meanwhile (they would push the held body out)."""
        self.release(actuator)
        m, d = self.model, self.data
        e = actuator.eq
        a, b = actuator.parent.id, target.id
        ta = pose_matrix(d.xpos[a], _xyzw(d.xquat[a]))
        tb = pose_matrix(d.xpos[b], _xyzw(d.xquat[b]))
        rel = invert(ta) @ tb
        q = matrix_to_quat(rel[:3, :3])
        m.eq_obj2id[e] = b
        m.eq_data[e, :3] = 0.0  # anchor: body2's origin
        m.eq_data[e, 3:6] = rel[:3, 3]
        m.eq_data[e, 6:10] = (q[3], q[0], q[1], q[2])
        m.eq_data[e, 10] = 1.0
        d.eq_active[e] = 1
        self.wake(target)
        actuator.target = target
        art = actuator.parent.articulation
        links = [r[3] for r in art.records] + [art.root] if art is not None else [actuator.parent]
        actuator.constraint = []
        for sb in links:
            for gid in np.nonzero(m.geom_bodyid == sb.id)[0]:
                if m.geom_contype[gid] or m.geom_conaffinity[gid]:
                    actuator.constraint.append((int(gid), int(m.geom_contype[gid]), int(m.geom_conaffinity[gid])))
        for gid, _, _ in actuator.constraint:  # only the links near the held body matter; all is simplest
            if np.linalg.norm(d.geom_xpos[gid] - d.xpos[b]) < 0.05:
                m.geom_contype[gid] = m.geom_conaffinity[gid] = 0

    def ghost_pose(self, g: MjGhost) -> np.ndarray:
        """World pose (4x4) of a ghost's frame, following its parent."""
        loc = g.pose_in_parent if g.pose_in_parent is not None else np.eye(4)
        return g.parent.world_matrix() @ loc if g.parent is not None else np.array(loc)

    def set_collision(self, a: MjBody, b: MjBody, enabled: bool) -> None:
        """Let two bodies collide or pass through each other, as SimWorld.set_collision: an
        excluded body pair written into one of the spare slots the build reserved."""
        m = self.model
        lo, hi = sorted((int(a.id), int(b.id)))
        sig = (lo << 16) + hi
        sigs = np.array(m.exclude_signature[: m.nexclude])
        if enabled:
            if sig not in self._runtime_excludes:
                return
            self._runtime_excludes.discard(sig)
            sigs[np.flatnonzero(sigs == sig)[0]] = 0
        else:
            if sig in sigs or lo == hi:
                return
            free = np.flatnonzero(sigs == 0)
            if not free.size:
                self._warn(
                    "runner-collision-pairs",
                    f"more than {EXCLUDE_SPARE} body pairs turned off at run time; {a.key} and {b.key} keep colliding",
                    None,
                )
                return
            sigs[free[0]] = sig
            self._runtime_excludes.add(sig)
        m.exclude_signature[: m.nexclude] = np.sort(sigs)

    def move_base(self, sb: MjBody, body_world: np.ndarray) -> None:
        """Put a body without joints (a PSM's base, as its setup joints would) at a new world
        pose of its ADF body frame; what hangs from it follows."""
        m, d = self.model, self.data
        parent = int(m.body_parentid[sb.id])
        tp = np.eye(4)
        tp[:3, :3], tp[:3, 3] = d.xmat[parent].reshape(3, 3), d.xpos[parent]
        local = invert(tp) @ body_world @ sb.link_in_body
        q = matrix_to_quat(local[:3, :3])
        m.body_pos[sb.id] = local[:3, 3]
        m.body_quat[sb.id] = (q[3], q[0], q[1], q[2])
        # with island sleeping on, MuJoCo computes the frames of bodies welded to the world once;
        # one forward pass without it puts them (and what hangs from them) where they now are
        flags = m.opt.enableflags
        m.opt.enableflags = flags & ~int(getattr(mujoco.mjtEnableBit, "mjENBL_SLEEP", 0))
        try:
            mujoco.mj_forward(m, d)
        finally:
            m.opt.enableflags = flags

    def wake(self, sb: MjBody) -> None:
        """Wake the sleeping tree of ``sb`` (MuJoCo wakes a tree a force is applied to: a
        1e-12 N force at the COM for one control step does it and nothing else)."""
        if self.sleep and sb.id > 0:
            self.data.xfrc_applied[sb.id, 2] += WAKE_FORCE

    def release(self, actuator: MjActuator) -> None:
        if actuator.target is not None:
            self.wake(actuator.target)
            self.data.eq_active[actuator.eq] = 0
            for gid, ct, ca in actuator.constraint or ():
                self.model.geom_contype[gid], self.model.geom_conaffinity[gid] = ct, ca
        actuator.target, actuator.constraint = None, None

    # ---- measures -----------------------------------------------------------------------
    def contacts(self, sb: MjBody) -> list:
        """[(other MjBody, normal force N, world point)] of the contacts ``sb`` has after the last step."""
        m, d = self.model, self.data
        out = []
        f = np.zeros(6)
        for i in range(d.ncon):
            c = d.contact[i]
            b1, b2 = int(m.geom_bodyid[c.geom1]), int(m.geom_bodyid[c.geom2])
            if sb.id not in (b1, b2):
                continue
            other = self._body_of_id.get(b2 if b1 == sb.id else b1)
            if other is None or other is sb:
                continue
            mujoco.mj_contactForce(m, d, i, f)
            out.append((other, abs(float(f[0])), tuple(float(v) for v in c.pos)))
        return out

    def constraint_error(self) -> float:
        """Largest distance, m, between the two pivots of a loop-closing joint (tree joints are exact)."""
        worst = 0.0
        d = self.data
        for _, _, parent, child, pa, pbv, _ in self.constraints:
            xa = d.xmat[parent.id].reshape(3, 3) @ pa + d.xpos[parent.id]
            xb = d.xmat[child.id].reshape(3, 3) @ pbv + d.xpos[child.id]
            worst = max(worst, float(np.linalg.norm(xa - xb)))
        return worst

    def report(self) -> dict:
        fell, fast, nan, shapeless = [], [], [], []
        for sb in self.bodies:
            if sb.static:
                continue
            p, _, v, _ = sb.state()
            if not np.all(np.isfinite(p)) or not np.all(np.isfinite(v)):
                nan.append(sb.key)
                continue
            if not sb.has_collision:
                shapeless.append(sb.key)
                continue
            if p[2] < self._floor_z - 0.1:
                fell.append(sb.key)
            if np.linalg.norm(v) > 10.0:
                fast.append(sb.key)
        return {
            "engine": "mujoco",
            "awake_trees": int(getattr(self.data, "ntree_awake", self.model.ntree)),
            "trees": int(self.model.ntree),
            "bodies": len(self.bodies),
            "skipped_bodies": self.skipped,
            "joints": len(self.joint_names),
            "multibodies": len(self.articulations),
            "constraints": len(self.constraints),
            "spring_joints": self.springs_count,
            "ghosts": len(self.ghosts),
            "sensors": len(self.sensors),
            "actuators": len(self.actuators),
            "cameras": [c.name for c in self.cameras],
            "renderer": "mujoco",
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
            "soft_bodies": [],  # not played by this engine (a runner-soft-body warning names each)
            **self.watch.report(),
            "engine_warnings": self.engine_warnings,
            "volumes": self.volumes,
            "not_played": self.not_played,
        }

    def _renderer(self):
        """MuJoCo's offscreen renderer, made on the first picture (render.CameraUnavailable
        when no headless OpenGL opens; the reason stays in ``camera_problem``)."""
        if self._render is None:
            from .render import CameraUnavailable, _Renderer

            if self.camera_problem:
                raise CameraUnavailable(self.camera_problem)
            try:
                self._render = _Renderer(self)
            except CameraUnavailable as e:
                self.camera_problem = str(e)
                raise
        return self._render

    def close(self) -> None:
        if self._render is not None:
            self._render.close()
            self._render = None


def _xyzw(wxyz) -> np.ndarray:
    return np.array([wxyz[1], wxyz[2], wxyz[3], wxyz[0]])


def jacobian_for(model) -> int:
    """Dense or sparse constraint algebra, from how full the joint-space inertia matrix is.

    A 40-element thread is a 120-dof chain: its mass matrix and contact Jacobians are dense,
    and dense algebra is faster for it than MuJoCo's sparse default above 60 dofs (the bundled
    suturing scene: 139 dofs, the matrix 79 % filled). Many shallow trees (free bodies joined
    by p2p joints) leave it nearly empty, and dense algebra there grows with the square of the
    size: a chain of 300 p2p-joined bodies steps 19x faster sparse (bench/scaling.py)."""
    full = model.nv * (model.nv + 1) // 2
    if model.nv < 60 or model.nM >= 0.5 * full:
        return mujoco.mjtJacobian.mjJAC_DENSE
    return mujoco.mjtJacobian.mjJAC_SPARSE
