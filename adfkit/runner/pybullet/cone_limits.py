"""The limits of `cone twist` joints in the PyBullet runner as AMBF's Bullet plays them (runner/
cone_twist.py: an elliptic swing cone and a twist limit apart), where AMBF's springs are asked for
(``Options.springs`` "ambf": ``adfkit run``, ``adfkit parity``); otherwise SpringSet limits each
Euler angle of the joint.

PyBullet's point constraint holds the pivots; the swing and twist rows are a torque pair at every
physics step (SpringSet.apply). Where the joint holds a body alone on a static one, the rows'
impulses are those Bullet's solver leaves: the joint's three pivot rows and two angular rows
solved one after another, ten sweeps, each body with its inertia about its centre of mass
(cone_twist.sequential_impulses). Where that body is free and on no other joint (frees_pivot),
no PyBullet constraint holds it at all: the force and torque that leave it moving as that solve
does are applied to it, its pivot rows too, and it moves as AMBF's does (level rods falling into
their stops and plates twisted into their limits within 0.01 mm of AMBF over 2 s, where the point
constraint's pivot, stiffer than Bullet's rows at erp 0.2, left them 0.1-1.3 mm off). Sized instead to leave the joint turning back at exactly
Bullet's rate about the pivot, a rod falling diagonally into a cone of 0.3 x 0.8 rad was 0.95 mm
from AMBF, one into 0.2 x 1.2 rad 16 mm, 5 mm into 0.8 x 0.3 (0.83, 14 and 1.2 mm now; `adfkit
parity`, 2 s). Joints that share bodies (a chain) are solved together the same way, all their
rows joint after joint (cone_twist.chain_impulses): two rods, one hanging from the other, fell
into their limits within 0.65 and 0.94 mm of AMBF over 0.2 s, 55 and 70 mm with each joint's rows
sized alone for SpringSet's share of its bodies' least inertia; a 12-element rope 0.1-0.4 mm
(1.4-34 mm with the Euler angles' limits), its stepping 8x as long (4.8 against 0.58 s for 2 s)."""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ..cone_twist import chain_impulses, cone_rows, elliptic, sequential_impulses


