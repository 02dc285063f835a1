"""The limits of `cone twist` joints in the MuJoCo world as AMBF's Bullet plays them (runner/
cone_twist.py: an elliptic swing cone and a twist limit apart), where AMBF's bodies are asked for
(``Options.bodies`` "ambf": ``adfkit run``, ``adfkit parity``); otherwise each of the joint's three
hinges keeps its range.

A cone twist is three hinges in its child's body (build.py: R = Rx·Ry·Rz, frame B in frame A).
Their ranges are taken out of the model and Bullet's swing and twist rows put in: before each
physics step, a generalized force on the three hinges (a torque pair between the two bodies).
Where the joint holds its body alone on a static one, each row's impulse is the one Bullet's
solver leaves, the joint's pivot rows and angular rows solved one after another from the body's
mass and inertia about its centre of mass (cone_twist.sequential_impulses); elsewhere (a body
with more below it, a moving parent) the one that leaves the joint turning back at Bullet's rate
through MuJoCo's mass matrix. Limiting each hinge, a rod falling diagonally into a cone of 0.3 x
0.8 rad was 66 mm from AMBF's over 2 s (docs/parity.md has the figures now)."""

from __future__ import annotations

import mujoco
import numpy as np

from ...model.semantics import JointKind, ReversedJoint
from ..cone_twist import CONE_TWIST_BIAS, cone_rows, elliptic, row_impulses, sequential_impulses, spans


def _hinges(names) -> list[str] | None:
    """The x, y, z hinges of a cone twist's MuJoCo joints, None unless it has exactly those."""
    ends = [n.rsplit("#", 1)[-1] for n in names]
    return list(names) if ends == ["hingex", "hingey", "hingez"] else None


