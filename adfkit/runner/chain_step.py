"""One physics step of AMBF's solver on a driven chain, engine-neutral: an articulation read as
AMBF's chain of btRigidBodies (each link and the base a body at its centre of mass with its
velocities, damped over the step as Bullet damps them and given the step's gravity and the last
step's contact forces), its hinges and sliders and the joints closing its loops solved as
runner/chain_rows.py solves them, and the joints' velocities read back out. What AMBF's bodies
carry that a reduced-coordinate articulation cannot is carried from step to step here: their
velocities as the last step left them, in the world's frame (the articulation's are turned with
its links as its joints carry them), and their displacement off where the joints put them, left
by ten iterations that did not settle. The engines read their own state into it
(runner/pybullet/chain.py, runner/mujoco/chain.py)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .chain_rows import Body, Joint, cross3, joint_velocities, solve
from .damping import decay_rates
from .ghost_rules import ghost_velocity
from .joint_commands import AMBF_JOINT_ERP, limits_of


@dataclass
class ChainState:
    """What the engine reads of a chain at a step's start, bodies in chain order (the base
    first, then each joint's child): centres of mass, inertial frames' rotations (n+1, 3, 3),
    linear and angular velocities; per joint its child's joint frame origin, its axis, a
    direction across the axis fixed in the parent (a hinge's fallback), its position and
    velocity; the contacts' pushes (body index, force, point) of the last step; the bodies AMBF's
    ghosts act on before the step (body index -> [(contact points, the ghost parent's velocity)],
    in the ghosts' order: ghost_rules.ghost_velocity, and no gravity in the step)."""

    coms: np.ndarray
    rots: np.ndarray
    v: np.ndarray
    w: np.ndarray
    joints: list[tuple[np.ndarray, np.ndarray, np.ndarray, float, float]]
    pushes: list[tuple[int, np.ndarray, np.ndarray]]
    ghosted: dict[int, list[tuple[int, tuple]]] = field(default_factory=dict)


class ChainStep:
    """A chain's constants (masses, principal inertias, damping, gravity, joints) and what its
    bodies carry from step to step."""

    def __init__(self, dt: float, bodies: list[tuple], joints: list[tuple], added: list[int]) -> None:
        """``bodies``: (ADF body, mass, principal inertia, static, gravity) in chain order;
        ``joints``: (parent body index, "revolute" or "prismatic", ADF joint); ``added``: the
        order the solver takes the joints in (indices past the joints' are the loops')."""
        self.dt = dt
        self.inv_mass, self.inv_inertia, self.inertia, self.decay, self.gravity = [], [], [], [], []
        for body, mass, diag, static, g in bodies:
            static = static or mass <= 0.0
            self.inv_mass.append(0.0 if static else 1.0 / mass)
            self.inv_inertia.append(np.array([0.0 if static or x <= 0.0 else 1.0 / x for x in diag]))
            self.inertia.append(np.zeros(3) if static else np.asarray(diag, dtype=float))
            lin, ang = decay_rates(body)
            self.decay.append((math.exp(-lin * dt), math.exp(-ang * dt)))
            self.gravity.append(np.zeros(3) if static else np.asarray(g, dtype=float) * dt)
        # the principal inertias and their inverses as diagonal matrices, made once
        self.inv_inertia_diag = [np.diag(x) for x in self.inv_inertia]
        self.inertia_diag = [np.diag(x) for x in self.inertia]
        self.joints = [(parent, kind, limits_of(j), _erp(j)) for parent, kind, j in joints]
        self.added = added
        n = len(bodies)
        self.drift = np.zeros((n, 6))
        # the bodies' velocities the last step left (n, 6: linear, angular, in the world's frame)
        self.carried: np.ndarray | None = None
        # the joints' velocities the last step's contacts gave, as its pushes (None: no contact)
        self.contact: np.ndarray | None = None
        self.step = -2  # the physics step it was last played at: a step missed, nothing is carried

    def velocities(
        self,
        state: ChainState,
        motors: dict[int, tuple[float, float, float]],
        efforts: dict[int, float],
        step: int,
        loops: Callable | None = None,
    ) -> np.ndarray:
        """The joints' velocities after one step of AMBF's solver (physics step ``step``), with
        the motors ``motors`` (joint index -> target, cfm, max impulse) on and the joints'
        ``efforts`` (joint index -> N·m or N) pushing their two bodies apart; ``loops(bodies,
        coms, rots, drift)`` gives the joints closing the chain's loops."""
        if step != self.step + 1:
            self.carried = None
            self.drift[:] = 0.0
        self.step = step
        rots, coms = state.rots, state.coms
        # the drift is kept in each body's own frame: it turns with the body
        drift = _turned(rots, self.drift)
        # AMBF's bodies start the step at the velocities the last one left them, in the world's
        # frame: the articulation's, read where its joints have since carried the bodies, are
        # turned with them (a body on a turning joint: its velocity across its arm), which AMBF's
        # rows take out in the step, unsettled in ten iterations
        start = np.concatenate([state.v, state.w], axis=1) if self.carried is None else self.carried
        bodies = []
        for k in range(len(coms)):
            rot = rots[k]
            dv, dw = self.decay[k]
            moving = self.inv_mass[k] > 0.0
            v, w, g = start[k, :3], start[k, 3:], self.gravity[k]
            for points, v_parent in state.ghosted.get(k, ()):  # AMBF's ghosts, after the last step
                v, w = ghost_velocity(v, w, v_parent, points)
                g = 0.0
            bodies.append(
                Body(
                    coms[k] + drift[k, :3],
                    self.inv_mass[k],
                    rot @ self.inv_inertia_diag[k] @ rot.T,
                    v * dv + g if moving else np.zeros(3),
                    gyroscopic(w * dw, rot, self.inertia[k], self.dt) if moving else np.zeros(3),
                    rot @ self.inertia_diag[k] @ rot.T,
                )
            )
        joints, fk = [], []  # fk: the joints where the articulation has them
        d = drift
        for k, ((parent, kind, lim, erp), (pivot, axis, y, qk, qdk)) in enumerate(zip(self.joints, state.joints)):
            a, b = parent, k + 1
            # each body's pivot and axis where its drift has taken them
            pivot_b = pivot + d[b, :3] + cross3(d[b, 3:], pivot - coms[b])
            pivot_a = pivot + d[a, :3] + cross3(d[a, 3:], pivot - coms[a])
            turn = (d[b, 3:] - d[a, 3:]) @ axis
            axis_a = axis + cross3(d[a, 3:], axis)
            axis_b = axis + cross3(d[b, 3:], axis)
            axis_a /= math.sqrt(axis_a @ axis_a)  # np.linalg.norm's sum and root, without its checks
            axis_b /= math.sqrt(axis_b @ axis_b)
            gap = (pivot_b - pivot_a) @ axis_a
            position = qk + (turn if kind == "revolute" else gap)
            jt = Joint(kind, a, b, pivot_b, axis_a, y, position, qdk, erp, lim, motors.get(k))
            fk.append(Joint(kind, a, b, pivot, axis, y, qk, qdk, erp))
            jt.pivot_a, jt.axis_b, jt.twist = pivot_a, axis_b, turn
            if kind == "revolute":  # the limit's bounce reads the bodies' own (damped) turn
                jt.velocity = float((bodies[b].w - bodies[a].w) @ axis_a)
            joints.append(jt)
        if loops is not None:
            joints += loops(bodies, coms, rots, d)
        pushed = np.zeros((len(coms), 6)) if state.pushes else None
        for k, force, at in state.pushes:
            # AMBF solves its contact rows with the joints' rows, so its motors do not push
            # through a contact; the chain's rows see the contact as the push it gave
            bd = bodies[k]
            if bd.inv_mass > 0.0:
                dv, dw = force * self.dt * bd.inv_mass, bd.inv_inertia @ cross3(at - coms[k], force) * self.dt
                bd.v, bd.w = bd.v + dv, bd.w + dw
                pushed[k, :3] += dv
                pushed[k, 3:] += dw
        # what those pushes alone did to the joints (the contacts' share of the step before's change)
        self.contact = None
        if pushed is not None:
            held = [Body(c, bd.inv_mass, bd.inv_inertia, bd.v, bd.w, bd.inertia) for c, bd in zip(coms, bodies)]
            self.contact = joint_velocities(held, fk, pushed)[0]
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
        # read as the articulation's joints, which carry the bodies where their joints put them
        # (what is apart is measured from there)
        at = [Body(c, bd.inv_mass, bd.inv_inertia, bd.v, bd.w, bd.inertia) for c, bd in zip(coms, bodies)]
        qd, together = joint_velocities(at, fk, after)
        apart = after - together
        apart[[k for k in range(len(coms)) if self.inv_mass[k] <= 0.0]] = 0.0
        drift += apart * self.dt
        self.drift = _turned(rots.transpose(0, 2, 1), drift)
        self.carried = after
        self.carried[[k for k in range(len(coms)) if self.inv_mass[k] <= 0.0]] = 0.0
        return qd


def gyroscopic(w: np.ndarray, rot: np.ndarray, diag: np.ndarray, dt: float) -> np.ndarray:
    """The angular velocity ``w`` after Bullet's implicit gyroscopic step, which AMBF's
    btRigidBodies take before the solver's rows (btRigidBody's default flag
    BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY, computeGyroscopicImpulseImplicit_Body): one
    Newton step of I·(ω' − ω) + dt·ω'×(I·ω') = 0 in the body's principal frame (``rot``, its
    principal inertias ``diag``), on Python floats (numpy's 3x3 solve cost five times as much)."""
    x, y, z = (rot.T @ w).tolist()
    i0, i1, i2 = diag.tolist()
    a, b, c = i0 * x, i1 * y, i2 * z
    # the residual dt·ω×(I·ω) and the Jacobian I + (skew(ω)·I − skew(I·ω))·dt
    f0, f1, f2 = dt * (y * c - z * b), dt * (z * a - x * c), dt * (x * b - y * a)
    if f0 == 0.0 and f1 == 0.0 and f2 == 0.0:
        return w
    m00, m01, m02 = i0, (c - z * i1) * dt, (y * i2 - b) * dt
    m10, m11, m12 = (z * i0 - c) * dt, i1, (a - x * i2) * dt
    m20, m21, m22 = (b - y * i0) * dt, (x * i1 - a) * dt, i2
    c0, c1, c2 = m11 * m22 - m12 * m21, m12 * m20 - m10 * m22, m10 * m21 - m11 * m20  # cofactors of row 0
    det = m00 * c0 + m01 * c1 + m02 * c2
    if abs(det) <= 1.1920929e-07:  # btMatrix3x3::solve33 leaves so small a step as good as none
        return w
    # Cramer's rule, as solve33
    d0 = (f0 * c0 + m01 * (m12 * f2 - f1 * m22) + m02 * (f1 * m21 - m11 * f2)) / det
    d1 = (m00 * (f1 * m22 - m12 * f2) + f0 * c1 + m02 * (m10 * f2 - f1 * m20)) / det
    d2 = (m00 * (m11 * f2 - f1 * m21) + m01 * (f1 * m20 - m10 * f2) + f0 * c2) / det
    return rot @ np.array([x - d0, y - d1, z - d2])


def _erp(joint) -> float:
    return joint.joint_erp if joint.joint_erp is not None else AMBF_JOINT_ERP


def _turned(rots: np.ndarray, six: np.ndarray) -> np.ndarray:
    """Each row of ``six`` (n, 6: two 3-vectors) turned by its body's rotation ``rots`` (n, 3, 3)."""
    return (rots @ six.reshape(-1, 2, 3).transpose(0, 2, 1)).transpose(0, 2, 1).reshape(-1, 6)
