"""ADF body damping on the moving bodies of PyBullet's multibodies, as AMBF applies it
(runner/damping.py). PyBullet damps a multibody as a whole: one linear and one angular damping
per multibody (whichever link's changeDynamics came last), applied to each link as the force
m·v·(d + d·|v|), linear and quadratic, where AMBF scales each body's velocities by (1 - d)^dt.
On the KUKA (0.95 on every link: AMBF's rate 3.0/s, PyBullet's 0.95·(1 + |v|)) under an effort
program that was 1.44 mm and 5.5° from AMBF; with AMBF's decay 0.03 mm and 0.4°. So each
multibody's own damping is 0, and each moving link (and a moving base) is given, each control
step, the force at its centre of mass and the torque that decay its velocities as AMBF does.
A free body is a btRigidBody in PyBullet too, damped by Bullet itself as in AMBF."""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ..damping import decay_rates, gains
from . import held


class LinkDamping:
    def __init__(self, world) -> None:
        self.cid = world.cid
        cdt = world.dt * world.opt.control_substeps
        groups: dict[int, list] = {}
        for sb in world.bodies:
            if sb.static or sb.articulation is None:
                continue
            groups.setdefault(sb.uid, []).append(sb)
        self.groups = []
        for uid, sbs in groups.items():
            pb.changeDynamics(uid, -1, linearDamping=0.0, angularDamping=0.0, physicsClientId=self.cid)
            rates = np.array([decay_rates(sb.body) for sb in sbs])
            if not rates.any():
                continue
            k = gains(rates, cdt)
            self.groups.append(
                (
                    uid,
                    [sb.link for sb in sbs],
                    np.array([sb.mass for sb in sbs]) * k[:, 0],  # force per m/s
                    np.array([sb.inertia for sb in sbs]) * k[:, 1:2],  # principal torque per rad/s
                )
            )
        # (uid, link) -> (COM position, quaternion, linear and angular velocity) as read this control step
        self.read: dict[tuple[int, int], tuple] = {}

    def apply(self) -> None:
        """Add this control step's damping forces and torques (cleared by the next step)."""
        cid = self.cid
        push, twist, read = held.push, held.twist, self.read
        for uid, links, k_lin, k_ang in self.groups:
            pos, rot, lin, ang = _states(uid, links, cid, read)
            # the torque k·I·ω with I = R·diag(I)·Rᵀ, R the COM frame's rotation in the world
            local = np.einsum("nji,nj->ni", rot, ang)
            torque = np.einsum("nij,nj->ni", rot, k_ang * local)
            force = k_lin[:, None] * lin
            for link, f, at, t in zip(links, force.tolist(), pos.tolist(), torque.tolist()):  # each row's floats
                push(uid, link, f, at, cid)
                twist(uid, link, t, cid)


def _states(uid: int, links: list[int], cid: int, read: dict):
    """(COM positions, COM frame rotations, COM velocities, angular velocities) of ``links``
    (-1: the base), world frame; each link's (position, quaternion, velocities) also into ``read``,
    keyed (uid, link), as SimBody.state() gives them."""
    out = {}
    kids = [k for k in links if k >= 0]
    if kids:  # computeLinkVelocity 1, computeForwardKinematics 1
        for k, s in zip(kids, pb.getLinkStates(uid, kids, 1, 1, physicsClientId=cid)):
            out[k] = (s[0], s[1], s[6], s[7])
    if -1 in links:
        p, q = pb.getBasePositionAndOrientation(uid, physicsClientId=cid)
        v, w = pb.getBaseVelocity(uid, physicsClientId=cid)
        out[-1] = (p, q, v, w)
    rows = [out[k] for k in links]
    read.update(((uid, k), r) for k, r in zip(links, rows))
    rot = np.array([pb.getMatrixFromQuaternion(r[1]) for r in rows]).reshape(-1, 3, 3)
    return (
        np.array([r[0] for r in rows]),
        rot,
        np.array([r[2] for r in rows]),
        np.array([r[3] for r in rows]),
    )
