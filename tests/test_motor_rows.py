"""Joint motors as soft as AMBF's constraint rows (runner/joint_commands.py, soft_row_impulses): a
motor reaches its target over several steps when it moves more than its own two bodies, by the
joint's `joint cfm`, and a chain's rows settle together; with cfm 0 it reaches it within the step
(the control)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402
from adfkit.runner.joint_commands import JointCommands, soft_row_impulses  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent

# the parity arm (adfkit.scenes.parity.build_arm): 0.5 kg, iz 0.0037875 kg m² about its centre,
# 0.2 m from the joint's axis (z), on a static base: the row sees iz, the joint (its only one) iz + m d²
ARM_ROW = 0.0037875
ARM_JOINT = 0.0037875 + 0.5 * 0.2**2


def _share(cfm, inertia, row_mass):
    """How far one soft row takes its joint in a step: r·(v_t − v) = cfm·λ, λ = I·(v − v_free)."""
    return 1 / (1 + cfm * inertia / row_mass)


def test_one_soft_row_goes_its_share_of_the_way():
    (lam,) = soft_row_impulses(np.array([[1 / ARM_JOINT]]), [ARM_ROW], [0.1], [1.0], [0.0])
    assert lam / ARM_JOINT == pytest.approx(_share(0.1, ARM_JOINT, ARM_ROW))  # 0.614 of the way
    (lam,) = soft_row_impulses(np.array([[1 / ARM_JOINT]]), [ARM_ROW], [0.0], [1.0], [0.0])
    assert lam / ARM_JOINT == pytest.approx(1.0)  # cfm 0: all the way


def test_a_chains_soft_rows_settle_together():
    """Two joints, M = [[1, 1], [1, 2]] (W = M⁻¹ = [[2, -1], [-1, 1]]), rows of mass 1 and 0.5,
    cfm 0.1, the first driven at 1 from rest, the second held at 0: by hand λ = (0.6, 0.5)/0.76,
    v = W·λ = (0.921, -0.132): the second joint, pushed by its neighbour's row, falls behind its
    target too, which one row at a time (the first alone, I = 1/W₁₁: 1/(1 + 0.1·0.5) = 0.952) misses."""
    w = np.array([[2.0, -1.0], [-1.0, 1.0]])
    lam = soft_row_impulses(w, [1.0, 0.5], [0.1, 0.1], [1.0, 0.0], [0.0, 0.0])
    assert lam == pytest.approx([0.6 / 0.76, 0.5 / 0.76])
    v = w @ lam
    assert v == pytest.approx([0.92105, -0.13158], abs=1e-5)
    assert [1.0, 0.5] * (np.array([1.0, 0.0]) - v) == pytest.approx(0.1 * lam)  # each row r·(v_t − v) = cfm·λ
    assert abs(v[0] - _share(0.1, 1 / 2.0, 1.0)) > 0.01


def _arm(tmp_path, cfm):
    from adfkit.scenes.parity import write_parity

    scene = load_scene(write_parity(tmp_path), [1])
    for m in scene.all_models():
        for j in m.joints:
            j.joint_cfm = cfm
    return open_world(scene, Options(visuals=False, control_substeps=1))


@pytest.mark.parametrize("cfm", [None, 0.0])
def test_a_velocity_command_is_reached_at_the_rows_pace(tmp_path, cfm):
    w = _arm(tmp_path, cfm)
    try:
        commands = JointCommands(w)
        (joint, _parent, child) = next(r for r in w.joints_made if r[0].name == "base-arm")
        commands.command(joint, child, "velocity", 1.0)
        dj = commands.joints[id(joint)]
        assert dj.row_mass == pytest.approx(ARM_ROW, rel=1e-3)
        v = []
        for k in range(3):
            commands.apply(k * w.dt)
            w.step(1)
            v.append(float(w.joint_state(dj.art, [dj.index])[1][0]))
    finally:
        w.close()
    g = _share(0.1, ARM_JOINT, ARM_ROW) if cfm is None else 1.0  # AMBF's joint cfm is 0.1
    expected = [1 - (1 - g) ** n for n in (1, 2, 3)]  # 0.614, 0.851, 0.943 rad/s at cfm 0.1
    assert v == pytest.approx(expected, abs=2e-3)


@pytest.mark.parametrize("cfm, ring", [(None, False), (0.0, True)])
def test_a_psm_yaw_held_by_ambfs_controller_does_not_ring(cfm, ring):
    """The bundled PSM's yaw joint given a position under AMBF's default controller (P 10, D 1, a
    velocity to its motor): with the row's softness it settles; with a motor that reaches the
    controller's velocity within the step the D term's kick grows each step, its sign flipping,
    until the motor's force caps it (±76 rad/s)."""
    scene = load_scene(ROOT / "sample_scenes" / "suturing" / "launch.yaml")
    if cfm is not None:
        for m in scene.all_models():
            for j in m.joints:
                j.joint_cfm = cfm
    w = open_world(scene, Options(visuals=False, control_substeps=1))
    try:
        commands = JointCommands(w)
        joint, _parent, child = next(
            r for r in w.joints_made if r[0].name == "base link-yaw link" and "psm1" in r[2].key
        )
        commands.command(joint, child, "position", 0.1)
        dj = commands.joints[id(joint)]
        v = []
        for k in range(600):
            w.step(1)
            commands.apply((k + 1) * w.dt)
            v.append(float(w.joint_state(dj.art, [dj.index])[1][0]))
        q = float(w.joint_state(dj.art, [dj.index])[0][0])
    finally:
        w.close()
    late = float(np.abs(v[300:]).max())
    if ring:
        assert late > 50.0  # measured 75.8 rad/s
    else:
        assert late < 0.1 and q == pytest.approx(0.1, abs=1e-3)  # measured 0.009 rad/s, 0.09998 rad


