"""The objects of a MuJoCo world, with the same queries as the PyBullet runner's: bodies
(world_matrix/com_position/state/force/torque), articulations (records, targets, drive),
ghosts, constraint actuators and proximity sensors."""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np

from ..rotations import invert, matrix_to_quat
from ..world import EngineBody


@dataclass(eq=False)
class MjBody(EngineBody):
    """One ADF body in MuJoCo; the same queries as the PyBullet SimBody."""

    key: str
    body: object
    model: object
    mass: float
    com_in_body: np.ndarray
    link_in_body: np.ndarray
    id: int
    world: object = None
    articulation: object = None
    gravity: np.ndarray | None = None
    has_collision: bool = True

    def __post_init__(self) -> None:
        self._body_in_link = invert(self.link_in_body)

    def world_matrix(self) -> np.ndarray:
        """Pose of the ADF body frame in the world, 4×4."""
        d = self.world.data
        t = np.eye(4)
        t[:3, :3] = d.xmat[self.id].reshape(3, 3)
        t[:3, 3] = d.xpos[self.id]
        return t @ self._body_in_link

    def state(self, velocity: bool = True):
        """(position, quaternion x y z w, linear velocity, angular velocity) of the COM frame."""
        t = self.world_matrix() @ self.com_in_body
        p, q = tuple(t[:3, 3]), tuple(matrix_to_quat(t[:3, :3]))
        if not velocity:
            return p, q, None, None
        v = np.zeros(6)
        mujoco.mj_objectVelocity(self.world.model, self.world.data, mujoco.mjtObj.mjOBJ_BODY, self.id, v, 0)
        return p, q, tuple(v[3:]), tuple(v[:3])

    def com_position(self):
        return tuple((self.world_matrix() @ self.com_in_body)[:3, 3])

    def force(self, f, at) -> None:
        """A world-frame force at point ``at`` for the next control step (it wakes a sleeping tree)."""
        f = np.asarray(f, float)
        xf = self.world.data.xfrc_applied[self.id]
        xf[:3] += f
        xf[3:] += np.cross(np.asarray(at, float) - self.world.data.xipos[self.id], f)
        self.world._xfrc_dirty = True

    def torque(self, t) -> None:
        self.world.data.xfrc_applied[self.id][3:] += np.asarray(t, float)
        self.world._xfrc_dirty = True


class MjArticulation:
    """A tree of revolute/prismatic(/fixed) joints under one root, as PSM reads it: records
    (joint, kind, parent, child) in depth-first order, position targets, drive() (the joint
    equalities of drives.py: q - qpos0 = eq_data[0]; off until driven, free())."""

    def __init__(self, world, root, records):
        self.world, self.root, self.records = world, root, records
        self.uid = None
        self.joint_names = [r[0].identifier for r in records]
        self.kinds = [r[1] for r in records]
        m = world.model
        self.qadr = np.array([m.jnt_qposadr[r[4]] if r[4] >= 0 else -1 for r in records])
        self.vadr = np.array([m.jnt_dofadr[r[4]] if r[4] >= 0 else -1 for r in records])
        self.eqs = np.array([r[5] for r in records])  # the drive equality of each joint, -1: none
        driven = self.eqs >= 0
        self._eq, self._q0 = self.eqs[driven], m.qpos0[self.qadr[driven]]
        self._driven = np.flatnonzero(driven)
        self.targets = [float(world.data.qpos[a]) if a >= 0 else 0.0 for a in self.qadr]
        self.efforts = False  # a drive is off for an effort command (MujocoWorld.drive_joints)

    def joint_values(self) -> list[float]:
        return [float(self.world.data.qpos[a]) if a >= 0 else 0.0 for a in self.qadr]

    @property
    def held(self) -> bool:
        """Whether a drive holds one of its joints (``drive``, or a joint's motor command)."""
        return bool(np.any(self.world.data.eq_active[self._eq]))

    def retarget(self) -> None:
        """The drives' targets from ``targets`` (a drive switched off stays off)."""
        t = np.asarray(self.targets, dtype=float)[self._driven]
        self.world.model.eq_data[self._eq, 0] = t - self._q0

    def drive(self) -> None:
        """Every drive holds its target (one switched off for an effort command is on again)."""
        self.retarget()
        if self.efforts:
            d = self.world.data
            d.eq_active[self._eq] = 1
            d.qfrc_applied[self.vadr[self._driven]] = 0.0
            self.efforts = False

    def free(self) -> None:
        """Every drive off until ``drive`` or a joint command: AMBF builds its joints' motors
        disabled and turns one on only for a position or velocity command."""
        d = self.world.data
        d.eq_active[self._eq] = 0
        d.qfrc_applied[self.vadr[self._driven]] = 0.0
        self.efforts = True


@dataclass(eq=False)
class MjGhost:
    key: str
    ghost: object
    parent: MjBody | None
    geoms: np.ndarray
    friction: bool = False
    overlapping: list = field(default_factory=list)
    pose_in_parent: np.ndarray | None = None  # the ghost's frame in its parent's ADF body frame (or the world)
    points: list = field(default_factory=list)  # (body, penetrating contact points) under AMBF's rule, last step


@dataclass(eq=False)
class MjActuator:
    key: str
    actuator: object
    parent: MjBody
    eq: int
    location: np.ndarray
    target: MjBody | None = None
    constraint: object = None


@dataclass(eq=False)
class MjSensor:
    """A proximity sensor: rays from ``starts`` to ``ends`` in its frame (``location`` in the
    parent body frame); ``sensed``: the bodies its rays hit at the last control step."""

    key: str
    sensor: object
    parent: MjBody
    location: np.ndarray
    starts: np.ndarray
    ends: np.ndarray
    sensed: list = field(default_factory=list)
    rays: list = field(default_factory=list)  # per ray: (body hit or None, fraction of the range)
