"""AMBF's solver step played on an articulation (runner/chain_step.py) against the same rows on
btRigidBodies integrated as Bullet integrates them (each body's centre along its velocity, its
turn by its angular velocity), with no articulation: a two-hinge arm under soft motors that
reverse."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from adfkit.runner.chain_rows import Body, Joint, solve
from adfkit.runner.chain_step import ChainState, ChainStep, gyroscopic

DT = 1e-3
Z, Y, X = np.eye(3)[2], np.eye(3)[1], np.eye(3)[0]
MASS = (1.0, 0.7)
DIAG = (np.array([0.004, 0.012, 0.010]), np.array([0.003, 0.002, 0.004]))
COM = (np.array([0.15, 0.0, 0.05]), np.array([0.0, 0.02, 0.12]))  # link 1's in its frame; link 2's from its pivot
PIVOT2 = np.array([0.3, 0.0, 0.1])  # the second hinge (about link 1's y) in link 1's frame


def _turn(axis: np.ndarray, angle: float) -> np.ndarray:
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def _chain() -> ChainStep:
    damped = SimpleNamespace(damping=SimpleNamespace(linear=0.5, angular=0.5))
    bodies = [(damped, 0.0, np.zeros(3), True, np.zeros(3))]
    bodies += [(damped, m, d, False, np.zeros(3)) for m, d in zip(MASS, DIAG)]
    hinge = SimpleNamespace(joint_limits=None, joint_erp=None)
    return ChainStep(DT, bodies, [(0, "revolute", hinge), (1, "revolute", hinge)], [0, 1])


def _articulation(q: np.ndarray, qd: np.ndarray) -> ChainState:
    """The arm where its joints put it, at the joints' velocities (what an engine reads)."""
    r1 = _turn(Z, q[0])
    r2 = r1 @ _turn(Y, q[1])
    pivot2 = r1 @ PIVOT2
    c1, c2 = r1 @ COM[0], pivot2 + r2 @ COM[1]
    w1 = qd[0] * Z
    w2 = w1 + qd[1] * (r1 @ Y)
    v1, v2 = np.cross(w1, c1), np.cross(w1, pivot2) + np.cross(w2, c2 - pivot2)
    joints = [(np.zeros(3), Z, Y, q[0], qd[0]), (pivot2, r1 @ Y, r1 @ X, q[1], qd[1])]
    coms = np.array([np.zeros(3), c1, c2])
    return ChainState(coms, np.array([np.eye(3), r1, r2]), np.array([np.zeros(3), v1, v2]),
                      np.array([np.zeros(3), w1, w2]), joints, [])  # fmt: skip


def _motors(step: int) -> dict[int, tuple[float, float, float]]:
    sign = 1.0 if step < 150 else -1.0  # the motors reverse at 0.15 s
    return {0: (sign * 0.6, 0.1, 1e3), 1: (-sign * 0.8, 0.1, 1e3)}


def _articulated(carry: bool = True) -> np.ndarray:
    """Link 2's centre over 0.3 s, the articulation moved at the joints' velocities the chain
    step gives (``carry`` False: each step started from the articulation's own velocities)."""
    chain = _chain()
    q, qd, out = np.zeros(2), np.zeros(2), []
    for step in range(300):
        state = _articulation(q, qd)
        out.append(state.coms[2])
        if not carry:
            chain.carried = None
        qd = chain.velocities(state, _motors(step), {}, step)
        q = q + qd * DT
    return np.array(out)