class ConeLimits:
    """The cone twists among SpringSet's joints whose swing Bullet limits with an ellipse."""

    @staticmethod
    def among(joints) -> np.ndarray:
        """Indices of the joints (SpringJoint) these limits play."""
        return np.flatnonzero([j.cone is not None and elliptic(j.cone) for j in joints])

    @staticmethod
    def frees_pivot(sj, joints) -> bool:
        """Whether cone twist ``sj`` (a SpringJoint) holds a free body alone on a static free one,
        among ``joints`` (the assembly's, not in a multibody: (joint, kind, parent, child)): then
        no PyBullet constraint joins them and torques() plays Bullet's pivot rows too."""
        p, c = sj.parent, sj.child
        if sj.cone is None or not elliptic(sj.cone) or not p.static or c.static:
            return False
        if p.articulation is not None or c.articulation is not None:
            return False
        return sum(c is a or c is b for _j, _k, a, b in joints) == 1

    def __init__(self, springs, index, held, gravity) -> None:
        """The joints ``index`` of SpringSet ``springs``; ``held``: the indices of its joints that
        hold a body alone on a static one (PivotInertia.held); ``gravity``: each body's."""
        bodies = springs.bodies
        self.index = index
        self.span = np.stack([springs.joints[i].cone for i in index])
        self.ip, self.ic = springs.ip[index], springs.ic[index]
        self.held = np.isin(index, held)
        self.free = np.array([springs.joints[i].free_pivot for i in index], bool)
        self.held |= self.free
        self.cid, self.bodies = springs.cid, bodies
        # each body's 1/m, principal 1/I and gravity (static: none), for Bullet's solve (cone_twist.py)
        self.inv_mass = np.array([0.0 if b.static else 1.0 / float(b.mass) for b in bodies])
        self.inv_principal = np.array([np.zeros(3) if b.static else 1.0 / np.asarray(b.inertia, float) for b in bodies])
        self.gravity = np.where(self.inv_mass[:, None] > 0.0, gravity, 0.0)
        self.pa_in_p, self.pb_in_c = (p[index][:, :, None] for p in (springs.pa_in_p, springs.pb_in_c))

    def torques(self, pos, rot, lv, av, r_a, r_b, dt: float) -> np.ndarray:
        """(k, 3): the torque on each joint's child in the world (its parent takes the opposite),
        ``r_a``, ``r_b`` the joint frames in the world, ``pos``, ``rot``, ``lv``, ``av`` every body's
        centre-of-mass pose and velocity (SpringSet.states), for all the joints these play."""
        axes, err = cone_rows(r_a, r_b, self.span)
        active = err > 0.0
        if not active.any() and not self.free.any():
            return np.zeros((len(self.index), 3))
        ip, ic = self.ip, self.ic
        lam = np.zeros_like(err)
        h = self.held
        pivots = [pos[i] + (rot[i] @ p)[..., 0] for i, p in ((ip, self.pa_in_p), (ic, self.pb_in_c))]
        rest = ~h
        if active[rest].any():  # joints sharing bodies: Bullet's solve of all their rows together
            inv_all = (rot * self.inv_principal[:, None, :]) @ rot.transpose(0, 2, 1)
            bodies = (self.inv_mass, inv_all, lv + self.gravity * dt, av)
            arms = (pivots[0] - pos[ip])[rest], (pivots[1] - pos[ic])[rest], (pivots[1] - pivots[0])[rest]
            lam[rest] = chain_impulses(bodies, (ip[rest], ic[rest], *arms), axes[rest], err[rest], dt)
        if active[h].any() or self.free.any():  # a body held alone: Bullet's solve of the joint's rows
            sides, moved = [], []
            for i, pivot in zip((ip[h], ic[h]), pivots):
                r = rot[i]
                inv_i = (r * self.inv_principal[i][:, None, :]) @ r.transpose(0, 2, 1)
                v = lv[i] + self.gravity[i] * dt
                sides.append((self.inv_mass[i], inv_i, v, av[i], pivot[h] - pos[i]))
            lam[h] = sequential_impulses(sides, (pivots[1] - pivots[0])[h], axes[h], err[h], dt, moved=moved)
            self._push(np.flatnonzero(self.free[h]), ic[h], sides[1], moved[2:], rot, pos, dt)
            lam[self.free] = 0.0  # pushed whole, its pivot rows too
        return (axes * lam[:, :, None]).sum(1) / dt

    def _push(self, which, child, before, after, rot, pos, dt: float) -> None:
        """The free-pivot joints ``which`` (of the held ones): their children's force and torque
        that leave them moving as Bullet's solve of their rows does (``after``: velocities,
        angular velocities; ``before``: the solve's inputs)."""
        for q in which:
            c = child[q]
            b, r = self.bodies[c], rot[c]
            inertia = (r / np.maximum(self.inv_principal[c], 1e-300)[None, :]) @ r.T
            force = (after[0][q] - before[2][q]) / self.inv_mass[c] / dt
            torque = inertia @ (after[1][q] - before[3][q]) / dt
            pb.applyExternalForce(
                b.uid, b.link, force.tolist(), pos[c].tolist(), pb.WORLD_FRAME, physicsClientId=self.cid
            )
            pb.applyExternalTorque(b.uid, b.link, torque.tolist(), pb.WORLD_FRAME, physicsClientId=self.cid)

    def in_frame_a(self, pos, rot, lv, av, r_a, r_b, dt: float) -> np.ndarray:
        """torques() of the joints these play in their frames A, ``r_a`` and ``r_b`` every joint's."""
        c = self.index
        return (r_a[c].transpose(0, 2, 1) @ self.torques(pos, rot, lv, av, r_a[c], r_b[c], dt)[:, :, None])[..., 0]