class ConeRows:
    """Every cone twist of the world's plan whose swing Bullet limits with an ellipse."""

    @classmethod
    def make(cls, world) -> ConeRows | None:
        m = world.model
        found = []
        for j, kind, parent, _child, names in world._plan.joints:
            if kind is not JointKind.CONE_TWIST or isinstance(j, ReversedJoint):
                continue
            span, hinges = spans(j.joint_limits), _hinges(names)
            if hinges is None or not elliptic(span):
                continue
            ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n) for n in hinges]
            if min(ids) < 0:
                continue
            pid = 0 if parent.mjname == "world" else mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, parent.mjname)
            found.append((ids, span, pid))
        return cls(world, found) if found else None

    def __init__(self, world, found) -> None:
        m, d = world.model, world.data
        self.model, self.data, self.dt = m, d, world.dt
        ids = np.array([f[0] for f in found])
        m.jnt_limited[ids.ravel()] = 0  # the ellipse and the twist row, not a range per hinge
        self.qadr = m.jnt_qposadr[ids]
        self.dofs = m.jnt_dofadr[ids]
        self.span = np.array([f[1] for f in found])
        self.child = m.jnt_bodyid[ids[:, 0]]
        self.parent = np.array([f[2] for f in found])
        self.anchor = m.jnt_pos[ids[:, 0]]  # the pivot in the child's body frame
        # Bullet's solve of the joint alone: the parent static and the child with nothing below it
        static = m.body_weldid[self.parent] == 0
        alone = np.isclose(m.body_subtreemass[self.child], m.body_mass[self.child])
        self.held = static & alone
        self.nv = m.nv
        self._on = False
        self.frame_a = None  # _frames

    def apply(self) -> None:
        """This physics step's swing and twist rows, as generalized forces on the hinges."""
        m, d, dt = self.model, self.data, self.dt
        q = d.qpos[self.qadr]
        rx, ry, rz = (_turn(q[:, i], i) for i in range(3))
        r_rel = rx @ ry @ rz  # frame B in frame A
        n = len(q)
        axes, err = cone_rows(np.broadcast_to(np.eye(3), (n, 3, 3)), r_rel, self.span)
        active = err > 0.0
        if not active.any():
            if self._on:
                d.qfrc_applied[self.dofs.ravel()] = 0.0
                self._on = False
            return
        # each row on the hinges: ω of B relative to A, in A, is x·q̇x + Rx·y·q̇y + Rx·Ry·z·q̇z
        cols = np.stack([np.broadcast_to([1.0, 0.0, 0.0], (n, 3)), rx[:, :, 1], (rx @ ry)[:, :, 2]], axis=2)
        jac = axes @ cols  # (n, 2, 3): the rows on the joint's three dofs
        rate = (jac @ d.qvel[self.dofs][:, :, None])[..., 0]
        full = np.zeros((n * 2, self.nv))
        for k in range(n):
            full[2 * k : 2 * k + 2, self.dofs[k]] = jac[k]
        solved = np.zeros_like(full)
        mujoco.mj_solveM(m, d, solved, full)
        w = np.stack([full[2 * k : 2 * k + 2] @ solved[2 * k : 2 * k + 2].T for k in range(n)])
        lam = row_impulses(w, rate, CONE_TWIST_BIAS * err / dt, active)
        h = self.held & active.any(1)
        if h.any():
            lam[h] = self._bullet(h, axes, err, r_rel, cols)
        d.qfrc_applied[self.dofs] = (jac * lam[:, :, None]).sum(1) / dt
        self._on = True

    def _frames(self) -> None:
        """The held joints' frame A and pivot in the world (fixed: their parents are static), and
        their children's centre of mass and inertial frame in the body frame, from the poses now."""
        m, d, c = self.model, self.data, self.child
        q = d.qpos[self.qadr]
        r_rel = _turn(q[:, 0], 0) @ _turn(q[:, 1], 1) @ _turn(q[:, 2], 2)
        body = d.xmat[c].reshape(-1, 3, 3)
        self.frame_a = body @ r_rel.transpose(0, 2, 1)  # the child's body frame with its hinges at zero
        self.pivot = d.xpos[c] + (body @ self.anchor[:, :, None])[..., 0]
        self.com = m.body_ipos[c] - self.anchor
        quat = m.body_iquat[c]
        self.inertial = np.zeros((len(c), 3, 3))
        for i, qi in enumerate(quat):
            mujoco.mju_quat2Mat(self.inertial[i].ravel(), qi)

    def _bullet(self, h, axes_in_a, err, r_rel, cols) -> np.ndarray:
        """The rows' impulses of the held joints ``h`` as Bullet's solver leaves them, from the
        joints' values and rates now (MuJoCo's poses and body velocities are a physics step old)."""
        m, d, dt = self.model, self.data, self.dt
        if self.frame_a is None:
            self._frames()
        c, r_a = self.child[h], self.frame_a[h]
        k = len(c)
        axes = (r_a[:, None, :, :] @ axes_in_a[h][:, :, :, None])[..., 0]
        body = r_a @ r_rel[h]
        arm = (body @ self.com[h][:, :, None])[..., 0]  # from the pivot to the centre of mass
        omega = (r_a @ (cols[h] @ d.qvel[self.dofs[h]][:, :, None]))[..., 0]
        rot = body @ self.inertial[h]
        inv_i = (rot / m.body_inertia[c][:, None, :]) @ rot.transpose(0, 2, 1)
        v = np.cross(omega, arm) + np.broadcast_to(m.opt.gravity, (k, 3)) * dt
        zero = np.zeros((k, 3))
        parent = (np.zeros(k), np.zeros((k, 3, 3)), zero, zero, zero)
        child = (1.0 / m.body_mass[c], inv_i, v, omega, -arm)
        return sequential_impulses((parent, child), zero, axes, err[h], dt)


def _turn(angle: np.ndarray, axis: int) -> np.ndarray:
    """(n, 3, 3) rotations by ``angle`` about coordinate axis ``axis``."""
    c, s = np.cos(angle), np.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    out = np.zeros((len(angle), 3, 3))
    out[:, axis, axis] = 1.0
    out[:, i, i], out[:, j, j], out[:, i, j], out[:, j, i] = c, c, -s, s
    return out
