"""ADF body damping (`damping: {linear, angular}`, velocity damping) in the MuJoCo world, which
has none of its own: Bullet scales a rigid body's velocities by (1 - d)^dt each step, a decay at
the rate -ln(1 - d) per second (runner/damping.py). The suturing thread's elements and the
needle have 0.9 (2.3/s); without it MuJoCo's thread swung freely where AMBF's is drawn as through
a viscous medium.

Applied each control step as the force that gives the same decay over the step (the exact
exp(-λ·t) of the velocity, as the hole ghosts' viscous friction), at the centre of mass, to the
awake bodies outside a driven articulation (free bodies and six-dof-spring chains; a driven
arm's joints hold it anyway, and a force would wake a sleeping body), and where AMBF's bodies are
asked for (Options.bodies "ambf") to an articulation's bodies too: AMBF damps every btRigidBody,
and its motors are soft rows that leave a jointed body its damping (the corpus KUKA's effort
program 2.96 -> 0.005 mm from AMBF, its velocity program 14.2 -> 3.5 mm). A tree whose every joint
moves slower than SLOW × MuJoCo's sleep tolerance is left alone, so that it can fall asleep (a
force keeps a tree awake: applied down to rest, the corpus suturing set's thread never slept and
its first 6 s played at 2.1x real time instead of 11-26x); the damping there is a 5e-4 N drag."""

from __future__ import annotations

import numpy as np

from ..damping import decay_rates, gains

SLOW = 10.0  # × the sleep tolerance: below it, in every dof of its tree, a body is not damped


class BodyDamping:
    def __init__(self, world) -> None:
        m = world.model
        ids, lin, ang = [], [], []
        for sb in world.bodies:
            jointed = sb.articulation is not None and world.opt.bodies != "ambf"
            if sb.static or jointed or sb.id <= 0 or m.body_mass[sb.id] <= 0:
                continue
            if m.body_treeid[sb.id] < 0:  # welded to the world: it cannot move
                continue
            a, b = decay_rates(sb.body)
            if a or b:
                ids.append(sb.id)
                lin.append(a)
                ang.append(b)
        self.world = world
        self.ids = np.array(ids, dtype=int)
        cdt = world.dt * world.opt.control_substeps
        self.k_lin, self.k_ang = gains(lin, cdt), gains(ang, cdt)
        if len(ids):
            self.mass = np.array(m.body_mass[self.ids])
            self.inertia = np.array(m.body_inertia[self.ids])
            self.root = np.array(m.body_rootid[self.ids], dtype=int)
            tree = np.array(m.body_treeid[self.ids], dtype=int)
            self.trees, self.tree_of = np.unique(tree, return_inverse=True)
            # every damped tree's dofs one after the other, and where each tree's begin: one
            # reduceat gives each tree's fastest dof
            self.dofs = np.concatenate(
                [np.arange(m.tree_dofadr[t], m.tree_dofadr[t] + m.tree_dofnum[t]) for t in self.trees]
            )
            self.starts = np.concatenate([[0], np.cumsum(m.tree_dofnum[self.trees])[:-1]])
            self.slow = SLOW * float(getattr(m.opt, "sleep_tolerance", 0.0))

    def apply(self) -> None:
        """Add this control step's damping forces and torques to xfrc_applied."""
        if not len(self.ids):
            return
        w = self.world
        d = w.data
        ids = self.ids
        if w.sleep:
            # a sleeping tree's velocities are zero: the trees with a dof at SLOW or faster are
            # the awake, moving ones
            speed = np.abs(d.qvel[self.dofs])
            if not np.count_nonzero(speed >= self.slow):  # (faster than .any() on a few elements)
                return  # nothing moves: a resting scene's whole cost
            moving = np.maximum.reduceat(speed, self.starts) >= self.slow
            on = moving[self.tree_of]
            ids, k = ids[on], on
        else:
            k = slice(None)
        cvel = d.cvel[ids]  # [ω; v] in the world frame, v at the subtree centre of mass of the root
        om = cvel[:, :3]
        v = cvel[:, 3:] + np.cross(om, d.xipos[ids] - d.subtree_com[self.root[k]])
        r = d.ximat[ids].reshape(-1, 3, 3)  # inertia frame in the world
        om_local = np.einsum("nji,nj->ni", r, om)
        torque = np.einsum("nij,nj->ni", r, self.inertia[k] * om_local)
        xf = d.xfrc_applied
        xf[ids, :3] += (self.mass[k] * self.k_lin[k])[:, None] * v
        xf[ids, 3:] += self.k_ang[k][:, None] * torque
        w._xfrc_dirty = True
