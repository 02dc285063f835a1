"""MuJoCo's joints under position and velocity commands as AMBF's motor rows (a constraint row at
the joint's cfm between the joint's two bodies: runner/mujoco/motor_rows.py, joint_commands.py),
where AMBF's bodies are asked for; real MuJoCo and PyBullet, no mocks."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("mujoco")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402
from adfkit.runner.joint_commands import JointCommands  # noqa: E402
from adfkit.scenes.parity import write_parity  # noqa: E402

# the parity arm: 0.0037875 kg·m² about its centre, 0.0237875 about its hinge on a static base
ROW, ABOUT_HINGE = 0.0037875, 0.0237875


def _one_step_at(tmp_path, engine: str, bodies: str | None, chain_step: bool = True):
    opt = Options(visuals=False, control_substeps=1, ground=False)
    if bodies is not None:
        opt.bodies = bodies
    w = open_world(load_scene(write_parity(tmp_path), [1]), opt, engine=engine)
    try:
        if not chain_step:  # the rows settled (joint_commands.soft_row_impulses), as for a chain it cannot read
            w.chain_velocities = lambda *a: None
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
    the target after one step; AMBF's ten solver iterations leave it short of that, at 0.584 in
    both engines (the chain step). Control: with PyBullet's bodies (Options()) the row is infinite
    and the joint follows its stiff drive, whose target moved 1 mrad: a quarter of the target
    speed after the first step (measured: 0.25), not the row's 0.614."""
    row, mobility, qd = _one_step_at(tmp_path / "a", "mujoco", "ambf", chain_step=False)
    assert row == pytest.approx(ROW, rel=1e-9)
    assert mobility == pytest.approx(1 / ABOUT_HINGE, rel=1e-6)
    assert qd == pytest.approx(1 / (1 + 0.1 * ABOUT_HINGE / ROW), rel=1e-4)
    pb_row, _m, pb_qd = _one_step_at(tmp_path / "b", "pybullet", "ambf")
    assert pb_row == pytest.approx(ROW, rel=1e-9)
    ten = _one_step_at(tmp_path / "d", "mujoco", "ambf")[2]
    assert ten == pytest.approx(pb_qd, rel=1e-4) and ten == pytest.approx(0.5837, abs=1e-3)
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


# a chain of a hinge across gravity, a hinge across that and a slider, on a static base
CHAIN = """\
bodies: [BODY base, BODY upper, BODY fore, BODY slide]
joints: [JOINT base-upper, JOINT upper-fore, JOINT fore-slide]
namespace: /ambf/env/chain3/
BODY base:
  name: base
  collision shape: BOX
  collision geometry: {x: 0.05, y: 0.05, z: 0.05}
  location: {position: {x: 0.0, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  mass: 0.0
BODY upper:
  name: upper
  collision shape: BOX
  collision geometry: {x: 0.3, y: 0.03, z: 0.03}
  location: {position: {x: 0.15, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  mass: 0.5
  inertia: {ix: 7.5e-05, iy: 0.0037875, iz: 0.0037875}
BODY fore:
  name: fore
  collision shape: BOX
  collision geometry: {x: 0.2, y: 0.02, z: 0.02}
  location: {position: {x: 0.4, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  mass: 0.2
  inertia: {ix: 1.3e-05, iy: 0.00067, iz: 0.00067}
BODY slide:
  name: slide
  collision shape: BOX
  collision geometry: {x: 0.04, y: 0.04, z: 0.04}
  location: {position: {x: 0.5, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  mass: 0.1
  inertia: {ix: 2.7e-05, iy: 2.7e-05, iz: 2.7e-05}
JOINT base-upper:
  name: base-upper
  parent: BODY base
  child: BODY upper
  type: revolute
  parent pivot: {x: 0.0, y: 0.0, z: 0.0}
  child pivot: {x: -0.15, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 1.0, z: 0.0}
  child axis: {x: 0.0, y: 1.0, z: 0.0}
  joint limits: {low: -2.0, high: 2.0}
JOINT upper-fore:
  name: upper-fore
  parent: BODY upper
  child: BODY fore
  type: revolute
  parent pivot: {x: 0.15, y: 0.0, z: 0.0}
  child pivot: {x: -0.1, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 0.0, z: 1.0}
  child axis: {x: 0.0, y: 0.0, z: 1.0}
  joint limits: {low: -2.0, high: 2.0}
JOINT fore-slide:
  name: fore-slide
  parent: BODY fore
  child: BODY slide
  type: prismatic
  parent pivot: {x: 0.1, y: 0.0, z: 0.0}
  child pivot: {x: 0.0, y: 0.0, z: 0.0}
  parent axis: {x: 1.0, y: 0.0, z: 0.0}
  child axis: {x: 1.0, y: 0.0, z: 0.0}
  joint limits: {low: -0.05, high: 0.05}
"""


def _chain_played(tmp_path, engine: str, chain_step: bool = True) -> np.ndarray:
    """The chain's three joints (position and velocity) every 50 ms over 0.3 s, each driven by a
    velocity command (0.5 rad/s, -1 rad/s, 0.05 m/s) under AMBF's bodies."""
    path = tmp_path / f"chain_{engine}_{chain_step}.yaml"
    path.write_text(CHAIN)
    opt = Options(visuals=False, control_substeps=1, ground=False)
    opt.bodies = "ambf"
    w = open_world(load_scene(path, None), opt, engine=engine)
    try:
        if not chain_step:  # the motor rows settled together instead (joint_commands.soft_row_impulses)
            w.chain_velocities = lambda *a: None
        jc = JointCommands(w)
        made = {r[0].name: r for r in w.joints_made}
        for name, v in (("base-upper", 0.5), ("upper-fore", -1.0), ("fore-slide", 0.05)):
            joint, _parent, child = made[name]
            jc.command(joint, child, "velocity", v)
        dj = jc.joints[id(made["base-upper"][0])]
        out = []
        for k in range(300):
            jc.apply(k * w.dt)
            w.step(1)
            if k % 50 == 49:
                out.append(np.concatenate(w.joint_state(dj.art, [0, 1, 2])))
        return np.array(out)
    finally:
        w.close()


def test_a_driven_chain_takes_ambfs_ten_iterations_in_mujoco_as_in_pybullet(tmp_path):
    """AMBF's ten solver iterations do not settle a chain's motor rows; both engines play that
    step on the chain's bodies (runner/chain_step.py) and read it from their own state: MuJoCo's
    joints follow PyBullet's within 0.03 mrad and 0.03 mm/s (measured 3.0e-5), where the rows
    settled together (MuJoCo without the chain step, what it played before) are 4.0e-3 apart."""
    pybullet = _chain_played(tmp_path, "pybullet")
    mujoco_ = _chain_played(tmp_path, "mujoco")
    assert np.abs(pybullet - mujoco_).max() < 2e-4
    assert pybullet[-1, 0] == pytest.approx(0.1658, abs=1e-3)  # 0.5 rad/s under gravity's load
    assert np.abs(pybullet - _chain_played(tmp_path, "mujoco", chain_step=False)).max() > 2e-3
