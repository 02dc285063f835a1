"""The inertias the force-driven joints (spring_forces.py) push against: Bullet's caps on a six-dof
spring (bullet_spring_masses) and, for an angular limit, the inertia about the joint's pivot
(PivotInertia).

AMBF's six-dof, six-dof-spring and cone-twist limits are constraint rows Bullet solves together
with the rows that hold the two pivots together, so a limit stops a body turning about the
pivot: a pendulum swinging into its stop is stopped there, whatever its own inertia about its
centre of mass. The PyBullet runner plays those limits as a torque each physics step (SpringSet,
spring_forces.py) while PyBullet's point constraint holds the pivots, so the torque must be
sized for the inertia about the pivot: sized for the body's least principal inertia about its
centre of mass, a 0.2 kg rod 0.2 m long hinged at its end (3.3e-6 kg·m² about its axis, 3.1e-3
about the pivot across it) swung through its stop at 0.5 rad to 1.24 rad and on like a pendulum,
where AMBF's stops there (`adfkit parity`, 1.5 s: 80-130 mm apart).

For each joint and each axis of its frame A: 1 / Σ a·(I_pivot)⁻¹·a over its two bodies, a
body's inertia about the pivot being its inertia about its centre of mass carried there
(parallel axes), each body's share divided among the joints on it as SpringSet divides its
inertia (a Jacobi step)."""

from __future__ import annotations

import numpy as np


def bullet_spring_masses(bodies, ip, ic, frame_a, frame_b):
    """The inertia (n, 3) and mass (n, 3) Bullet's btGeneric6DofSpring2Constraint caps each joint's
    spring and damper with, per axis of joint frame A: each dynamic body's inertia about the axis
    (1/|I⁻¹·a|, the axis in its principal frame; the child's at the joint's zero angle) plus its
    mass times the squared distance from its centre of mass to the joint frame, and each body's
    mass; the two in series (mA·mB/(mA + mB)), one body's alone when the other is static."""
    mass = np.array([0.0 if b.static else b.mass for b in bodies])
    inertia = np.array([np.maximum(np.asarray(b.inertia, float), 1e-12) for b in bodies])

    def about(i, frame):  # (n, 3): body i's inertia about each axis of its joint frame
        axes = frame[:, :3, :3]  # columns: the joint frame's axes in the body's principal frame
        own = 1.0 / np.linalg.norm(axes / inertia[i][:, :, None], axis=1)
        return mass[i][:, None] * (frame[:, :3, 3] ** 2).sum(1)[:, None] + own

    def series(a, b, ma, mb):
        with np.errstate(divide="ignore", invalid="ignore"):
            both = a * b / (a + b)
        return np.where((ma == 0)[:, None], b, np.where((mb == 0)[:, None], a, both))

    ma, mb = mass[ip], mass[ic]
    lin = series(np.repeat(ma[:, None], 3, 1), np.repeat(mb[:, None], 3, 1), ma, mb)
    return series(about(ip, frame_a), about(ic, frame_b), ma, mb), lin


class PivotInertia:
    def __init__(self, bodies, ip: np.ndarray, ic: np.ndarray, deg: np.ndarray, pb_in_c: np.ndarray) -> None:
        self.ip, self.ic, self.pb_in_c = ip, ic, pb_in_c[:, :, None]
        static = np.array([b.static for b in bodies])
        self.mass = np.array([0.0 if b.static else float(b.mass) for b in bodies])
        self.principal = np.array([np.zeros(3) if b.static else np.asarray(b.inertia, float) for b in bodies])
        self.share = np.where(static, 0.0, deg)  # a static body takes nothing

    @staticmethod
    def held(bodies, ip: np.ndarray, ic: np.ndarray, deg: np.ndarray, free_lin: np.ndarray) -> np.ndarray:
        """(n,) bool: the joints whose limits turn a body about their pivot: one body static, the
        other on no other force-driven joint, the linear axes locked. In a chain (a thread's
        light elements between two joints each) the joints act at once, and limits sized for
        the inertia about each pivot threw the corpus-like thread falling from a held needle
        12 km: those keep the inertia SpringSet shares among them."""
        static = np.array([b.static for b in bodies])
        alone = (static[ip] & (deg[ic] == 1)) | (static[ic] & (deg[ip] == 1))
        alone[free_lin] = False
        return alone

    def about_pivots(self, pos: np.ndarray, rot: np.ndarray, axes: np.ndarray) -> np.ndarray:
        """(n, 3): each joint's effective inertia about each axis of its frame A (``axes``: the
        frames' columns in the world), its bodies' centres of mass at ``pos``, turned ``rot``."""
        ip, ic = self.ip, self.ic
        pivot = pos[ic] + (rot[ic] @ self.pb_in_c)[..., 0]
        inv = np.zeros((len(ip), 3, 3))
        for side in (ip, ic):
            r = pivot - pos[side]
            inertia = (rot[side] * self.principal[side][:, None, :]) @ rot[side].transpose(0, 2, 1)
            inertia += self.mass[side][:, None, None] * (
                np.einsum("ni,ni->n", r, r)[:, None, None] * np.eye(3) - r[:, :, None] * r[:, None, :]
            )
            share = self.share[side]
            moving = share > 0
            inv[moving] += np.linalg.inv(inertia[moving] + 1e-12 * np.eye(3)) * share[moving][:, None, None]
        per_axis = np.einsum("nik,nij,njk->nk", axes, inv, axes)
        return 1.0 / np.maximum(per_axis, 1e-12)
