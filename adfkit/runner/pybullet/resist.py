"""Resistance sensors in PyBullet, as AMBF plays them (the forces: ../resistance.py): after each
physics step every sensor casts its rays and works out its forces, applied over the next physics
step (AMBF updates its sensors after each world update, a physics step in parity's harness, and
Bullet holds a force until the next stepSimulation ends); the rays leave from the parent's motion
state, a physics step behind, the forces from its pose now, as in AMBF."""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ...model.semantics import DEFAULT_SENSOR_RANGE
from ..resistance import Body, missed, ray_force
from ..rotations import invert, rotation_exp

MAX_HITS = 8  # hits looked through past the parent


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
            t = _motion_state(s.parent, dt) @ invert(s.parent.com_in_body) @ s.location
            a_ = (t[:3, :3] @ s.starts.T).T + t[:3, 3]
            b_ = (t[:3, :3] @ s.ends.T).T + t[:3, 3]
            hits = pb.rayTestBatch(a_.tolist(), b_.tolist(), physicsClientId=w.cid)
            dirs = (s.ends - s.starts) / max(float(s.sensor.range or DEFAULT_SENSOR_RANGE), 1e-12)
            a = None
            for i, h in enumerate(hits):
                st = s.states[i]
                sb = w._lookup.get((h[0], h[1]))
                if sb is s.parent:  # PyBullet's ray from inside the parent meets it at 0; AMBF's does not
                    h, sb = _past_parent(w, s.parent, a_[i], b_[i])
                if sb is None:
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


def _past_parent(w, parent, start, end) -> tuple:
    """The nearest hit of a ray that is not on ``parent`` (rayTestBatch's reportHitNumber gives
    the hits unsorted), and its body; (None, None) if none."""
    best, body = None, None
    for k in range(MAX_HITS):
        h = pb.rayTestBatch([list(start)], [list(end)], reportHitNumber=k, physicsClientId=w.cid)[0]
        if h[0] < 0:
            break
        sb = w._lookup.get((h[0], h[1]))
        if sb is not None and sb is not parent and (best is None or h[2] < best[2]):
            best, body = h, sb
    return best, body


def _motion_state(sb, dt: float) -> np.ndarray:
    """The parent's COM frame as AMBF casts the rays from it: its motion state, which Bullet's
    latency interpolation keeps one physics step behind (the pose integrated back by -dt at the
    step's velocities; the parity plugin's sample() says the same of AMBF's published poses)."""
    p, q, v, w = sb.state()
    m = np.eye(4)
    m[:3, :3] = rotation_exp(-np.array(w) * dt) @ np.array(pb.getMatrixFromQuaternion(q)).reshape(3, 3)
    m[:3, 3] = np.array(p) - np.array(v) * dt
    return m


def _body(sb) -> Body:
    p, q, v, w = sb.state()
    return Body(np.array(p), np.array(pb.getMatrixFromQuaternion(q)).reshape(3, 3), np.array(v), np.array(w))
