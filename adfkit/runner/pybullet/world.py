"""PyBulletWorld: an ADF scene (adfkit.model.Scene) built in PyBullet and stepped.

Bodies joined by revolute/prismatic trees become multibodies (exact joints, native limits and
position motors); every other body is a maximal-coordinate rigid body and every other joint a
createConstraint plus per-step forces (joints.py, spring_forces.py). docs/runner.md says why. The world is three
parts: building (assemble.py), what happens between steps (interact.py) and, here, stepping,
state and the report; what is engine-neutral is in runner/world.py and runner/plan.py.
"""

from __future__ import annotations

import contextlib
import time

import numpy as np
import pybullet as pb

from ..joint_commands import row_mass
from ..options import Options
from ..rotations import matrix_to_pq, pose_matrix, quat_to_matrix
from ..soft import in_scene as soft_in_scene
from ..soft import soft_health
from ..stability import CHECK_EVERY_S
from ..world import World
from . import bullet_globals, egl, held
from . import stability as pb_stability
from .articulation import AXIS, ROTARY, TREE_KINDS
from .assemble import Assembly
from .bodies import SimBody
from .broadphase_margin import MARGIN as BROADPHASE_MARGIN
from .cameras import choose_renderer, render
from .chain import ChainModel
from .ghost_steps import GhostSteps
from .interact import Interaction
from .limit_chains import LimitChains
from .resist import PyBulletResistance
from .softbodies import SoftBodies, enable_deformable_world
from .solver_info import AMBF_SOLVER_INFO
from .state import WorldState