@pytest.mark.parametrize("leaving, effort", [(True, -0.5), (False, -0.5), (False, 0.5)])
def test_a_limit_holds_an_effort_one_way_only(tmp_path, leaving, effort):
    """The arm 0.01 rad past its lower limit (-2 rad) under an effort: AMBF's limit row drives it
    back at erp·error a step, and only pushes: a joint already leaving its limit faster than that
    (5 rad/s) goes on, slowed by the effort alone (-0.5 N·m, pushing it further on). Controls: the
    joint moving further past its limit (5 rad/s) is driven back at erp·error/dt, whether the
    effort pushes it out or pulls it in (the limit, not the effort, holds it)."""
    w = _arm(tmp_path, None)
    try:
        commands = JointCommands(w)
        (joint, _parent, child) = next(r for r in w.joints_made if r[0].name == "base-arm")
        commands.command(joint, child, "effort", effort)
        dj = commands.joints[id(joint)]
        w.reset_joints(dj.art, [dj.index], [-2.01], [5.0 if leaving else -5.0])
        commands.apply(w.dt)
        w.step(1)
        v = float(w.joint_state(dj.art, [dj.index])[1][0])
    finally:
        w.close()
    if leaving:  # 5 - 0.5·dt/I, I the arm's 0.0238 kg m² about the joint (and AMBF's damping)
        assert v == pytest.approx(5.0 + effort * w.dt / ARM_JOINT, rel=2e-3)
    else:
        assert v == pytest.approx(dj.erp * 0.01 / w.dt, rel=2e-2)  # 1 rad/s back toward the limit


@pytest.mark.parametrize("start", [-2.1, -1.9])
def test_a_joint_outside_its_limits_is_pushed_back_in_as_ambfs_hinge_row(tmp_path, start):
    """The arm at rest, no command on it, 0.1 rad past its lower limit (-2 rad): AMBF's hinge
    limit row (bias 0.3, erp 0.1) kicks it back in at 0.3·erp·0.1/dt = 3 rad/s within the step,
    and it coasts on into its limits (PyBullet's own limit held it where it started). Control:
    0.1 rad inside its limits it is left where it is."""
    from adfkit.runner.pybullet.limit_rows import HINGE_LIMIT_BIAS

    w = _arm(tmp_path, None)
    try:
        (joint, _parent, child) = next(r for r in w.joints_made if r[0].name == "base-arm")
        art, index = child.articulation, child.link
        w.reset_joints(art, [index], [start])
        w.step(1)
        v = float(w.joint_state(art, [index])[1][0])
        w.step(99)
        q = float(w.joint_state(art, [index])[0][0])
    finally:
        w.close()
    if start < -2.0:
        assert v == pytest.approx(HINGE_LIMIT_BIAS * 0.1 * 0.1 / w.dt, rel=2e-2)  # 3 rad/s
        assert -2.0 < q < -1.6  # 0.1 s later, inside its limits (about 0.3 rad on)
    else:
        assert v == pytest.approx(0.0, abs=1e-6) and q == pytest.approx(start, abs=1e-6)