def _bullets() -> np.ndarray:
    """Link 2's centre over 0.3 s, the same rows on free bodies integrated as btRigidBodies."""
    chain = _chain()
    start = _articulation(np.zeros(2), np.zeros(2))
    coms, rots = start.coms.copy(), start.rots.copy()
    v, w = np.zeros((3, 3)), np.zeros((3, 3))
    inv_i = [np.zeros(3), *(1 / d for d in DIAG)]
    inertia = [np.zeros(3), *DIAG]
    # each hinge's pivot from either body's centre and its axis, in the body's frame; the parent's y
    local = [(np.zeros(3), -COM[0], Z, Z, Y), (PIVOT2 - COM[0], -COM[1], Y, Y, X)]
    out = []
    for step in range(300):
        out.append(coms[2].copy())
        bodies = [Body(coms[0], 0.0, np.zeros((3, 3)), np.zeros(3), np.zeros(3))]
        for k in (1, 2):
            dv, dw = chain.decay[k]
            r = rots[k]
            bodies.append(Body(coms[k], 1 / MASS[k - 1], r @ np.diag(inv_i[k]) @ r.T, v[k] * dv,
                               gyroscopic(w[k] * dw, r, inertia[k], DT), r @ np.diag(inertia[k]) @ r.T))  # fmt: skip
        joints = []
        for k, (pa, pb, xa, xb, ya) in enumerate(local):
            a, b = k, k + 1
            pivot_a = coms[a] + rots[a] @ pa
            axis = rots[a] @ xa
            jt = Joint(
                "revolute", a, b, coms[b] + rots[b] @ pb, axis, rots[a] @ ya, 0.0, 0.0, 0.1, None, _motors(step)[k]
            )
            jt.pivot_a, jt.axis_b = pivot_a, rots[b] @ xb
            joints.append(jt)
        after = solve(bodies, joints, DT, [0, 1])
        for k in (1, 2):
            v[k], w[k] = after[k, :3], after[k, 3:]
            coms[k] = coms[k] + v[k] * DT
            angle = math.sqrt(w[k] @ w[k]) * DT
            if angle > 0.0:
                rots[k] = _turn(w[k] / np.linalg.norm(w[k]), angle) @ rots[k]
    return np.array(out)


def test_the_chain_step_moves_an_arm_as_bullets_bodies_through_a_reversal():
    """Each step starts from the velocities the last step left the bodies (Bullet's, in the
    world's frame), not from the articulation's read where its joints have since carried them,
    which turn with the links: Bullet's rows take that turn out within the step, unsettled in ten
    iterations. 0.1 s after the motors' reversal (its bodies' pivots shut again), link 2's centre
    stands within 2 µm of the btRigidBodies' (its whole swing 31 mm); control: started from the
    articulation's velocities, 23 µm and more, growing."""
    bullet = _bullets()
    settled = slice(250, None)
    gap = np.linalg.norm((_articulated() - bullet)[settled], axis=1).max()
    control = np.linalg.norm((_articulated(carry=False) - bullet)[settled], axis=1).max()
    assert np.linalg.norm(bullet - bullet[0], axis=1).max() > 0.03  # the arm swung
    assert gap < 2e-6
    assert control > 1.5e-5


def test_the_contacts_share_is_what_their_pushes_give_the_joints():
    """ChainStep.contact, what the last step's contact pushes alone gave the joints (runner/
    joint_commands.py takes it out of the change it extrapolates): the joint-space answer to the
    push, M⁻¹·Q·dt, with M the arm's joint-space mass and Q the push's generalised force, both
    worked out here from the arm's own kinematics; none without a contact."""
    q, qd = np.array([0.4, -0.7]), np.array([0.2, -0.1])
    state = _articulation(q, qd)
    chain = _chain()
    chain.velocities(state, _motors(0), {}, 0)
    assert chain.contact is None
    force, point = np.array([3.0, -1.0, 2.0]), state.coms[2] + np.array([0.01, 0.03, -0.02])
    state.pushes = [(2, force, point)]
    chain.velocities(state, _motors(1), {}, 1)
    # each joint's unit velocity: the bodies' velocities (from the arm's kinematics) and the point's
    unit = [_articulation(q, e) for e in np.eye(2)]
    mass = np.zeros((2, 2))
    for i, a in enumerate(unit):
        for j, b in enumerate(unit):
            for k in (1, 2):
                inertia = state.rots[k] @ np.diag(DIAG[k - 1]) @ state.rots[k].T
                mass[i, j] += MASS[k - 1] * a.v[k] @ b.v[k] + a.w[k] @ inertia @ b.w[k]
    push = np.array([force @ (u.v[2] + np.cross(u.w[2], point - state.coms[2])) for u in unit])
    assert np.allclose(chain.contact, np.linalg.solve(mass, push) * DT, rtol=1e-9, atol=1e-12)
    assert np.abs(chain.contact).max() > 1e-3  # a push that moves the joints