class PyBulletWorld(Assembly, Interaction, WorldState, World):
    engine = "pybullet"
    body_type = SimBody
    chain_model = ChainModel  # AMBF's solver step on a multibody (chain.py)

    def __init__(self, scene, options: Options | None = None, gui: bool = False, mirror=None) -> None:
        """``mirror``: a callable making the MuJoCo mirror that draws the cameras with
        ``renderer="mujoco"`` (runner.open_world passes it); without one that renderer is not chosen."""
        self._setup(scene, options, gui)
        self.mirror = mirror
        self.cid = pb.connect(pb.GUI if gui else pb.DIRECT)
        held.forget(self.cid)  # a closed world's client id comes back: nothing of its is held
        self.soft = SoftBodies(self) if soft_in_scene(scene) else None  # soft bodies: a deformable world
        if self.soft is not None:
            enable_deformable_world(self.cid)
        has_cameras = bool(scene.world is not None and scene.world.cameras) or any(
            m.cameras for m in scene.all_models()
        )
        self._mj_view = None
        self.renderer, self.renderer_note = choose_renderer(
            self.opt.renderer, self.cid, has_cameras, self.soft is not None, gui, mirror is not None
        )
        w = scene.world
        self.max_substeps = w.max_iterations if w is not None and w.max_iterations else 10
        pb.setGravity(*self.gravity, physicsClientId=self.cid)
        # PyBullet: each stepSimulation advances fixedTimeStep, split into numSubSteps internal steps
        params = dict(fixedTimeStep=self.dt * self.opt.control_substeps, numSubSteps=self.opt.control_substeps)
        if self.opt.solver_iterations:
            params["numSolverIterations"] = self.opt.solver_iterations
        # AABBs grow by it and contact points are made within (a size-scaled share of) it; a
        # millimetre-sized scene plays ~1.4x faster at 0.001 (bench/run_suturing.py). One value for
        # the whole process: put in force again before each step (bullet_globals.py)
        self.contact_threshold = params["contactBreakingThreshold"] = bullet_globals.threshold(self.opt)
        # the broadphase's margin, one per process too (broadphase_margin.py): each box grown a
        # little, so that a creeping body leaves the broadphase's tree alone
        self.broadphase_margin = BROADPHASE_MARGIN
        if self.opt.bodies == "ambf":
            params.update(AMBF_SOLVER_INFO)  # AMBF's contact solver settings (solver_info.py)
        pb.setPhysicsEngineParameter(physicsClientId=self.cid, **params)
        # self.constraints: (joint name, constraint id, parent, child, pivot a, pivot b, slide axis in a | None)
        self._next_stability_check = 0.0
        # the broadphase's overlapping pairs: PyBullet's bodies keep them sorted (PyBullet's
        # setting). AMBF's world leaves them in the order they were found, and the solver takes the
        # contacts in that order: sorted, a stack resting on the floor creeps sideways under 10
        # iterations (solver_info.py), so AMBF's bodies get AMBF's order. A restored snapshot
        # replays no less closely unsorted (state.py)
        sorted_pairs = 0 if self.opt.bodies == "ambf" else 1
        pb.setPhysicsEngineParameter(
            enableFileCaching=1, deterministicOverlappingPairs=sorted_pairs, physicsClientId=self.cid
        )
        self._ambf_dt = self.dt if self.opt.bodies == "ambf" else None  # AMBF's bodies (ambf_bodies.py)
        self._build()
        # AMBF's springs (Options.springs): explicit, at every physics step; PyBullet then steps one
        # physics step a call and the control step's other forces are applied again at each (held.py)
        self._springs_every_step = self.opt.springs == "ambf" and bool(self.springs.joints)
        # AMBF's ghosts on free bodies at every physics step (ghost_steps.py): stepped the same way
        acting = self.opt.ghosts == "ambf" and self._acting_ghosts and self.opt.control_substeps > 1
        self._ghost_steps = GhostSteps(self) if acting else None
        if self._ghost_steps is not None and not self._ghost_steps.free:
            self._ghost_steps = None
        self.resistance = PyBulletResistance(self, [s for s in self.sensors if s.resist is not None])
        self._after_steps = [a for a in (self.vehicles, self.resistance) if a]
        # free multibodies' stops through AMBF's solver step, at every physics step (limit_chains.py)
        self.limit_chains = LimitChains(self)
        self._stops = self.limit_chains.before_step if self.limit_chains else None
        each = self._springs_every_step or self._ghost_steps is not None or bool(self._after_steps)
        self._each_step = each or self._stops is not None
        if self._each_step:
            pb.setPhysicsEngineParameter(fixedTimeStep=self.dt, numSubSteps=1, physicsClientId=self.cid)
            held.record(self.cid)

    def move_base(self, sb: SimBody, body_world: np.ndarray) -> None:
        """Put the root of a multibody (e.g. a PSM's base, as its setup joints would) at a new
        world pose of its ADF body frame; its links follow."""
        pos, orn = matrix_to_pq(body_world @ sb.com_in_body)
        pb.resetBasePositionAndOrientation(sb.uid, pos, orn, physicsClientId=self.cid)

    def _frame(self, sb: SimBody) -> np.ndarray:
        """World pose of the PyBullet frame of a body."""
        p, q, _, _ = sb.state(velocity=False)
        return pose_matrix(p, q)

    def joint_state(self, art, idxs) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities of joints ``idxs`` (record indices) of an articulation."""
        st = pb.getJointStates(art.uid, list(idxs), physicsClientId=self.cid)
        return np.array([s[0] for s in st]), np.array([s[1] for s in st])

    def reset_joints(self, art, idxs, positions, velocities=None) -> None:
        """Put joints ``idxs`` of an articulation at ``positions`` (and ``velocities``, default 0) now."""
        vel = velocities if velocities is not None else [0.0] * len(idxs)
        for i, p, v in zip(idxs, positions, vel):
            pb.resetJointState(art.uid, i, float(p), float(v), physicsClientId=self.cid)

    def joint_motor(self, art, index: int, velocity: float, max_force: float, gain: float = 1.0) -> None:
        """Joint ``index`` of ``art`` driven at ``velocity`` by a motor of at most ``max_force``
        (runner/joint_commands.py: AMBF's velocity motor). With ``gain`` under 1 the motor takes
        the joint that share of the way from the velocity the step would leave it at toward
        ``velocity`` (PyBullet's velocity gain: solved with the step's other rows)."""
        pb.setJointMotorControl2(
            art.uid,
            index,
            pb.VELOCITY_CONTROL,
            targetVelocity=velocity,
            force=max_force,
            velocityGain=gain,
            physicsClientId=self.cid,
        )

    def joint_mobility(self, art, idxs) -> np.ndarray:
        """(M⁻¹) over joints ``idxs`` (revolute or prismatic record indices) of an articulation, now,
        M its joint-space mass matrix: the velocity change of those joints per unit of impulse on
        each (rad/s per N·m·s, m/s per N·s), the articulation's other joints free."""
        cid = self.cid
        dofs = [n for n, k in enumerate(art.kinds) if k in TREE_KINDS]
        q = [s[0] for s in pb.getJointStates(art.uid, dofs, physicsClientId=cid)]
        mass = np.array(pb.calculateMassMatrix(art.uid, q, physicsClientId=cid))
        at = [len(mass) - len(dofs) + dofs.index(i) for i in idxs]  # a floating base's six come first
        return np.linalg.pinv(mass)[np.ix_(at, at)]  # pinv: a massless link leaves M singular

    def joint_row_mass(self, art, index: int) -> float:
        """The mass AMBF's motor row along joint ``index`` sees between the joint's two bodies
        (joint_commands.row_mass; a static parent adds nothing)."""
        cid = self.cid
        kind = art.kinds[index]
        parent = pb.getJointInfo(art.uid, index, physicsClientId=cid)[16]
        link = pb.getLinkState(art.uid, index, computeForwardKinematics=True, physicsClientId=cid)
        axis = quat_to_matrix(link[5])[:, 2 if kind in ROTARY else AXIS.get(kind, 2)]
        ends = []
        for n in (parent, index):
            mass, _f, diag = pb.getDynamicsInfo(art.uid, n, physicsClientId=cid)[:3]
            if mass <= 0.0:
                continue
            if n < 0:
                orn = pb.getBasePositionAndOrientation(art.uid, physicsClientId=cid)[1]
            else:
                orn = pb.getLinkState(art.uid, n, computeForwardKinematics=True, physicsClientId=cid)[1]
            ends.append((mass, diag, quat_to_matrix(orn)))
        return row_mass(axis, ends, kind not in ROTARY)

    def joint_effort(self, art, index: int, effort: float) -> None:
        """Joint ``index`` of ``art`` pushed by ``effort`` (N·m or N) for the next control step, its
        motor off (runner/joint_commands.py: AMBF's commandEffort)."""
        pb.setJointMotorControl2(art.uid, index, pb.VELOCITY_CONTROL, force=0.0, physicsClientId=self.cid)
        pb.setJointMotorControl2(art.uid, index, pb.TORQUE_CONTROL, force=effort, physicsClientId=self.cid)

    def set_body_velocity(self, sb, linear, angular) -> bool:
        """Set a free body's (or a multibody base's) COM velocity, world frame; False for a link."""
        if sb.link >= 0:
            return False
        pb.resetBaseVelocity(sb.uid, list(linear), list(angular), physicsClientId=self.cid)
        return True

    def control(self) -> None:
        """Per-control-step forces: gravity overrides, springs, multibody links' damping (damping.py),
        joints past their limits pushed back (limit_rows.py),
        ghosts' viscous friction, sensors.
        PyBullet's calls take their arguments by position here (this runs every control step)."""
        cdt = self.dt * self.opt.control_substeps
        cid = self.cid
        base_pose, link_states, push = pb.getBasePositionAndOrientation, pb.getLinkStates, held.push
        poses = {}  # (uid, link) -> (position, quaternion) read this control step: the ghosts use them
        for uid, links, _sbs, forces in self._gravity_overrides:
            coms = []
            states = link_states(uid, [max(k, 0) for k in links], 0, 1, cid) if links != [-1] else [None]
            for k, s in zip(links, states):  # getLinkStates: computeLinkVelocity 0, computeForwardKinematics 1
                pq = base_pose(uid, cid) if k < 0 else (s[0], s[1])
                poses[(uid, k)] = pq
                coms.append(pq[0])
            for k, f, at in zip(links, forces, coms):
                push(uid, k, f, at, cid)
        self.springs.apply(self.dt if self._springs_every_step else cdt)
        self.link_damping.apply()
        self.limit_rows.apply()
        poses.update(self.springs.pq)
        self._reset_now = {}  # (uid, link) -> a state with the velocity the ghosts set this control step
        self._update_ghosts(poses)
        for s in self.sensors:
            self._sense(s)
        if self._parting:
            self.parting()

    @property
    def physics_steps_a_call(self) -> int:
        """The physics steps each stepSimulation splits into: ``control_substeps`` where a control
        step is one call (the default), 1 where the world steps them one by one (AMBF's springs,
        ghosts or stops). PyBullet reports a contact's normal force as the last physics step's
        impulse over the call's whole time, a 1/``physics_steps_a_call`` share of it (a 1 kg box
        at rest reads 2.45 N at 4 substeps): ``contacts`` multiplies it back to newtons."""
        return 1 if self._each_step else self.opt.control_substeps

    def _state_now(self, sb) -> tuple:
        """SimBody.state() of ``sb`` as this control step read it (the springs' free bodies, the damped
        links; a velocity the ghosts set since: _reset_now), else read now (the ghosts ask)."""
        key = (sb.uid, sb.link)
        s = self._reset_now.get(key) or self.springs.last_state(key) or self.link_damping.read.get(key)
        return s if s is not None else sb.state()

    def step(self, n: int = 1) -> None:
        """Advance n control steps (n·control_substeps physics steps of 1/physics_hz)."""
        t0 = time.perf_counter()
        sub = self.opt.control_substeps
        # AMBF's vehicles and resistance sensors act after each physics step (vehicles.py, resist.py)
        veh = self._after_steps or None
        stops = self._stops
        bullet_globals.use(
            self.contact_threshold, self.cid, self.broadphase_margin
        )  # another world may have set its own
        for _ in range(n):
            self.control()
            if veh is not None:
                for v in veh:
                    v.push()
            if stops is not None:
                stops()
            pb.stepSimulation(physicsClientId=self.cid)
            if veh is not None:
                for v in veh:
                    v.update(self.dt)
            fine = self._ghost_steps is not None and self._ghost_steps.fine
            if self._each_step:
                for _ in range(sub - 1):  # the springs, ghosts, vehicles again at each physics step, the rest held
                    held.replay(self.cid)
                    if fine:
                        self._ghost_steps.between()
                    if self._springs_every_step:
                        self.springs.apply(self.dt)
                    if veh is not None:
                        for v in veh:
                            v.push()
                    if stops is not None:
                        stops()
                    pb.stepSimulation(physicsClientId=self.cid)
                    if veh is not None:
                        for v in veh:
                            v.update(self.dt)
                held.clear(self.cid)
        self.steps += n * sub
        self.sim_time = self.steps * self.dt
        if self.sim_time >= self._next_stability_check:  # NaN or a flung body, caught as it happens
            self._next_stability_check = self.sim_time + CHECK_EVERY_S
            pb_stability.check_pybullet(self, self.watch)
        self.wall_time += time.perf_counter() - t0

    def _frames_of(self, bodies: list) -> np.ndarray:
        """World poses (n, 4, 4) of the PyBullet frames of ``bodies``, each body read once."""
        index: dict[int, int] = {}
        for sb in bodies:
            index.setdefault(id(sb), len(index))
        unique = {id(sb): sb for sb in bodies}
        states = [unique[k].state(velocity=False) for k in index]
        frames = np.zeros((len(states), 4, 4))
        frames[:, :3, :3] = quat_to_matrix(np.array([s[1] for s in states]))  # all at once
        frames[:, :3, 3] = [s[0] for s in states]
        frames[:, 3, 3] = 1.0
        return frames[[index[id(sb)] for sb in bodies]]

    def constraint_error(self) -> float:
        """Largest distance, m, between the two pivots of any joint (constraints and springs
        with a locked linear range); multibody joints are exact, and a joint between two static
        bodies holds nothing (AMBF's constraint between them does nothing either)."""
        rows = [r for r in self.constraints if not (r[2].static and r[3].static)]
        if not rows:
            return 0.0
        key = tuple(id(r) for r in rows)
        if getattr(self, "_error_rows", (None,))[0] != key:  # the pivots as arrays, once
            pa = np.array([r[4] for r in rows], dtype=float)
            pbv = np.array([r[5] for r in rows], dtype=float)
            slide = [i for i, r in enumerate(rows) if r[6] is not None]
            axes = np.array([rows[i][6] for i in slide], dtype=float).reshape(-1, 3)
            self._error_rows = (key, pa, pbv, slide, axes)
        _, pa, pbv, slide, axes = self._error_rows
        f = self._frames_of([r[2] for r in rows] + [r[3] for r in rows])
        a, b = f[: len(rows)], f[len(rows) :]
        gap = np.einsum("nij,nj->ni", a[:, :3, :3], pa) + a[:, :3, 3] - np.einsum("nij,nj->ni", b[:, :3, :3], pbv)
        gap -= b[:, :3, 3]
        if slide:  # a slider: only the gap across its axis is an error
            u = np.einsum("nij,nj->ni", a[slide, :3, :3], axes)
            gap[slide] -= np.einsum("ni,ni->n", gap[slide], u)[:, None] * u
        return float(np.sqrt(np.einsum("ni,ni->n", gap, gap)).max())

    def joint_angle_error(self) -> float:
        """Largest angle, rad, by which a fixed joint made of point pivots has turned its child
        off the relative orientation the joint holds (the pivots' gaps are constraint_error)."""
        rows = self.fixed_frames
        if not rows:
            return 0.0
        f = self._frames_of([r[1] for r in rows] + [r[2] for r in rows])
        ra = f[: len(rows), :3, :3] @ np.array([r[3] for r in rows])
        rb = f[len(rows) :, :3, :3] @ np.array([r[4] for r in rows])
        trace = np.einsum("nij,nij->n", ra, rb)  # trace of ra^T rb
        return float(np.arccos(np.clip((trace - 1.0) / 2.0, -1.0, 1.0)).max())

    def render_camera(self, cam, rgb_only: bool = False) -> dict:
        return render(self, cam, rgb_only)

    def _shapeless(self, sb) -> bool:
        parts = getattr(sb, "_parts", None)
        return parts is not None and not parts.types and parts.plane is None

    def _engine_report(self, rep: dict) -> dict:
        return {
            "engine": "pybullet",
            **soft_health(self.soft, self._floor_z, rep),
            "spring_joints": len(self.springs.joints),
            "renderer": self.renderer,
            **({"renderer_note": self.renderer_note} if self.renderer_note else {}),
        }

    def mj_view(self):
        """The MuJoCo mirror that draws the cameras with ``renderer="mujoco"``, built on the first
        picture by the ``mirror`` this world was given (runner/engines.py gives
        runner/mujoco/mirror.py's; this back end does not import the other)."""
        if self._mj_view is None:
            if self.mirror is None:
                raise RuntimeError("no MuJoCo mirror was given to this world (open it with runner.open_world)")
            self._mj_view = self.mirror(self)
        return self._mj_view

    def adopt(self, old) -> None:
        """Take over ``old``'s MuJoCo view (the ``renderer="mujoco"`` mirror, ~0.2 s to build)
        when this world draws with it too."""
        view = getattr(old, "_mj_view", None)
        if view is None or self._mj_view is not None or self.renderer != "mujoco" or old.renderer != "mujoco":
            return
        view.rebind(self)
        self._mj_view, old._mj_view = view, None

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
        held.forget(self.cid)
        if getattr(self, "_ghost_pass", None) is not None:
            self._ghost_pass.close()
        if pb.isConnected(self.cid):
            with egl.quiet_stdout() if self.renderer == "egl" else contextlib.nullcontext():
                pb.disconnect(self.cid)
