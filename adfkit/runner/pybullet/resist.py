"""Resistance sensors in PyBullet, as AMBF plays them (the forces: ../resistance.py): after each
physics step every sensor casts its rays and works out its forces, applied over the next physics
step (AMBF updates its sensors after each world update, a physics step in parity's harness, and
Bullet holds a force until the next stepSimulation ends)."""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ...model.semantics import DEFAULT_SENSOR_RANGE
from ..resistance import Body, missed, ray_force
from ..rotations import invert


class PyBulletResistance:
    def __init__(self, world, sensors: list) -> None:
        self.world = world
        self.sensors = sensors  # SimSensors with ``resist`` set
        self._pending: list = []  # (uid, link, force, at), world frame

    def __bool__(self) -> bool:
        return bool(self.sensors)

    def update(self, dt: float) -> None:
        """After a physics step: each sensor's rays and forces, applied over the next (push)."""
        self._pending = []
        w = self.world
        for s in self.sensors:
            t = w._frame(s.parent) @ invert(s.parent.com_in_body) @ s.location
            a_ = (t[:3, :3] @ s.starts.T).T + t[:3, 3]
            b_ = (t[:3, :3] @ s.ends.T).T + t[:3, 3]
            hits = pb.rayTestBatch(a_.tolist(), b_.tolist(), physicsClientId=w.cid)
            dirs = (s.ends - s.starts) / max(float(s.sensor.range or DEFAULT_SENSOR_RANGE), 1e-12)
            a = None
            for i, h in enumerate(hits):
                st = s.states[i]
                sb = w._lookup.get((h[0], h[1]))
                if sb is None or sb is s.parent:
                    missed(st)
                    continue
                a = a or _body(s.parent)
                point = np.array(h[3])
                fw = ray_force(s.resist, st, dirs[i], a, _body(sb), point, np.array(h[4]), 1.0 - float(h[2]))
                if not s.parent.static:
                    self._pending.append((s.parent.uid, s.parent.link, (-fw).tolist(), h[3]))
                if not sb.static:
                    self._pending.append((sb.uid, sb.link, fw.tolist(), h[3]))

    def push(self) -> None:
        """Before a physics step: the forces the last one left."""
        for uid, link, force, at in self._pending:
            pb.applyExternalForce(uid, link, force, at, pb.WORLD_FRAME, physicsClientId=self.world.cid)


def _body(sb) -> Body:
    p, q, v, w = sb.state()
    return Body(np.array(p), np.array(pb.getMatrixFromQuaternion(q)).reshape(3, 3), np.array(v), np.array(w))
