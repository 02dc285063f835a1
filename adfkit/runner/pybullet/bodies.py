"""Rigid bodies: free (maximal-coordinate) bodies and Featherstone articulations for the
revolute/prismatic trees (adf-format.md §7, §8.2)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pybullet as pb

from ...model.semantics import (
    DEFAULT_ANGULAR_DAMPING,
    DEFAULT_FRICTION_ROLLING,
    DEFAULT_FRICTION_STATIC,
    DEFAULT_LINEAR_DAMPING,
    DEFAULT_RESTITUTION,
    effective_mass,
    inertial_offset,
)
from .. import ambf_bodies
from ..rotations import pose_to_matrix
from ..world import EngineBody
from . import held


@dataclass(eq=False)
class SimBody(EngineBody):
    """One ADF body as PyBullet holds it: (uid, link); link -1 is a base or a free body."""

    key: str
    body: object
    model: object
    mass: float
    com_in_body: np.ndarray  # 4×4, §7.2
    ref_in_body: np.ndarray = None  # PyBullet frame of the body (COM, or the joint frame for a link)
    uid: int = -1
    link: int = -1
    cid: int = 0
    gravity: np.ndarray | None = None
    inertia: tuple = (1.0, 1.0, 1.0)
    articulation: object = None
    body_world_matrix: np.ndarray = None  # the file's `location`
    extra_force: list = field(default_factory=list)
    piece_links: tuple = ()  # more links of the multibody that are this body (a volume's surface pieces)

    @property
    def links(self) -> tuple:
        """Every link of the multibody that is this body."""
        return (self.link, *self.piece_links)

    def state(self, velocity: bool = True):
        """(position, quaternion, linear velocity, angular velocity) of the COM frame; the
        velocities are None when ``velocity`` is False (cheaper for multibody links). The calls take
        their arguments by position (the ghosts ask each control step; keywords cost a tenth of a call)."""
        if self.link < 0:
            p, q = pb.getBasePositionAndOrientation(self.uid, self.cid)
            if not velocity:
                return p, q, None, None
            v, w = pb.getBaseVelocity(self.uid, self.cid)
            return p, q, v, w
        # computeLinkVelocity, computeForwardKinematics
        s = pb.getLinkState(self.uid, self.link, int(velocity), 1, self.cid)
        if not velocity:
            return s[0], s[1], None, None
        return s[0], s[1], s[6], s[7]  # the COM frame: constraint pivots are relative to it

    def com_position(self):
        if self.link < 0:
            return pb.getBasePositionAndOrientation(self.uid, physicsClientId=self.cid)[0]
        return pb.getLinkState(self.uid, self.link, computeForwardKinematics=1, physicsClientId=self.cid)[0]

    def world_matrix(self) -> np.ndarray:
        """Pose of the ADF body frame (the mesh origin) in the world, 4×4."""
        from ..rotations import invert, pose_matrix

        p, q, _, _ = self.state(velocity=False)
        return pose_matrix(p, q) @ invert(self.com_in_body)

    def torque(self, t) -> None:
        held.twist(self.uid, self.link, t, self.cid)

    def force(self, f, at) -> None:
        held.push(self.uid, self.link, f, at, self.cid)


def make_sim_body(key: str, body, model) -> SimBody:
    mass = effective_mass(body)
    com = pose_to_matrix(inertial_offset(body))
    from ...model.semantics import pose_or_identity

    return SimBody(
        key=key,
        body=body,
        model=model,
        mass=max(mass, 0.0),
        com_in_body=com,
        ref_in_body=com,
        body_world_matrix=pose_to_matrix(pose_or_identity(body.location)),
    )


def body_gravity(body, model, world_g: np.ndarray) -> np.ndarray | None:
    """The gravity override of a body (body `gravity` beats model `gravity`, §7.2), or None."""
    g = body.gravity if body.mass is not None and body.gravity is not None else model.gravity
    if g is None:
        return None
    g = np.array(g, dtype=float)
    return None if np.allclose(g, world_g) else g


def set_dynamics(sb: SimBody, ambf_dt: float | None = None) -> None:
    """The body's friction, restitution, damping and inertia; with ``ambf_dt`` (the physics step,
    Options.bodies == "ambf") AMBF's estimated inertia where the file gives none
    (runner/ambf_bodies.py)."""
    b = sb.body
    fr = b.friction
    kw = dict(
        lateralFriction=fr.static if fr is not None and fr.static is not None else DEFAULT_FRICTION_STATIC,
        rollingFriction=fr.rolling if fr is not None and fr.rolling is not None else DEFAULT_FRICTION_ROLLING,
        restitution=b.restitution if b.restitution is not None else DEFAULT_RESTITUTION,
        linearDamping=b.damping.linear
        if b.damping is not None and b.damping.linear is not None
        else DEFAULT_LINEAR_DAMPING,
        angularDamping=b.damping.angular
        if b.damping is not None and b.damping.angular is not None
        else DEFAULT_ANGULAR_DAMPING,
    )
    frozen = ambf_bodies.frozen_inertia(b) if ambf_dt is not None and not sb.static else None
    if (
        not sb.static
        and b.mass is not None
        and b.inertia is not None
        and None not in (b.inertia.ix, b.inertia.iy, b.inertia.iz)
        and min(b.inertia.ix, b.inertia.iy, b.inertia.iz) > 0
    ):
        kw["localInertiaDiagonal"] = [b.inertia.ix, b.inertia.iy, b.inertia.iz]
        kw["mass"] = sb.mass  # PyBullet zeroes a maximal body's mass when only the inertia is given
    elif frozen is not None:
        kw["localInertiaDiagonal"] = list(frozen)  # a moment of 0: AMBF's body never turns about it
        kw["mass"] = sb.mass
    elif ambf_dt is not None and not sb.static and sb.mass > 0:
        estimate = ambf_bodies.estimated_inertia(sb.model, b, sb.com_in_body)
        if estimate is not None:
            kw["localInertiaDiagonal"] = list(estimate)
            kw["mass"] = sb.mass
    pb.changeDynamics(sb.uid, sb.link, physicsClientId=sb.cid, **kw)
    info = pb.getDynamicsInfo(sb.uid, sb.link, physicsClientId=sb.cid)
    sb.inertia = tuple(info[2]) if not sb.static else (0.0, 0.0, 0.0)


def refresh_inertia(cid: int) -> None:
    """Have Bullet take every body's inertia as changeDynamics set it before the first physics step.

    A maximal-coordinate body (a btRigidBody) turns by the world-frame inverse inertia Bullet last
    computed, which it recomputes only when it integrates the body: an inertia set through
    changeDynamics (localInertiaDiagonal) reaches the first physics step as the collision shape's
    own. A thread element given 5e-5 kg·m², turned by its joint's 0.054 N·m spring, spun at
    1720 rad/s after 1 ms, as its 3e-8 kg·m² capsule would, where 1.08 rad/s is its own. AMBF makes
    its bodies with their inertia. One physics step of a nanosecond makes Bullet recompute it, and
    the world's state from before that step is put back (saveState / restoreState): every body
    starts where and as it was. (Not with soft bodies, whose state PyBullet does not save.)"""
    state = pb.saveState(physicsClientId=cid)
    params = pb.getPhysicsEngineParameters(physicsClientId=cid)
    pb.setPhysicsEngineParameter(fixedTimeStep=1e-9, numSubSteps=1, physicsClientId=cid)
    pb.stepSimulation(physicsClientId=cid)
    pb.setPhysicsEngineParameter(
        fixedTimeStep=params["fixedTimeStep"], numSubSteps=params["numSubSteps"], physicsClientId=cid
    )
    pb.restoreState(state, physicsClientId=cid)
    pb.removeState(state, physicsClientId=cid)
