"""A multibody read as AMBF's chain of btRigidBodies for one physics step of its solver
(runner/chain_rows.py): each link and the base a body at its centre of mass with its
velocities, damped over the step as Bullet damps them and given the step's gravity and the
last step's contact forces; each revolute or prismatic joint a hinge or slider at the link's
joint frame; each hinge or p2p joint closing a loop between two of its links (a parallelogram,
the ECM's remote centre) the btHingeConstraint or btPoint2PointConstraint AMBF makes of it, its
motor off. Only for a multibody whose joints are all revolute or prismatic and whose loops are
closed by hinges or points; anything else is left to the joint-space rows."""

from __future__ import annotations

import math

import numpy as np
import pybullet as pb

from ...model.semantics import JointKind
from ..chain_step import ChainState, ChainStep
from ..loop_rows import loop_joints
from ..rotations import quat_to_matrix
from .articulation import ROTARY
from .chain_loops import find_loops


class ChainModel:
    """What does not change of an articulation's bodies and joints (runner/chain_step.py)."""

    def __init__(self, world, art) -> None:
        cid = world.cid
        self.uid, self.cid = art.uid, cid
        by_link = {sb.link: sb for sb in world.bodies if sb.uid == art.uid}
        n = len(art.records)
        hinges = all(k in (JointKind.REVOLUTE, JointKind.PRISMATIC) for k in art.kinds)
        self.ok = hinges and set(by_link) >= {-1, *range(n)}
        if not self.ok:
            return
        bodies = []
        for link in range(-1, n):
            sb = by_link[link]
            mass, _f, diag = pb.getDynamicsInfo(art.uid, link, physicsClientId=cid)[:3]
            g = sb.gravity if sb.gravity is not None else world.gravity
            bodies.append((sb.body, mass, diag, bool(sb.static), g))
        joints = []
        for k, rec in enumerate(art.records):
            parent = pb.getJointInfo(art.uid, k, physicsClientId=cid)[16]
            joints.append((parent + 1, "revolute" if art.kinds[k] in ROTARY else "prismatic", rec[0]))
        self.loops = find_loops(world, art)
        if self.loops is None:
            self.ok = False
            return
        in_file = {id(j): i for i, j in enumerate(j for m in world.scene.all_models() for j in m.joints)}
        added = sorted(range(n), key=lambda k: in_file.get(id(art.records[k][0]), k))
        # the loops' rows after the chain's own. AMBF adds its joints in the file's order (loops
        # among them), but measured against AMBF under the parity programs (1 s, velocity and
        # position), that order put the corpus PSM 39.9 and 123.6 mm off, the MTM 1.7 and 4.3 mm;
        # after the chain's own 18.8 and 33.2 mm, 1.3 and 2.5 mm (the ECM 1.5-1.6 mm either way)
        added += range(n, n + len(self.loops))
        self.core = ChainStep(world.dt, bodies, joints, added)
        self.kinds = [kind for _p, kind, _j in joints]

    def velocities(
        self, motors: dict[int, tuple[float, float, float]], efforts: dict[int, float], step: int, ghosted=None
    ) -> np.ndarray:
        """The joints' velocities (by record index) after one step of AMBF's solver (physics
        step ``step``), with the motors ``motors`` (record index -> target, cfm, max impulse) on
        and the joints' ``efforts`` (record index -> N·m or N) pushing their two bodies apart."""
        uid, cid = self.uid, self.cid
        n = len(self.kinds)
        links = pb.getLinkStates(uid, list(range(n)), 1, 1, physicsClientId=cid)
        base_p, base_q = pb.getBasePositionAndOrientation(uid, physicsClientId=cid)
        base_v, base_w = pb.getBaseVelocity(uid, physicsClientId=cid)
        frames = [(base_p, base_q, base_v, base_w)] + [(s[0], s[1], s[6], s[7]) for s in links]
        states = pb.getJointStates(uid, list(range(n)), physicsClientId=cid)
        link_rots = quat_to_matrix(np.array([s[5] for s in links]))  # the link frames: the children's joint frames
        joints = []
        for kind, rot, s, link in zip(self.kinds, link_rots, states, links):
            qk = s[0]
            if kind == "revolute":  # the parent's joint frame is the child's turned back by q
                axis, y = rot[:, 2], rot @ np.array([math.sin(qk), math.cos(qk), 0.0])
            else:
                axis, y = rot[:, 0], rot[:, 1]
            joints.append((np.asarray(link[4], dtype=float), axis, y, qk, s[1]))
        state = ChainState(
            np.array([f[0] for f in frames], dtype=float),
            quat_to_matrix(np.array([f[1] for f in frames])),
            np.array([f[2] for f in frames], dtype=float),
            np.array([f[3] for f in frames], dtype=float),
            joints,
            _contact_pushes(uid, cid),
            ghosted or {},
        )
        loops = self.loops

        def closing(bodies, coms, rots, drift):
            return loop_joints(loops, bodies, coms, rots, drift)

        return self.core.velocities(state, motors, efforts, step, closing)


def _contact_pushes(uid: int, cid: int) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """(body index, force, point) of every contact on the multibody ``uid`` in the last step:
    the normal force and both friction forces, on each of its links a contact touches. The chain
    steps only where each stepSimulation is one physics step (control_substeps 1, or the stops
    stepping them one by one), where PyBullet's reading is the force in newtons
    (``PyBulletWorld.physics_steps_a_call`` is 1 there)."""
    out = []
    for c in pb.getContactPoints(bodyA=uid, physicsClientId=cid):
        force = c[9] * np.asarray(c[7]) + c[10] * np.asarray(c[11]) + c[12] * np.asarray(c[13])
        if c[1] == uid:
            out.append((c[3] + 1, force, np.asarray(c[5])))
        if c[2] == uid:
            out.append((c[4] + 1, -force, np.asarray(c[6])))
    return out
