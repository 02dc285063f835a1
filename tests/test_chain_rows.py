"""AMBF's solver on a chain of btRigidBodies (runner/chain_rows.py): Bullet's hinge rows and its
projected Gauss-Seidel, a step worked by hand; and the PyBullet runner's hinge under an effort
past its limit, which plays it (runner/pybullet/chain.py, JointCommands._efforts)."""

from __future__ import annotations

import numpy as np
import pytest

from adfkit.runner.chain_rows import Body, Joint, island_order, joint_velocities, solve
from adfkit.runner.joint_commands import soft_row_impulses

# a body of 2 kg, 0.01 kg·m² about every axis, its centre 0.1 m along x from a hinge about z at
# the origin on a static parent: about the hinge its inertia is 0.01 + 2·0.1² = 0.03
M, I, R = 2.0, 0.01, 0.1


def _chain(target, cfm=0.0):
    base = Body(np.zeros(3), 0.0, np.zeros((3, 3)), np.zeros(3), np.zeros(3))
    arm = Body(np.array([R, 0.0, 0.0]), 1 / M, np.eye(3) / I, np.zeros(3), np.zeros(3))
    z = np.array([0.0, 0.0, 1.0])
    hinge = Joint("revolute", 0, 1, np.zeros(3), z, np.array([0.0, 1.0, 0.0]), 0.0, 0.0, 0.1, None, (target, cfm, 1e9))
    return [base, arm], [hinge]


def test_one_sweep_and_two_by_hand():
    """The motor row (1 rad/s from rest) turns the body about its own centre in the first sweep
    (ω 1, its centre still: the locking row across the arm, v_y − 0.1·ω, saw nothing to do
    before it); the second sweep's locking row moves the centre 0.1/1.5·0.5 = 1/30 m/s and takes
    ω to 1/3, which the motor row brings back to 1. Read as the joint (the bodies' momentum
    about the hinge, over its inertia): (0.01·1)/0.03 = 1/3, then (2·0.1/30 + 0.01)/0.03 = 5/9;
    settled, the joint turns at its target (a negative control: one sweep is not settled)."""
    bodies, joints = _chain(1.0)
    one = solve(bodies, joints, 1e-3, iterations=1)
    assert one[1] == pytest.approx([0, 0, 0, 0, 0, 1.0], abs=1e-12)
    two = solve(bodies, joints, 1e-3, iterations=2)
    assert two[1] == pytest.approx([0, 1 / 30, 0, 0, 0, 1.0], abs=1e-12)
    assert joint_velocities(bodies, joints, one)[0] == pytest.approx([1 / 3])
    assert joint_velocities(bodies, joints, two)[0] == pytest.approx([5 / 9])
    settled = solve(bodies, joints, 1e-3, iterations=200)
    assert joint_velocities(bodies, joints, settled)[0] == pytest.approx([1.0], abs=1e-6)


def test_settled_soft_motor_is_the_joint_space_rows_share():
    """With cfm 0.1 the settled rows leave the joint where the joint-space rows do
    (soft_row_impulses: 1/(1 + cfm·I/r), I = 0.03 the joint's inertia, r = 0.01 what the motor
    row sees): 1/1.3 of the way."""
    bodies, joints = _chain(1.0, cfm=0.1)
    qd = joint_velocities(bodies, joints, solve(bodies, joints, 1e-3, iterations=400))[0]
    (lam,) = soft_row_impulses(np.array([[1 / 0.03]]), [I], [0.1], [1.0], [0.0])
    assert qd == pytest.approx([lam / 0.03], rel=1e-6)
    assert qd[0] == pytest.approx(1 / 1.3, rel=1e-6)


def test_island_order_is_bullets_quicksort_of_equal_keys():
    """btAlignedObjectArray::quickSort swaps equal keys from both ends, then each half: the
    order the PSM's eight joints are solved in, and one or two left as they are."""
    assert island_order(8) == [5, 4, 7, 6, 1, 0, 3, 2]
    assert island_order(3) == [2, 1, 0]
    assert island_order(1) == [0]


def _arm(tmp_path):
    pytest.importorskip("pybullet")
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.scenes.parity import write_parity

    opt = Options(visuals=False, control_substeps=1)
    opt.bodies = "ambf"
    return open_world(load_scene(write_parity(tmp_path), [1]), opt)


