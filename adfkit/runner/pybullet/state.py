"""Snapshots and placement of a SimWorld (a mixin of world.SimWorld): fast resets for tasks
and Gymnasium environments, and the small queries they need.

restore_state uses Bullet's restoreState (exact, contact caches included) while no collision
filter pair has changed since the snapshot; PyBullet cannot restore a state once one has (a
grasp toggles the pairs between the jaws and what they hold), so the snapshot also keeps every
body's and joint's state, restored one by one in that case (contacts then start afresh).
"""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ..rotations import matrix_to_pq


class WorldState:
    def save_state(self) -> int:
        """Snapshot the simulation in memory (Bullet's saveState, and every free body's and
        multibody base's pose and velocity, every joint's position, velocity and motor target,
        the clock); returns an id for restore_state."""
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
        self._snapshots = getattr(self, "_snapshots", [])
        bullet = pb.saveState(physicsClientId=cid)
        self._snapshots.append((bases, joints, [list(a.targets) for a in self.articulations], self.steps, bullet))
        return len(self._snapshots) - 1

    def restore_state(self, sid: int) -> None:
        """Put the world back to snapshot ``sid``: every grasp released, bodies and joints at
        their saved states, the joint motors at their saved targets, the clock at its time."""
        cid = self.cid
        for a in self.actuators:
            self.release(a)
        bases, joints, targets, steps, bullet = self._snapshots[sid]
        try:  # exact, contact caches too, while no collision pair changed since the snapshot
            pb.restoreState(stateId=bullet, physicsClientId=cid)
            bases, joints = [], [[] for _ in self.articulations]
        except pb.error:  # Bullet refuses once a collision filter pair changed (a grasp): per body
            pass
        for uid, p, q, v, w in bases:
            pb.resetBasePositionAndOrientation(uid, p, q, physicsClientId=cid)
            pb.resetBaseVelocity(uid, v, w, physicsClientId=cid)
        for art, states, t in zip(self.articulations, joints, targets):
            for i, (q, v) in enumerate(states):
                pb.resetJointState(art.uid, i, q, v, physicsClientId=cid)
            art.targets[:] = t
            art.drive()
        self.steps, self.sim_time = steps, steps * self.dt

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
