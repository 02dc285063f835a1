"""Snapshots and placement of a SimWorld (a mixin of world.SimWorld): fast resets for tasks
and Gymnasium environments, and the small queries they need.

A snapshot is restored two ways. Into the world that took it: Bullet's restoreState (contact
caches included) while no collision filter pair has changed since the snapshot; PyBullet cannot
restore a state once one has (a grasp toggles the pairs between the jaws and what they hold), so
the snapshot also keeps every body's and joint's state, restored one by one in that case (contacts
then start afresh). Either way the world keeps state that no restore brings back (the order of
its contact manifolds, which sets the solver's order), so steps played again after a restore
part a little from the first play: ~1e-8 m on the suture; under AMBF's bodies, whose broadphase
pairs stay unsorted (world.py), at most 1.6e-8 m on a nine-box stack over the second after the
restore and 1.3e-7 m on the corpus's suturing set (sorted, the stack parted by 0.6 mm). Into a
fresh world built from the same scene with the same set-up (the same bodies, collision filters
and constraints, made in the same order): the snapshot's Bullet file (``saveBullet``), contact
points included; a fresh world holds nothing else, so two such restores followed by the same
steps agree bit for bit.
"""

from __future__ import annotations

import os
import weakref
from dataclasses import dataclass

import numpy as np
import pybullet as pb

from ... import scratch
from ..rotations import matrix_to_pq
from . import bullet_globals


@dataclass(eq=False)
class Snapshot:
    """What save_state took: every free body's and multibody base's pose and velocity, every
    joint's position and velocity, the joint motors' targets and whether they hold them, the clock, Bullet's in-memory state
    (``state_id``, valid in the world that took it: ``world``, a weak reference) and its Bullet
    file (``bullet``, bytes, restorable in a fresh world of the same scene)."""

    world: weakref.ref
    bases: list
    joints: list
    targets: list
    steps: int
    state_id: int
    bullet: bytes
    held: list


class WorldState:
    def save_state(self) -> Snapshot:
        """Snapshot the simulation (see Snapshot) for restore_state, in this world or in a fresh
        world built from the same scene with the same set-up."""
        cid = self.cid
        bases = []
        for sb in self.bodies:
            if sb.link < 0 and sb.uid is not None and sb.uid >= 0:
                p, q = pb.getBasePositionAndOrientation(sb.uid, physicsClientId=cid)
                v, w = pb.getBaseVelocity(sb.uid, physicsClientId=cid)
                bases.append((sb.uid, p, q, v, w))
        joints = []
        for art in self.articulations:
            n = len(art.records)
            states = pb.getJointStates(art.uid, list(range(n)), physicsClientId=cid) if n else []
            joints.append([(s[0], s[1]) for s in states])
        with scratch.temporary_directory("adfkit-state-") as tmp:
            path = os.path.join(tmp, "state.bullet")
            pb.saveBullet(path, physicsClientId=cid)
            with open(path, "rb") as f:
                bullet = f.read()
        state_id = pb.saveState(physicsClientId=cid)
        targets = [list(a.targets) for a in self.articulations]
        held = [a.held for a in self.articulations]
        return Snapshot(weakref.ref(self), bases, joints, targets, self.steps, state_id, bullet, held)

    def restore_state(self, snap: Snapshot) -> None:
        """Put the world back to ``snap``: every grasp released, bodies and joints at their saved
        states, the joint motors at their saved targets, the clock at its time. ``snap`` may come
        from another world built from the same scene with the same set-up, as long as this world
        has not been stepped (restored exactly, see the module docstring); a world that does not
        match it is a ValueError."""
        for a in self.actuators:
            self.release(a)
        for g in self.ghosts:  # a restore puts the ghosts back too: the next control step places them
            g.placed_at = None
        self._pairs_epoch += 1
        self.limit_chains.reset()  # its motors and opened limits belong to the motion left behind
        bullet_globals.use(self.contact_threshold, self.cid, self.broadphase_margin)  # the restore detects contacts
        if snap.world() is self:
            self._restore_own(snap)
        else:
            self._restore_file(snap)
        for art, t, held in zip(self.articulations, snap.targets, snap.held):
            art.targets[:] = t
            if held:
                art.drive()
            else:
                art.free()
        self.steps, self.sim_time = snap.steps, snap.steps * self.dt

    def _restore_own(self, snap: Snapshot) -> None:
        cid = self.cid
        bases, joints = snap.bases, snap.joints
        try:  # contact caches too, while no collision pair changed since the snapshot
            pb.restoreState(stateId=snap.state_id, physicsClientId=cid)
            bases, joints = [], []
        except pb.error:  # Bullet refuses once a collision filter pair changed (a grasp): per body
            pass
        for uid, p, q, v, w in bases:
            pb.resetBasePositionAndOrientation(uid, p, q, physicsClientId=cid)
            pb.resetBaseVelocity(uid, v, w, physicsClientId=cid)
        for art, states in zip(self.articulations, joints):
            for i, (q, v) in enumerate(states):
                pb.resetJointState(art.uid, i, q, v, physicsClientId=cid)

    def _restore_file(self, snap: Snapshot) -> None:
        if len(snap.bases) != sum(1 for sb in self.bodies if sb.link < 0 and sb.uid is not None and sb.uid >= 0):
            raise ValueError("the snapshot was taken in a world with other bodies")
        with scratch.temporary_directory("adfkit-state-") as tmp:
            path = os.path.join(tmp, "state.bullet")
            with open(path, "wb") as f:
                f.write(snap.bullet)
            try:
                pb.restoreState(fileName=path, physicsClientId=self.cid)
            except pb.error as exc:
                raise ValueError(f"the snapshot does not fit this world (Bullet: {exc})") from None

    def place_body(self, sb, pose: np.ndarray) -> None:
        """Move a free body (its ADF body frame to the 4x4 world ``pose``), at rest; a
        multibody's base moves with move_base."""
        if sb.articulation is not None:
            raise ValueError(f"{sb.key} is part of a multibody; only free bodies can be placed")
        pos, orn = matrix_to_pq(pose @ sb.com_in_body)
        pb.resetBasePositionAndOrientation(sb.uid, pos, orn, physicsClientId=self.cid)
        if not sb.static:
            pb.resetBaseVelocity(sb.uid, [0, 0, 0], [0, 0, 0], physicsClientId=self.cid)

    def grasped(self, psm: str):
        """The body the constraint actuator of ``psm`` holds now, or None."""
        act = next((a for a in self.actuators if psm in a.key or psm in a.parent.key), None)
        return act.target if act is not None else None

    def nearest_point(self, sb, point, reach: float = 0.05):
        """The point of ``sb``'s collision shape nearest ``point`` (world, m), or None when it
        is farther than ``reach``."""
        if getattr(self, "_probe", None) is None:
            shape = pb.createCollisionShape(pb.GEOM_SPHERE, radius=1e-5, physicsClientId=self.cid)
            self._probe = pb.createMultiBody(
                0, shape, -1, [0, 0, 0], useMaximalCoordinates=True, physicsClientId=self.cid
            )
            pb.setCollisionFilterGroupMask(self._probe, -1, 0, 0, physicsClientId=self.cid)
        pb.resetBasePositionAndOrientation(self._probe, list(map(float, point)), [0, 0, 0, 1], physicsClientId=self.cid)
        hits = pb.getClosestPoints(self._probe, sb.uid, reach, -1, sb.link, physicsClientId=self.cid)
        if not hits:
            return None
        return np.array(min(hits, key=lambda h: h[8])[6])
