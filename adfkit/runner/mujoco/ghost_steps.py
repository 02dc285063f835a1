"""AMBF's ghost rule at every physics step on a moving free body near a ghost, in the MuJoCo world
(as runner/pybullet/ghost_steps.py does in PyBullet's): at a control step longer than a physics
step, while a free body moves near an acting ghost (within REACH of it, the growth Bullet gives a
ghost's box and a body's together, so that one entering it is caught on the step it enters), the
control step is played one physics step at a time and the rule acts on the free bodies between
them with the points found a physics step before: their velocities set, their weight taken off
for that physics step alone. The plan of the control step (ghosts._ambf_ghosts) leaves those
bodies to it."""

from __future__ import annotations

import mujoco
import numpy as np

from ..ghost_rules import SLOW, ghost_velocity

#: m: a free body's bounding sphere this near a ghost geom's has its control step played a
#: physics step at a time (Bullet's contact breaking threshold, 0.02 m, grows both boxes)
REACH = 0.04


class MjGhostSteps:
    """The fine control steps of one MuJoCo world (see the module)."""

    def __init__(self, world) -> None:
        self.world = world
        m = world.model
        free = world._free_dof[world._cand_geom_bodyid] >= 0
        self.cands = np.flatnonzero(free)  # candidate geoms of free bodies
        self.bodies = world._cand_geom_bodyid[self.cands]
        self.ghosts: list[int] = []  # indices of the ghosts played a physics step at a time now
        self.ids = np.zeros(0, dtype=int)  # the free bodies it acts on, by body id
        self.before: list | None = None  # each ghost's answer a physics step before
        self.was: np.ndarray | None = None  # the candidates' bodies' positions at the last control step
        self.was_near: np.ndarray | None = None  # which of them were near a ghost then
        self.weights: list[tuple[int, np.ndarray]] = []  # the weights taken off for this physics step
        self.gravcomp = np.zeros(0)
        self.mass = np.array(m.body_mass)

    def decide(self) -> list[int]:
        """The ghosts with a free body within REACH that moved more than SLOW·control step since
        the last control step (or was not near at the last), all in arrays."""
        w = self.world
        m, d = w.model, w.data
        self.ghosts = []
        if not len(self.cands):
            return self.ghosts
        if w.sleep and self.was is not None and not (w._body_awake[self.bodies] == w._AWAKE).any():
            return self.ghosts  # every free body asleep: none moves
        gg, starts = w._ghost_rows()
        cg = w._cand_geoms[self.cands]
        diff = d.geom_xpos[gg][:, None, :] - d.geom_xpos[cg][None, :, :]
        reach = (m.geom_rbound[gg][:, None] + m.geom_rbound[cg][None, :] + REACH) ** 2
        near = np.einsum("ijk,ijk->ij", diff, diff) <= reach
        pos = d.xpos[self.bodies]
        was, was_near = self.was, self.was_near
        self.was, self.was_near = pos, near.any(axis=0)
        if not self.was_near.any():
            return self.ghosts
        still = np.abs(pos - was).sum(axis=1) <= SLOW * w.dt * w.opt.control_substeps if was is not None else False
        moving = ~(still & was_near) if was_near is not None else np.ones(len(pos), dtype=bool)
        hot = np.logical_or.reduceat((near & moving[None, :]).any(axis=1), starts)
        self.ghosts = np.flatnonzero(hot).tolist()
        return self.ghosts

    def free_of(self, answers) -> np.ndarray:
        """The free bodies of the fine ghosts' answers now and a physics step before (the plan of
        the control step leaves them to act_now)."""
        free = self.world._free_dof
        ids: set[int] = set()
        for lists in (answers, self.before if self.before is not None else answers):
            for i in self.ghosts:
                ids.update(sb.id for sb, _ in lists[i] if free[sb.id] >= 0)
        return np.array(sorted(ids), dtype=int)

    def begin(self, now, plan_free_ids: np.ndarray) -> None:
        """At a fine control step's start: the plan's gravity compensation off for the bodies it
        acts on (given back at its end), and the rule on them with the points of the step before."""
        m = self.world.model
        self.ids = plan_free_ids
        self.gravcomp = np.array(m.body_gravcomp[self.ids])
        m.body_gravcomp[self.ids] = 0.0
        self.act_now(now)

    def between(self) -> None:
        """Between two physics steps of a fine control step (the poses computed)."""
        self.act_now(self.world._penetrating(self.world.ghosts))

    def end(self) -> None:
        """The fine control step is over: its weights off, the plan's compensation back."""
        w = self.world
        for b, f in self.weights:
            w.data.xfrc_applied[b, :3] += f
        self.weights = []
        w.model.body_gravcomp[self.ids] = self.gravcomp
        w._ghost_plan = None  # the answers moved under the plan: the next control step plans afresh

    def act_now(self, now) -> None:
        """The fine ghosts' rule on their free bodies with the points of the step before (each
        ghost in turn, the last velocity standing), their weight off for the next physics step;
        ``now``'s answers kept for the next."""
        w = self.world
        m, d = w.model, w.data
        for b, f in self.weights:
            d.xfrc_applied[b, :3] += f
        self.weights = []
        before = self.before if self.before is not None else [[] for _ in w.ghosts]
        acted: dict[int, object] = {}
        if any(before[i] for i in self.ghosts):
            mujoco.mj_comPos(m, d)
            mujoco.mj_comVel(m, d)
        for i in self.ghosts:
            g = w.ghosts[i]
            found = [(sb, n) for sb, n in before[i] if n and w._free_dof[sb.id] >= 0]
            if not found:
                continue
            v_par = np.zeros(3)
            if g.parent is not None and not g.parent.static:
                vel = np.zeros(6)
                mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, int(g.parent.id), vel, 0)
                v_par = vel[3:]
            for sb, n in found:
                vel = np.zeros(6)
                mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, int(sb.id), vel, 0)
                v2, w2 = ghost_velocity(vel[3:], vel[:3], v_par, n)
                a = int(w._free_dof[sb.id])
                d.qvel[a : a + 3] = v2
                d.qvel[a + 3 : a + 6] = d.xmat[sb.id].reshape(3, 3).T @ w2  # body frame
                acted[sb.id] = sb
        g_world = np.asarray(w.gravity, float)
        for b, sb in acted.items():
            f = self.mass[b] * (sb.gravity if sb.gravity is not None else g_world)
            d.xfrc_applied[b, :3] -= f
            self.weights.append((b, f))
        if acted:
            w._xfrc_dirty = True
        self.before = list(now)


def com_velocities(d, m, ids: np.ndarray) -> np.ndarray:
    """[ω, v] of bodies ``ids`` at their centres of mass in the world frame (mj_objectVelocity's,
    from cvel: mj_comVel must have run)."""
    cvel = d.cvel[ids]
    om = cvel[:, :3]
    r = d.xipos[ids] - d.subtree_com[m.body_rootid[ids]]
    cvel[:, 3] += om[:, 1] * r[:, 2] - om[:, 2] * r[:, 1]
    cvel[:, 4] += om[:, 2] * r[:, 0] - om[:, 0] * r[:, 2]
    cvel[:, 5] += om[:, 0] * r[:, 1] - om[:, 1] * r[:, 0]
    return cvel
