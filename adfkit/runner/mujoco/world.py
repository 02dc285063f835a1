"""MujocoWorld: an ADF scene played in MuJoCo behind the same World interface as the PyBullet
back end (runner/world.py): step, run, body(name) with world_matrix/com_position/state/force/
torque, grasp, overlapping, place_ghosts, ghosts/actuators/sensors/cameras/articulations,
joint_state/reset_joints, report, constraint_error, close. The model comes from build.py, is
built into the world by assemble.py and acted on between steps by interact.py (AMBF's ghost rule:
ghosts.py);
docs/mujoco.md says what is approximated.
"""

from __future__ import annotations

import time

import mujoco
import numpy as np

from ..options import Options
from ..rotations import invert, matrix_to_quat
from ..soft import in_scene as soft_in_scene
from ..soft import soft_health
from ..world import World
from . import motor_rows
from . import stability as mj_stability
from .assemble import Assembly
from .chain import ChainModel, chain_ghosts
from .cone_rows import ConeRows
from .interact import Interaction
from .limit_chains import LimitChains
from .objects import MjBody
from .restitution import Restitution
from .soft import MjSoftBodies


class MujocoWorld(Assembly, Interaction, World):
    engine = "mujoco"
    body_type = MjBody
    chain_model = ChainModel  # AMBF's solver step on an articulation (chain.py)
    hold_limits_under_efforts = False  # its limit rows hold an effort-driven joint as AMBF's (limits.py)

    def chain_ghosts(self, art) -> dict:
        return chain_ghosts(self, art)

    def __init__(self, scene, options: Options | None = None, gui: bool = False, sleep: bool = True) -> None:
        """``sleep``: MuJoCo's island sleeping (resting trees are not integrated until a contact,
        a force or a constraint with an awake tree wakes them; driven trees never sleep)."""
        if gui:
            raise ValueError("the MuJoCo engine plays headless only (use --engine pybullet for --gui)")
        self._setup(scene, options, False)
        self.soft = MjSoftBodies(self) if soft_in_scene(scene) else None  # the flexes of its soft bodies
        self.engine_warnings: list[str] = []  # MuJoCo's other warnings, with their time
        mj_stability.install_mujoco_handler()
        self.sleep = sleep and hasattr(mujoco.mjtEnableBit, "mjENBL_SLEEP")  # MuJoCo 4's island sleeping
        self._render = None
        self._vel6 = np.zeros(6)
        self._runtime_excludes: set[int] = set()
        self._contacts_key, self._contacts = None, ()  # interact._contact_table, once a step
        self._ghost_row_of = None  # ghosts._ghost_rows, made on the first look into the ghosts
        self._weightless_ids: set[int] = set()  # the bodies a ghost holds weightless (ghosts._plan_ghosts)
        self._ghost_plan, self._ghost_changed = None, False  # ghosts._ambf_ghosts' plan, while it holds
        self._ghost_before = None  # at a 1 ms control step: the answers a physics step before, and changed
        self._ghost_steps = None  # longer control steps: a moving free body's physics steps (ghost_steps.py)
        self.camera_problem = ""
        self._build()
        self._pair_margins = np.array(self.model.pair_margin)  # set_collision gives them back
        self.restitution = Restitution.make(self) if self.opt.bodies == "ambf" else None  # restitution.py
        self.cone_rows = ConeRows.make(self) if self.opt.bodies == "ambf" else None  # cone_rows.py
        self.limit_chains = LimitChains(self)  # free multibodies' stops through AMBF's solver step

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
        self._awake = None  # bodies moved by hand: control() looks at the hole ghosts again

    def joint_motor(self, art, index: int, velocity: float, max_force: float) -> None:
        """Joint ``index`` of ``art`` driven at ``velocity`` (runner/joint_commands.py: AMBF's
        velocity motor): its drive's target moves by velocity·dt each control step, a velocity
        servo on the same stiff drive (its force limit is watched as the drive's, DriveLimits)."""
        d = self.data
        eq, a = art.eqs[index], art.vadr[index]
        if eq >= 0:
            d.eq_active[eq] = 1
        if a >= 0:
            d.qfrc_applied[a] = 0.0
        art.targets[index] = float(d.qpos[art.qadr[index]]) + float(velocity) * self.dt * self.opt.control_substeps
        art.retarget()

    def joint_mobility(self, art, idxs) -> np.ndarray:
        """M⁻¹ over joints ``idxs`` of ``art`` (motor_rows.py: AMBF's motor rows)."""
        return motor_rows.joint_mobility(self, art, idxs)

    def joint_row_mass(self, art, index: int) -> float:
        """The mass AMBF's motor row along joint ``index`` sees (motor_rows.py)."""
        return motor_rows.joint_row_mass(self, art, index)

    def joint_effort(self, art, index: int, effort: float) -> None:
        """Joint ``index`` of ``art`` pushed by ``effort`` (N·m or N), its drive off, until the next
        command (runner/joint_commands.py: AMBF's commandEffort); ``art.drive()`` turns it on again."""
        d = self.data
        eq, a = art.eqs[index], art.vadr[index]
        art.efforts = True
        if eq >= 0:
            d.eq_active[eq] = 0
        if a >= 0:
            d.qfrc_applied[a] = float(effort)

    def pushes_spring(self, joint) -> bool:
        """Whether ``spring_effort`` can push ``joint`` (a limited torsion or linear spring here)."""
        return id(joint) in self._spring_dofs

    def spring_effort(self, joint, effort: float) -> bool:
        """A limited torsion or linear spring (the file's ``joint``) pushed by ``effort`` (N·m or N)
        about or along its axis until the next command, as AMBF's commandEffort pushes it; False
        for a joint that is not such a spring of this world."""
        dof = self._spring_dofs.get(id(joint))
        if dof is None:
            return False
        rows = self.spring_rows
        at = np.flatnonzero(rows.dofs == dof) if rows is not None else []
        if len(at):
            rows.efforts[at[0]] = float(effort)  # its row sets the dof's force each physics step
        else:
            self.data.qfrc_applied[dof] = float(effort)
        return True

    def set_body_velocity(self, sb, linear, angular) -> bool:
        """Set a free body's COM velocity (world frame); False for a body that is not free."""
        m, d = self.model, self.data
        j = m.body_jntadr[sb.id]
        if j < 0 or m.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE:
            return False
        a = m.jnt_dofadr[j]
        d.qvel[a : a + 3] = linear
        d.qvel[a + 3 : a + 6] = d.xmat[sb.id].reshape(3, 3).T @ np.asarray(angular, float)  # body frame
        return True

    def control(self) -> None:
        """Per-control-step forces and senses: proximity sensors' rays, the bodies' velocity damping
        (damping.py), the ghosts: AMBF's rule (Options.ghosts "ambf", every ghost) or the hole
        ghosts' viscous friction.
        Only awake candidate geoms are looked at (a sleeping body does not move), first against
        one sphere that holds every hole-ghost geom (kept while the ghosts' bodies sleep): all
        of them above it along -gravity (instruments over the tissue: one product and a
        comparison, all a resting scene costs), else all of them outside it, else a
        bounding-sphere test of every hole-ghost geom against every candidate, then MuJoCo's
        exact distance only for the pairs that pass. Each stage only rules out what the next
        would, so the friction is what the exact test alone gives."""
        for s in self.sensors:
            self._sense(s)
        self.damping.apply()
        if self.opt.ghosts == "ambf":
            self._ambf_ghosts()
            return
        fg = self._friction_geoms
        if not len(fg) or not len(self._cand_geoms):
            return
        m, d = self.model, self.data
        gx = self._geom_xpos  # views into MjData/MjModel, made once (attribute access costs)
        key = self._body_awake.tobytes() if self.sleep else None
        aw = self._awake
        if aw is None or key != self._awake_key or not self._fg_asleep:
            fgx = gx[fg]  # the hole ghosts move (or may have): their bounding sphere again if so
            if fgx.tobytes() != self._fg_key:
                self._ghost_sphere(fgx)
            aw = self._awake if self._awake is not None and key == self._awake_key else self._awake_candidates(key)
        idx, cgi, reach, above = aw
        # every awake candidate above the ghosts' sphere (instruments over the tissue), else
        # every awake candidate outside it, else the per-geom spheres
        if not len(idx) or not np.count_nonzero(gx @ self._up <= above):
            if not self._overlaps_cleared:
                self._no_overlaps()
            return
        x = gx[cgi] - self._fg_centre
        if not np.count_nonzero(np.einsum("ij,ij->i", x, x) <= reach):
            if not self._overlaps_cleared:
                self._no_overlaps()
            return
        diff = gx[cgi][None, :, :] - self._fg_pos(gx)
        reach = (self._cand_rbound[idx][None, :] + self._fg_rbound) ** 2
        near = np.einsum("ijk,ijk->ij", diff, diff) <= reach
        if not np.count_nonzero(near):
            self._no_overlaps()
            return
        cg = cgi
        self._overlaps_cleared = False
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

    def _awake_candidates(self, key) -> tuple:
        """(indices into the candidate geoms, their geom ids, their squared reach to the ghosts'
        sphere, every geom's least height above it) for the candidates whose body is awake (a
        sleeping body does not move: no friction to apply); kept while no body falls asleep or
        wakes (``key``: the bodies' sleep states as bytes, None without sleeping). A geom is
        above the sphere when its centre's height along ``_up`` exceeds the sphere's top by its
        bounding radius (padded by a nanometre against rounding); -inf for the geoms not watched."""
        if self.sleep:
            idx = np.flatnonzero(self._body_awake[self._cand_geom_bodyid] == self._AWAKE)
        else:
            idx = self._all_cand
        cgi = self._cand_geoms[idx]
        rb = self._cand_rbound[idx]
        # hole ghosts on sleeping bodies do not move while the sleep states stay (move_base and
        # reset_joints, which move bodies by hand, drop what is kept here)
        self._fg_asleep = self.sleep and not np.any(self._body_awake[self._fg_bodyid] == self._AWAKE)
        above = np.full(len(self._geom_xpos), -np.inf)
        above[cgi] = float(self._fg_centre @ self._up) + self._fg_radius + rb + 1e-9
        self._awake = (idx, cgi, (self._fg_radius + rb) ** 2, above)
        self._awake_key = key
        return self._awake

    def _no_overlaps(self) -> None:
        """Nothing is inside a hole ghost (set once while it stays so)."""
        if not self._overlaps_cleared:
            for g in self._friction_ghosts:
                g.overlapping = []
            self._overlaps_cleared = True

    def _ghost_sphere(self, fgx: np.ndarray) -> None:
        """The sphere that holds every hole-ghost geom's bounding sphere (padded by a nanometre,
        so that rounding never lets it miss what the per-geom test would find)."""
        centre = fgx.mean(axis=0)
        self._fg_centre = centre
        self._fg_radius = (
            float(np.max(np.linalg.norm(fgx - centre, axis=1) + self._fg_rbound[:, 0])) * (1 + 1e-9) + 1e-9
        )
        self._fg_key = fgx.tobytes()
        self._awake = None  # the reach depends on the radius

    def _fg_pos(self, gx) -> np.ndarray:
        return gx[self._friction_geoms][:, None, :]

    def step(self, n: int = 1) -> None:
        """Advance n control steps (n·control_substeps physics steps of 1/physics_hz)."""
        t0 = time.perf_counter()
        sub = self.opt.control_substeps
        m, d = self.model, self.data
        base, xfrc, control, step = self._base_xfrc, d.xfrc_applied, self.control, mujoco.mj_step
        kinematics = mujoco.mj_kinematics
        pending = mj_stability.pending_messages()
        limits, rows = self.drive_limits.check, self.spring_rows
        # AMBF's vehicles and resistance sensors act after each physics step (vehicles.py, resist.py)
        veh = [a for a in (self.vehicles, self.resistance) if a] or None
        rest = self.restitution  # Bullet's restitution after each physics step (restitution.py)
        cones = self.cone_rows  # Bullet's cone-twist rows before each physics step (cone_rows.py)
        stops = self.limit_chains if self.limit_chains else None  # AMBF's solver around a stop (limit_chains.py)
        for k in range(n):
            control()
            fine = self._ghost_steps
            fine = fine if fine is not None and fine.ghosts else None  # AMBF's ghosts at every physics step
            springs = rows is not None and rows.apply(sub * self.dt)  # spring_rows.py; False: sprung trees at rest
            each = fine is not None or veh is not None or springs or rest is not None or cones is not None
            watch = stops is not None and stops.watching()  # else nothing free to bounce: no look
            if stops is not None and not watch:
                stops.idle(sub)
            if each or watch:
                for i in range(sub):
                    if springs and i:
                        rows.apply()
                    if cones is not None:
                        cones.apply()
                    if veh is not None:
                        for v in veh:
                            v.push()
                    if rest is not None:
                        rest.before()
                    if watch:
                        stops.before()
                    step(m, d, 1)
                    if watch:
                        stops.after()
                    if rest is not None:
                        rest.after()
                    if veh is not None:
                        for v in veh:
                            v.pull()
                        kinematics(m, d)
                        for v in veh:
                            v.update(self.dt)
                    if i < sub - 1 and fine is not None:
                        if veh is None:
                            kinematics(m, d)
                        fine.between()
                if fine is not None:
                    fine.end()
            else:
                step(m, d, sub)
            # mj_step computes the poses (xpos, xquat, geom_xpos) before it integrates: without
            # this, every pose read after a step was the one a physics step earlier (a body
            # falling at 29 m/s read 29 mm high against AMBF, measured on puzzle1's Occulus)
            kinematics(m, d)
            if self._xfrc_dirty:  # something added forces for this control step
                xfrc[:] = base
                self._xfrc_dirty = False
            limits()
            if pending:  # a warning: NaN and a state reset, a singular inertia...
                self.sim_time = (self.steps + (k + 1) * sub) * self.dt
                mj_stability.drain_mujoco(self, self.watch)
        self.steps += n * sub
        self.sim_time = self.steps * self.dt
        self.wall_time += time.perf_counter() - t0

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
        self._awake = None  # bodies moved by hand: control() looks at the hole ghosts again
        self._contacts_key = None  # and the forward pass found the contacts anew

    def constraint_error(self) -> float:
        """Largest distance, m, between the two pivots of a loop-closing joint (tree joints are exact)."""
        worst = 0.0
        d = self.data
        for _, _, parent, child, pa, pbv, _ in self.constraints:
            xa = d.xmat[parent.id].reshape(3, 3) @ pa + d.xpos[parent.id]
            xb = d.xmat[child.id].reshape(3, 3) @ pbv + d.xpos[child.id]
            worst = max(worst, float(np.linalg.norm(xa - xb)))
        return worst

    def render_camera(self, cam, rgb_only: bool = False) -> dict:
        return self._renderer().render(cam, rgb_only)

    def _shapeless(self, sb) -> bool:
        return not sb.has_collision

    def _engine_report(self, rep: dict) -> dict:
        return {
            "engine": "mujoco",
            "awake_trees": int(getattr(self.data, "ntree_awake", self.model.ntree)),
            "trees": int(self.model.ntree),
            "spring_joints": self.springs_count,
            "renderer": "mujoco",
            "engine_warnings": self.engine_warnings,
            **soft_health(self.soft, self._floor_z, rep),
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
