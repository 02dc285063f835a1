"""MuJoCo's joints under position and velocity commands as AMBF's motor rows (a constraint row at
the joint's cfm between the joint's two bodies: runner/mujoco/motor_rows.py, joint_commands.py),
where AMBF's bodies are asked for; real MuJoCo and PyBullet, no mocks."""

from __future__ import annotations

import math

import pytest

pytest.importorskip("mujoco")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402
from adfkit.runner.joint_commands import JointCommands  # noqa: E402
from adfkit.scenes.parity import write_parity  # noqa: E402

# the parity arm: 0.0037875 kg·m² about its centre, 0.0237875 about its hinge on a static base
ROW, ABOUT_HINGE = 0.0037875, 0.0237875


def _one_step_at(tmp_path, engine: str, bodies: str | None):
    opt = Options(visuals=False, control_substeps=1, ground=False)
    if bodies is not None:
        opt.bodies = bodies
    w = open_world(load_scene(write_parity(tmp_path), [1]), opt, engine=engine)
    try:
        jc = JointCommands(w)
        joint, _parent, child = next(r for r in w.joints_made if r[0].name == "base-arm")
        jc.command(joint, child, "velocity", 1.0)
        dj = jc.joints[id(joint)]
        row, mobility = w.joint_row_mass(dj.art, dj.index), w.joint_mobility(dj.art, [dj.index])
        jc.apply(0.0)
        w.step(1)
        return row, float(mobility[0, 0]), float(w.joint_state(dj.art, [dj.index])[1][0])
    finally:
        w.close()


def test_a_velocity_command_moves_the_arm_as_a_settled_motor_row(tmp_path):
    """1 rad/s from rest on the arm: the row sees the arm's inertia about its own centre
    (PyBullet's figure too), the joint's mobility is one over its inertia about the hinge, and
    the row at AMBF's cfm 0.1 settles with the joint at 1 / (1 + 0.1·0.0237875/0.0037875) of
    the target after one step. Control: with PyBullet's bodies (Options()) the row is infinite
    and the joint follows its stiff drive, whose target moved 1 mrad: a quarter of the target
    speed after the first step (measured: 0.25), not the row's 0.614."""
    row, mobility, qd = _one_step_at(tmp_path / "a", "mujoco", "ambf")
    assert row == pytest.approx(ROW, rel=1e-9)
    assert mobility == pytest.approx(1 / ABOUT_HINGE, rel=1e-6)
    assert qd == pytest.approx(1 / (1 + 0.1 * ABOUT_HINGE / ROW), rel=1e-4)
    assert _one_step_at(tmp_path / "b", "pybullet", "ambf")[0] == pytest.approx(ROW, rel=1e-9)
    stiff_row, _m, stiff_qd = _one_step_at(tmp_path / "c", "mujoco", None)
    assert math.isinf(stiff_row) and stiff_qd == pytest.approx(0.25, abs=1e-6)


def _spun(tmp_path, bodies: str | None, joint_damping: float = 0.0) -> float:
    """The parity arm (its hinge vertical) spun at 5 rad/s, motor off, its speed after 0.2 s;
    ``joint_damping``: its joint's `damping` in the file."""
    opt = Options(visuals=False, control_substeps=1, ground=False)
    if bodies is not None:
        opt.bodies = bodies
    launch = write_parity(tmp_path)
    if joint_damping:
        arm = tmp_path / "arm.yaml"
        arm.write_text(arm.read_text().replace("  name: base-arm\n", f"  name: base-arm\n  damping: {joint_damping}\n"))
    w = open_world(load_scene(launch, [1]), opt, engine="mujoco")
    try:
        _joint, _parent, child = next(r for r in w.joints_made if r[0].name == "base-arm")
        art = child.articulation
        art.free()
        w.reset_joints(art, [0], [0.0], [5.0])
        w.step(200)
        return float(w.joint_state(art, [0])[1][0])
    finally:
        w.close()


def test_a_jointed_body_is_damped_as_ambfs_rigid_body(tmp_path):
    """AMBF damps every btRigidBody, a jointed one too (the KUKA's links: 0.95), and the runner
    gives MuJoCo's jointed bodies that damping where AMBF's bodies are asked for. The arm keeps
    AMBF's default damping (linear 0.04, angular 0.1 a second: rates -ln 0.96 and -ln 0.9): about
    its hinge the speed decays at (0.0408·m·d² + 0.1054·I_c) / (I_c + m·d²) = 0.0511/s, m·d² =
    0.02, I_c = 0.0037875 kg·m² (PyBullet: 4.94916 rad/s after 0.2 s, the same figure). Measured
    with AMBF, the KUKA's effort program in MuJoCo went from 2.96 mm to 0.005 mm. Control: with
    PyBullet's bodies (Options(): the suture's) a jointed body is left to its joints: 5 rad/s."""
    rate = (-math.log(0.96) * 0.02 - math.log(0.9) * 0.0037875) / 0.0237875
    assert _spun(tmp_path / "a", "ambf") == pytest.approx(5.0 * math.exp(-0.2 * rate), rel=1e-4)
    assert _spun(tmp_path / "b", "pybullet") == pytest.approx(5.0, abs=1e-9)


def test_a_hinges_damping_is_not_applied_as_ambf_does_not(tmp_path):
    """AMBF never applies a revolute or prismatic joint's `damping` (afJoint::applyDamping is not
    called); the MJCF writer keeps it, as MJCF means it, and MuJoCo drops it where AMBF's bodies
    are asked for: the arm with `damping: 0.5` on its hinge spins down at its bodies' damping
    alone, as without it (4.94916 rad/s after 0.2 s). Measured with AMBF, the LND PSM's programs
    (its joints' damping 0.001-100) in MuJoCo: velocity 28.6 -> 7.8 mm, position 29.0 -> 23.7,
    effort 10.7 -> 1.3 mm. Control: with Options() the hinge's damping acts, integrated
    implicitly by MuJoCo: 5 / (1 + 0.001·0.5/0.0237875)^200 rad/s."""
    assert _spun(tmp_path / "a", "ambf", 0.5) == pytest.approx(_spun(tmp_path / "b", "ambf"), rel=1e-9)
    assert _spun(tmp_path / "c", None, 0.5) == pytest.approx(5.0 / (1 + 1e-3 * 0.5 / ABOUT_HINGE) ** 200, rel=1e-6)