@pytest.mark.parametrize("start", [2.00372, 1.9])
def test_a_hinge_past_its_limit_comes_back_as_in_ambf(tmp_path, start):
    """The parity arm (0.5 kg, 0.0037875 kg·m² about its centre, 0.2 m from the hinge on a static
    base, limits ±2 rad) pushed by 0.2 N·m and turning out at 5.733 rad/s, 3.72 mrad past its
    upper limit, as AMBF's solver takes it through a step: the limit row turns the arm about its
    centre back at 0.3 of its speed (5.7324 after the step's damping: 1.7197 rad/s), and Bullet's
    hinge against a static body leaves the arm's turn out of two locking rows while the limit is
    on, so its centre is held; what that carries about the hinge is 1.7197·0.0037875/0.0237875 =
    0.2738 rad/s inward. (Measured in AMBF, adfkit parity: the arm hits its stop at 5.7 rad/s
    and comes back off it at 1.7 rad/s for three steps, its pivot opening, then at 0.14 rad/s.)
    Control: inside its limits the effort turns it on: the arm's motion along (m·d² = 0.02 of the
    0.0237875) damped by its linear damping 0.04, about its centre by its angular 0.1, a step
    each, plus 0.2 N·m for 1 ms over 0.0237875."""
    w = _arm(tmp_path)
    try:
        (_joint, _parent, child) = next(r for r in w.joints_made if r[0].name == "base-arm")
        art, index = child.articulation, child.link
        w.reset_joints(art, [index], [start], [5.733])
        v = w.chain_velocities(art, {}, {index: 0.2})[index]
    finally:
        w.close()
    if start > 2.0:
        assert v == pytest.approx(-0.3 * 5.733 * 0.9**0.001 * 0.0037875 / 0.0237875, rel=1e-4)
    else:
        damped = (0.02 * 0.96**0.001 + 0.0037875 * 0.9**0.001) / 0.0237875
        assert v == pytest.approx(5.733 * damped + 0.2 * 1e-3 / 0.0237875, rel=1e-7)


def test_only_ambfs_bodies_play_the_chain(tmp_path):
    """Options() (the suture's: PyBullet's bodies) leave the chain to the joint-space rows."""
    pytest.importorskip("pybullet")
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.scenes.parity import write_parity

    w = open_world(load_scene(write_parity(tmp_path), [1]), Options(visuals=False, control_substeps=1))
    try:
        art = w.articulations[0]
        assert w.chain_velocities(art, {}, {}) is None
    finally:
        w.close()


def _reference_pgs(bodies, joints, dt, iterations):
    """Bullet's projected Gauss-Seidel written out plainly: every row's Jacobian placed in a
    dense matrix body by body, each row in turn against the impulses so far (a joint row's cfm
    as btSequentialImpulseConstraintSolver::convertJoint leaves it, not scaled by the row's
    effective mass as a contact's is)."""
    from adfkit.runner.chain_rows import Rows, hinge_rows

    rows = Rows()
    for k in island_order(len(joints)):
        hinge_rows(rows, bodies, joints[k], dt)
    n, m = len(bodies), len(rows.c)
    J = np.zeros((m, 6 * n))
    for r in range(m):
        j12 = np.concatenate(rows.j[r])
        J[r, 6 * rows.a[r] : 6 * rows.a[r] + 6] = j12[:6]
        J[r, 6 * rows.b[r] : 6 * rows.b[r] + 6] = j12[6:]
    Minv = np.zeros((6 * n, 6 * n))
    v = np.zeros(6 * n)
    for k, b in enumerate(bodies):
        Minv[6 * k : 6 * k + 3, 6 * k : 6 * k + 3] = np.eye(3) * b.inv_mass
        Minv[6 * k + 3 : 6 * k + 6, 6 * k + 3 : 6 * k + 6] = b.inv_inertia
        v[6 * k : 6 * k + 6] = np.concatenate([b.v, b.w])
    lam = np.zeros(m)
    for _ in range(iterations):
        for i in range(m):
            d = J[i] @ Minv @ J[i]
            dv = Minv @ J.T @ lam
            s = lam[i] + (rows.c[i] - J[i] @ (v + dv)) / d - rows.cfm[i] * lam[i]  # a joint row's cfm unscaled
            lam[i] = min(max(s, rows.lo[i]), rows.hi[i])
    return (v + Minv @ J.T @ lam).reshape(n, 6)


