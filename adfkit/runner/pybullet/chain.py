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
from ..chain_rows import Body, Joint, cross3, joint_velocities, solve
from ..damping import decay_rates
from ..joint_commands import AMBF_JOINT_ERP, limits_of
from ..rotations import quat_to_matrix
from .articulation import ROTARY
from .chain_loops import find_loops, loop_joints


class ChainModel:
    """What does not change of an articulation's bodies and joints."""

    def __init__(self, world, art) -> None:
        cid = world.cid
        self.uid, self.cid, self.dt = art.uid, cid, world.dt
        by_link = {sb.link: sb for sb in world.bodies if sb.uid == art.uid}
        n = len(art.records)
        hinges = all(k in (JointKind.REVOLUTE, JointKind.PRISMATIC) for k in art.kinds)
        self.ok = hinges and set(by_link) >= {-1, *range(n)}
        if not self.ok:
            return
        self.inv_mass, self.inv_inertia, self.inertia, self.decay, self.gravity = [], [], [], [], []
        for link in range(-1, n):
            sb = by_link[link]
            mass, _f, diag = pb.getDynamicsInfo(art.uid, link, physicsClientId=cid)[:3]
            static = bool(sb.static) or mass <= 0.0
            self.inv_mass.append(0.0 if static else 1.0 / mass)
            self.inv_inertia.append(np.array([0.0 if static or d <= 0.0 else 1.0 / d for d in diag]))
            self.inertia.append(np.zeros(3) if static else np.asarray(diag, dtype=float))
            lin, ang = decay_rates(sb.body)
            self.decay.append((math.exp(-lin * world.dt), math.exp(-ang * world.dt)))
            g = sb.gravity if sb.gravity is not None else world.gravity
            self.gravity.append(np.zeros(3) if static else np.asarray(g, dtype=float) * world.dt)
        # what AMBF's bodies carry apart from the joints' motion, which the multibody cannot:
        # their velocities (linear, angular) and their displacement (position, small turn)
        # off where the joints put them, both left by ten iterations that did not settle
        self.apart = np.zeros((n + 1, 6))
        self.drift = np.zeros((n + 1, 6))
        self.step = -2  # the physics step it was last played at: a step missed, nothing is carried
        self.joints = []  # (parent body, kind, limits, erp)
        for k, rec in enumerate(art.records):
            joint = rec[0]
            parent = pb.getJointInfo(art.uid, k, physicsClientId=cid)[16]
            kind = "revolute" if art.kinds[k] in ROTARY else "prismatic"
            self.joints.append((parent + 1, kind, limits_of(joint), _erp(joint)))
        self.loops = find_loops(world, art)
        if self.loops is None:
            self.ok = False
            return
        in_file = {id(j): i for i, j in enumerate(j for m in world.scene.all_models() for j in m.joints)}
        self.added = sorted(range(n), key=lambda k: in_file.get(id(art.records[k][0]), k))
        # the loops' rows after the chain's own. AMBF adds its joints in the file's order (loops
        # among them), but measured against AMBF under the parity programs (1 s, velocity and
        # position), that order put the corpus PSM 39.9 and 123.6 mm off, the MTM 1.7 and 4.3 mm;
        # after the chain's own 18.8 and 33.2 mm, 1.3 and 2.5 mm (the ECM 1.5-1.6 mm either way)
        self.added += range(n, n + len(self.loops))

    def _contacts(self, bodies, coms) -> None:
        """The contacts' impulses of the last step given to the chain's bodies for this one:
        AMBF solves its contact rows with the joints' rows, so its motors do not push through a
        contact; the chain's rows see the contact as the push it gave (the corpus ECM's yaw link
        on the floor under a velocity program: 51.8 mm from AMBF without it, 8.2 mm with it)."""
        for k, force, at in _contact_pushes(self.uid, self.cid):
            bd = bodies[k]
            if bd.inv_mass > 0.0:
                bd.v = bd.v + force * self.dt * bd.inv_mass
                bd.w = bd.w + bd.inv_inertia @ cross3(at - coms[k], force) * self.dt

    def velocities(
        self, motors: dict[int, tuple[float, float, float]], efforts: dict[int, float], step: int
    ) -> np.ndarray:
        """The joints' velocities (by record index) after one step of AMBF's solver (physics
        step ``step``), with the motors ``motors`` (record index -> target, cfm, max impulse) on
        and the joints' ``efforts`` (record index -> N·m or N) pushing their two bodies apart."""
        if step != self.step + 1:
            self.apart[:] = 0.0
            self.drift[:] = 0.0
        self.step = step
        uid, cid = self.uid, self.cid
        n = len(self.joints)
        links = pb.getLinkStates(uid, list(range(n)), 1, 1, physicsClientId=cid)
        base_p, base_q = pb.getBasePositionAndOrientation(uid, physicsClientId=cid)
        base_v, base_w = pb.getBaseVelocity(uid, physicsClientId=cid)
        frames = [(base_p, base_q, base_v, base_w)] + [(s[0], s[1], s[6], s[7]) for s in links]
        bodies, coms = [], []
        rots = quat_to_matrix(np.array([f[1] for f in frames]))
        # the carried state is kept in each body's own frame: it turns with the body
        apart, drift = _turned(rots, self.apart), _turned(rots, self.drift)
        for k, (p, _q, v, w) in enumerate(frames):
            rot = rots[k]
            dv, dw = self.decay[k]
            moving = self.inv_mass[k] > 0.0
            coms.append(np.asarray(p, dtype=float))
            bodies.append(
                Body(
                    coms[-1] + drift[k, :3],
                    self.inv_mass[k],
                    rot @ np.diag(self.inv_inertia[k]) @ rot.T,
                    (np.asarray(v, dtype=float) + apart[k, :3]) * dv + self.gravity[k] if moving else np.zeros(3),
                    (np.asarray(w, dtype=float) + apart[k, 3:]) * dw if moving else np.zeros(3),
                    rot @ np.diag(self.inertia[k]) @ rot.T,
                )
            )
        states = pb.getJointStates(uid, list(range(n)), physicsClientId=cid)
        joints, fk = [], []  # fk: the joints where the multibody has them
        d = drift
        link_rots = quat_to_matrix(np.array([s[5] for s in links]))  # the link frames: the children's joint frames
        for k, ((parent, kind, lim, erp), s) in enumerate(zip(self.joints, states)):
            rot = link_rots[k]
            qk = s[0]
            if kind == "revolute":  # the parent's joint frame is the child's turned back by q
                axis, y = rot[:, 2], rot @ np.array([math.sin(qk), math.cos(qk), 0.0])
            else:
                axis, y = rot[:, 0], rot[:, 1]
            pivot = np.asarray(links[k][4], dtype=float)
            a, b = parent, k + 1
            # each body's pivot and axis where its drift has taken them
            pivot_b = pivot + d[b, :3] + cross3(d[b, 3:], pivot - coms[b])
            pivot_a = pivot + d[a, :3] + cross3(d[a, 3:], pivot - coms[a])
            turn = (d[b, 3:] - d[a, 3:]) @ axis
            axis_a = axis + cross3(d[a, 3:], axis)
            axis_b = axis + cross3(d[b, 3:], axis)
            axis_a /= np.linalg.norm(axis_a)
            axis_b /= np.linalg.norm(axis_b)
            gap = (pivot_b - pivot_a) @ axis_a
            position = qk + (turn if kind == "revolute" else gap)
            jt = Joint(kind, a, b, pivot_b, axis_a, y, position, s[1], erp, lim, motors.get(k))
            fk.append(Joint(kind, a, b, pivot, axis, y, qk, s[1], erp))
            jt.pivot_a, jt.axis_b, jt.twist = pivot_a, axis_b, turn
            if kind == "revolute":  # the limit's bounce reads the bodies' own (damped) turn
                jt.velocity = float((bodies[b].w - bodies[a].w) @ axis_a)
            joints.append(jt)
        joints += loop_joints(self.loops, bodies, coms, rots, d)
        self._contacts(bodies, coms)
        for k, effort in efforts.items():  # AMBF's commandEffort: the torque (force) on both bodies
            jt = joints[k]
            for b, sign in ((jt.child, 1.0), (jt.parent, -1.0)):
                bd = bodies[b]
                if bd.inv_mass > 0.0:
                    if jt.kind == "revolute":
                        bd.w = bd.w + sign * effort * self.dt * (bd.inv_inertia @ jt.axis)
                    else:
                        bd.v = bd.v + sign * effort * self.dt * bd.inv_mass * jt.axis
        after = solve(bodies, joints, self.dt, self.added)
        # read as the multibody's joints, which carry the bodies where their joints put them
        # (what is apart is measured from there: the next step starts from the same velocities)
        at = [Body(c, bd.inv_mass, bd.inv_inertia, bd.v, bd.w, bd.inertia) for c, bd in zip(coms, bodies)]
        qd, together = joint_velocities(at, fk, after)
        apart = after - together
        apart[[k for k in range(n + 1) if self.inv_mass[k] <= 0.0]] = 0.0
        drift += apart * self.dt
        back = rots.transpose(0, 2, 1)
        self.apart, self.drift = _turned(back, apart), _turned(back, drift)
        return qd


def _contact_pushes(uid: int, cid: int) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """(body index, force, point) of every contact on the multibody ``uid`` in the last step:
    the normal force and both friction forces, on each of its links a contact touches."""
    out = []
    for c in pb.getContactPoints(bodyA=uid, physicsClientId=cid):
        force = c[9] * np.asarray(c[7]) + c[10] * np.asarray(c[11]) + c[12] * np.asarray(c[13])
        if c[1] == uid:
            out.append((c[3] + 1, force, np.asarray(c[5])))
        if c[2] == uid:
            out.append((c[4] + 1, -force, np.asarray(c[6])))
    return out


def _erp(joint) -> float:
    return joint.joint_erp if joint.joint_erp is not None else AMBF_JOINT_ERP


def _turned(rots: np.ndarray, six: np.ndarray) -> np.ndarray:
    """Each row of ``six`` (n, 6: two 3-vectors) turned by its body's rotation ``rots`` (n, 3, 3)."""
    return (rots @ six.reshape(-1, 2, 3).transpose(0, 2, 1)).transpose(0, 2, 1).reshape(-1, 6)
