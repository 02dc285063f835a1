"""Resistance sensors in MuJoCo, as AMBF plays them (the forces: ../resistance.py; PyBullet's side:
../pybullet/resist.py): after each physics step every sensor casts its rays with ``mj_ray`` and
works out its forces, which ride in ``xfrc_applied`` over the next physics step (AMBF updates its
sensors after each world update, a physics step in parity's harness, and Bullet holds a force
until the next stepSimulation ends). The rays leave from the parent's motion state, a physics step
behind (AMBF's getCOMTransform reads it), and see past the parent's own geoms (Bullet's ray does
not meet a shape it starts inside); the forces use the bodies' poses now, as in AMBF."""

from __future__ import annotations

import mujoco
import numpy as np

from ...model.semantics import DEFAULT_SENSOR_RANGE
from ..plan import SENSOR_TYPES
from ..resistance import Body, RayState, ResistanceParams, missed, ray_force
from ..rotations import invert, rotation_exp
from .after_step import AfterStep


class MujocoResistance(AfterStep):
    def __init__(self, world) -> None:
        """The world's played resistance sensors (played_sensors keeps them under AMBF's bodies)."""
        super().__init__(world)
        self.sensors = [
            (s, ResistanceParams.of(s.sensor), [RayState() for _ in s.starts])
            for s in world.sensors
            if SENSOR_TYPES.get(s.sensor.type) == "resistance"
        ]
        self._hit = np.zeros(1, dtype=np.int32)
        self._normal = np.zeros(3)
        self._vel = np.zeros(6)

    def __bool__(self) -> bool:
        return bool(self.sensors)

    def update(self, dt: float) -> None:
        """After a physics step (its poses computed): each sensor's rays and forces, for the next."""
        w = self.world
        m, d = w.model, w.data
        mujoco.mj_comPos(m, d)
        mujoco.mj_comVel(m, d)
        self._pending = []
        for s, params, states in self.sensors:
            a = self._body(s.parent)
            t = _motion_state(a, dt) @ invert(s.parent.com_in_body) @ s.location
            starts = s.starts @ t[:3, :3].T + t[:3, 3]
            ends = s.ends @ t[:3, :3].T + t[:3, 3]
            dirs = (s.ends - s.starts) / max(float(s.sensor.range or DEFAULT_SENSOR_RANGE), 1e-12)
            for i, st in enumerate(states):
                p, vec = starts[i], ends[i] - starts[i]
                x = -1.0
                if float(vec @ vec) > 1e-24:  # a ray of no length meets nothing (mj_ray refuses it)
                    x = mujoco.mj_ray(m, d, p, vec, w._ray_groups, 1, s.parent.id, self._hit, self._normal)
                sb = (
                    w._body_of_id.get(int(m.geom_bodyid[self._hit[0]]))
                    if 0.0 <= x <= 1.0 and self._hit[0] >= 0
                    else None
                )
                if sb is None:
                    missed(st)
                    continue
                point = p + vec * x
                fw = ray_force(params, st, dirs[i], a, self._body(sb), point, self._normal.copy(), 1.0 - x)
                if not s.parent.static:
                    self._add(s.parent.id, -fw, point)
                if not sb.static:
                    self._add(sb.id, fw, point)

    def _add(self, bid: int, f: np.ndarray, at: np.ndarray) -> None:
        torque = np.cross(at - self.world.data.xipos[bid], f)  # about MuJoCo's COM
        self._pending.append((bid, np.concatenate([f, torque])))

    def _body(self, sb) -> Body:
        """``sb``'s AMBF COM frame and its velocities there (mj_objectVelocity gives MuJoCo's COM's)."""
        m, d = self.world.model, self.world.data
        t = sb.world_matrix() @ sb.com_in_body
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, sb.id, self._vel, 0)
        ang = self._vel[:3].copy()
        return Body(t[:3, 3], t[:3, :3], self._vel[3:] + np.cross(ang, t[:3, 3] - d.xipos[sb.id]), ang)


def _motion_state(a: Body, dt: float) -> np.ndarray:
    """The COM frame ``a`` as Bullet's motion state holds it, a physics step behind (the pose
    integrated back by -dt at the step's velocities, as pybullet/resist.py does)."""
    t = np.eye(4)
    t[:3, :3] = rotation_exp(-a.w * dt) @ a.rot
    t[:3, 3] = a.com - a.v * dt
    return t