def test_a_chain_of_three_hinges_solves_as_bullets_sweeps_written_out():
    """Three moving links on a static base, hinges about z, x and z, a motor with a small impulse
    bound on the first (clamped), the second past its upper limit (a one-sided row), the bodies
    moving and falling: ten sweeps give what the sweeps written out give (the dense assembly and
    the clamps of solve), and not what one sweep gives (a negative control)."""
    rng = np.random.default_rng(7)
    base = Body(np.zeros(3), 0.0, np.zeros((3, 3)), np.zeros(3), np.zeros(3))
    links = [
        Body(np.array([0.1 * (k + 1), 0.02 * k, 0.0]), 1 / (1.0 + k), np.diag(rng.uniform(50, 200, 3)),
             rng.normal(0, 0.2, 3), rng.normal(0, 1.0, 3))
        for k in range(3)
    ]  # fmt: skip
    z, x, y = np.eye(3)[2], np.eye(3)[0], np.eye(3)[1]
    joints = [
        Joint("revolute", 0, 1, np.zeros(3), z, y, 0.0, 0.5, 0.1, None, (2.0, 0.1, 0.004)),
        Joint("revolute", 1, 2, np.array([0.15, 0.0, 0.0]), x, y, 0.6, 1.0, 0.1, (-0.5, 0.5), None),
        Joint("revolute", 2, 3, np.array([0.25, 0.02, 0.0]), z, y, 0.0, -0.3, 0.1, None, (0.0, 0.1, 1e9)),
    ]
    bodies = [base, *links]
    ten = solve(bodies, joints, 1e-3)
    assert ten == pytest.approx(_reference_pgs(bodies, joints, 1e-3, 10), abs=1e-12)
    assert not np.allclose(ten, solve(bodies, joints, 1e-3, iterations=1), atol=1e-6)


def _hung(cfm: float, gap: float = 0.0):
    """A 2 kg body (0.01 kg·m²) hung by a p2p joint 0.1 m above its centre from a static body,
    moving 1 m/s sideways; ``gap``: the child's pivot that far (along x) from the parent's."""
    base = Body(np.zeros(3), 0.0, np.zeros((3, 3)), np.zeros(3), np.zeros(3))
    bob = Body(np.array([gap, 0.0, -R]), 1 / M, np.eye(3) / I, np.array([1.0, 0.0, 0.0]), np.zeros(3))
    x = np.eye(3)[0]
    point = Joint("p2p", 0, 1, np.array([gap, 0.0, 0.0]), x, x, 0.0, 0.0, 0.1, cfm=cfm)
    point.pivot_a = np.zeros(3)
    return [base, bob], [point]


def test_a_point_joint_stops_its_pivot_as_worked_by_hand():
    """btPoint2PointConstraint's rows on a bob moving 1 m/s across its pivot: the x row pushes at
    the pivot with P, v = 1 + P/m, ω_y = 0.1·P/I; the pivot still: 1 + P (1/m + 0.01/I) = 0,
    P = −2/3: v = 2/3 m/s, ω_y = −20/3 rad/s. AMBF sets the joint's cfm (0.1 unless the file
    gives one) on its rows, unscaled: (−1 − 1.5·P) / 1.5 = 0.1·P, P = −1/1.65 (the bob keeps
    0.697 m/s). A pivot 1 mm open is closed at erp/dt: the pivot moves back at 0.1 m/s."""
    bodies, joints = _hung(0.0)
    v = solve(bodies, joints, 1e-3, iterations=50)[1]
    assert v == pytest.approx([2 / 3, 0, 0, 0, -20 / 3, 0], abs=1e-9)
    soft = solve(*_hung(0.1), 1e-3, iterations=400)[1]
    assert soft[0] == pytest.approx(1 - 1 / 1.65 / M, rel=1e-9)
    opened = solve(*_hung(0.0, gap=1e-3), 1e-3, iterations=50)[1]
    assert opened[0] + opened[4] * R == pytest.approx(-0.1 * 1e-3 / 1e-3, abs=1e-9)


def test_a_body_turns_as_bullets_implicit_gyroscopic_step():
    """AMBF's btRigidBodies keep Bullet's default BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY: before
    the rows, one Newton step of I·(ω' − ω) + dt·ω'×(I·ω') = 0 in the body's principal frame.
    Worked by hand for principal inertias (1, 2, 3), ω = (1, 1, 0), dt 0.1: the residual
    dt·ω×(I·ω) = (0, 0, 0.1), the Jacobian [[1, 0, 0.1], [0, 2, −0.2], [0.1, 0.1, 3]], the step
    (−1/300, 1/300, 1/30); the same in a body turned 90° about z. Control: a spin about a
    principal axis, and any spin of a body with equal inertias, is left as it is."""
    from adfkit.runner.chain_step import gyroscopic

    diag, w = np.array([1.0, 2.0, 3.0]), np.array([1.0, 1.0, 0.0])
    want = np.array([1 + 1 / 300, 1 - 1 / 300, -1 / 30])
    assert gyroscopic(w, np.eye(3), diag, 0.1) == pytest.approx(want, abs=1e-12)
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    assert gyroscopic(turn @ w, turn, diag, 0.1) == pytest.approx(turn @ want, abs=1e-12)
    assert gyroscopic(np.array([0.0, 0.0, 2.0]), np.eye(3), diag, 0.1) == pytest.approx([0, 0, 2.0], abs=1e-15)
    assert gyroscopic(w, np.eye(3), np.ones(3), 0.1) == pytest.approx(w, abs=1e-15)
