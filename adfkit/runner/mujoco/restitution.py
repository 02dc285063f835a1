"""Bullet's restitution in the MuJoCo world, under AMBF's bodies (``Options.bodies`` "ambf").

MuJoCo's contacts are soft and stiff here (contacts.py): a ball dropped on a floor stops dead
whatever its restitution. Bullet (btSequentialImpulseConstraintSolver::setupContactConstraint,
2.88 as AMBF builds it) gives a contact the target normal velocity

    e·(−v) + erp·depth/dt   where the approach speed −v ≥ 0.2 m/s (m_restitutionVelocityThreshold),

``e`` the product of the two bodies' restitutions (Bullet's combination; a body without one has
AMBF's 0.1), ``v`` the normal velocity before the step (before gravity), ``depth`` how far the
shapes overlap and ``erp`` 0.2, its contact error reduction (the push stays in the velocity, as
AMBF's ball shows: 0.72 × 2.683 + 0.2 × 0.905 mm / 1 ms = 2.113 m/s, measured). After each
physics step where such a contact was made, the contacts' normal velocities are raised to their
targets by impulses along the contacts' normals (never pulling), solved together as Bullet's
projected Gauss-Seidel does, and the step's positions moved by what the impulses add over the
step. A pair whose combined restitution is 0 is left alone, as is every scene without one.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ...model.semantics import DEFAULT_RESTITUTION

#: Bullet's m_restitutionVelocityThreshold: slower approaches get no restitution
VELOCITY_THRESHOLD = 0.2
#: Bullet's contact ERP (btContactSolverInfo m_erp), its push out of an overlap per step
CONTACT_ERP = 0.2
#: projected Gauss-Seidel sweeps over a step's bouncing contacts (Bullet's default iterations)
SWEEPS = 10


class Restitution:
    """Raises the normal velocities of a step's bouncing contacts to Bullet's restitution targets."""

    def __init__(self, world, geom_rest: np.ndarray) -> None:
        self.world = world
        self.rest = geom_rest  # per geom: its body's restitution (0 where none can bounce)
        self.qvel0 = np.zeros(world.model.nv)
        m = world.model
        self._jacp = np.zeros((3, m.nv))
        self._jv = np.zeros(0)  # the constraint rows' velocities, before the step
        self._elliptic = m.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC

    @classmethod
    def make(cls, world) -> Restitution | None:
        """The per-step restitution of ``world``; None where no two colliding geoms can bounce."""
        m = world.model
        rest = np.zeros(m.ngeom)
        for sb in world.bodies:
            b = sb.body
            r = getattr(b, "restitution", None)
            rest[m.geom_bodyid == sb.id] = DEFAULT_RESTITUTION if r is None else float(r)
        rest[(m.geom_contype == 0) & (m.geom_conaffinity == 0)] = 0.0  # not colliding (visuals, ghosts)
        if np.count_nonzero(rest > 0) < 2 and not (np.any(rest > 0) and m.npair):
            return None
        return cls(world, rest)

    def before(self) -> None:
        """Keep the velocities the step starts from (Bullet's restitution reads them)."""
        self.qvel0[:] = self.world.data.qvel

    def after(self) -> None:
        """After mj_step (its contacts, Jacobians and mass matrix still those of the step's start):
        the bouncing contacts' impulses, into qvel and qpos."""
        m, d = self.world.model, self.world.data
        if d.ncon == 0:
            return
        con, n = d.contact, d.ncon
        e = self.rest[con.geom1[:n]] * self.rest[con.geom2[:n]]
        live = np.flatnonzero((e > 0.0) & (con.exclude[:n] == 0) & (con.efc_address[:n] >= 0))
        if not len(live):
            return
        # the contacts' normal velocities before the step, from MuJoCo's constraint Jacobian (its
        # first row is the normal of an elliptic cone; a pyramid's first two rows average to it)
        jv = self._jv if len(self._jv) == d.nefc else np.empty(d.nefc)
        self._jv = jv
        mujoco.mj_mulJacVec(m, d, jv, self.qvel0)
        adr = con.efc_address[live]
        v0 = jv[adr]
        if not self._elliptic:
            two = con.dim[live] > 1
            v0[two] = 0.5 * (v0[two] + jv[adr[two] + 1])
        fast = v0 <= -VELOCITY_THRESHOLD  # approaching (the normal points from geom1 to geom2)
        if not np.count_nonzero(fast):
            return
        rows, targets = [], []
        for i, v in zip(live[fast], v0[fast]):
            depth = max(0.0, float(con.includemargin[i] - con.dist[i]))
            rows.append(self._normal_row(m, d, con, i))
            targets.append(-e[i] * v + CONTACT_ERP * depth / m.opt.timestep)
        jac = np.array(rows)
        minv_jt = np.zeros_like(jac)
        mujoco.mj_solveM(m, d, minv_jt, jac)  # (M⁻¹Jᵀ)ᵀ, row by row (M is symmetric)
        minv_jt = minv_jt.T
        a = jac @ minv_jt
        gap = np.array(targets) - jac @ d.qvel
        lam = np.zeros(len(rows))
        for _ in range(SWEEPS):
            for k in range(len(rows)):
                if a[k, k] > 0.0:
                    lam[k] = max(0.0, lam[k] + (gap[k] - a[k] @ lam) / a[k, k])
        if not np.any(lam):
            return
        dv = minv_jt @ lam
        d.qvel += dv
        mujoco.mj_integratePos(m, d.qpos, dv, m.opt.timestep)

    def _normal_row(self, m, d, con, i: int) -> np.ndarray:
        """Contact i's normal velocity row: geom2's point's velocity less geom1's, along the normal."""
        n, p = con.frame[i, :3], con.pos[i]
        row = np.zeros(m.nv)
        for geom, sign in ((con.geom2[i], 1.0), (con.geom1[i], -1.0)):
            body = int(m.geom_bodyid[geom])
            if m.body_weldid[body] == 0:
                continue  # welded to the world: does not move
            mujoco.mj_jac(m, d, self._jacp, None, p, body)
            row += sign * (n @ self._jacp)
        return row
