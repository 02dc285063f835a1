"""The PSM API of the runner (adfkit/runner/psm.py): the challenge's LND 400006 PSM played in
real PyBullet, driven through the closed-form IK."""

from __future__ import annotations

import math
import re
import shutil

import numpy as np
import pytest
from conftest import CORPUS, require_corpus

pb = pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402
from adfkit.runner.psm import PSM, PSMModelError, hand_eye  # noqa: E402
from adfkit.runner.psm_kinematics import pose_error  # noqa: E402
from adfkit.runner.rotations import invert  # noqa: E402

PSM1 = "src/ADF/PSMs/LND_400006_SIMPLE/psm1.yaml"


@pytest.fixture(scope="module")
def psm():
    require_corpus()
    world = open_world(load_scene(CORPUS / PSM1), Options(visuals=False, ground=False))
    yield PSM(world, "psm1")
    world.close()


def _random_pose(rng, T):
    """T moved by up to 2 cm and turned by up to 0.3 rad about a random axis."""
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    a = rng.uniform(-0.3, 0.3)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    out = T.copy()
    out[:3, :3] = T[:3, :3] @ (np.eye(3) + math.sin(a) * k + (1 - math.cos(a)) * k @ k)
    out[:3, 3] += rng.uniform(-0.02, 0.02, size=3)
    return out


def test_hand_eye_recovers_known_frames():
    rng = np.random.default_rng(3)

    def rand_pose():
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        x, y, z, w = q
        t = np.eye(4)
        t[:3, :3] = [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
        t[:3, 3] = rng.normal(size=3)
        return t

    b, y = rand_pose(), rand_pose()
    model = [rand_pose() for _ in range(6)]
    world = [b @ f @ y for f in model]
    b2, y2 = hand_eye(world, model)
    assert np.abs(b2 - b).max() < 1e-9 and np.abs(y2 - y).max() < 1e-9


def test_model_follows_the_dh_kinematics(psm):
    # the file's rounding of offsets and pivots: 0.1 mm / 0.1 mrad
    assert psm.calibration_error < 3e-4
    # the model's base body frame is the DH base frame (the RCM) to the file's rounding
    assert pose_error(psm.base_to_dh, np.eye(4)) < 1e-3
    assert pose_error(psm.measured_cp(), psm.kin.fk(psm.measured_jp())) < 3e-4


def test_servo_jp_and_measured_cp_agree_with_fk(psm):
    world = psm.world
    q = np.array([0.3, -0.2, 0.1, 0.5, -0.4, 0.3])
    psm.servo_jp(q)
    world.run(1.0)
    assert np.abs(psm.measured_jp() - q).max() < 1e-3
    assert pose_error(psm.measured_cp(), psm.kin.fk(q)) < 1e-3
    assert np.allclose(psm.setpoint_cp(), psm.kin.fk(q))


def test_servo_cp_reaches_poses_through_the_ik(psm):
    rng = np.random.default_rng(5)
    world = psm.world
    psm.servo_jp([0.0, 0.0, 0.12, 0.0, 0.0, 0.0])
    world.run(0.5)
    for _ in range(3):
        goal = _random_pose(rng, psm.kin.fk([0.0, 0.0, 0.12, 0.0, 0.0, 0.0]))
        q = psm.servo_cp(goal)
        assert pose_error(psm.kin.fk(q), goal) < 1e-7  # the IK solution itself
        world.run(0.8)
        assert pose_error(psm.measured_cp(), goal) < 1e-3  # the played arm got there


def test_move_cp_follows_a_straight_line(psm):
    world = psm.world
    psm.servo_jp([0.0, 0.0, 0.12, 0.0, 0.0, 0.0])
    world.run(0.5)
    start = psm.measured_cp()
    goal = start.copy()
    goal[:3, 3] += [0.03, -0.02, 0.01]
    seen = []
    world_step = world.step

    def spy(n=1):
        world_step(n)
        seen.append(psm.measured_cp()[:3, 3].copy())

    world.step = spy
    try:
        psm.move_cp(goal, 0.4)
    finally:
        del world.step
    world.run(0.3)
    assert pose_error(psm.measured_cp(), goal) < 1e-3
    d = goal[:3, 3] - start[:3, 3]
    d /= np.linalg.norm(d)
    off_line = [np.linalg.norm((p - start[:3, 3]) - np.dot(p - start[:3, 3], d) * d) for p in seen]
    assert max(off_line) < 2e-3 and len(seen) == 100


def test_bad_set_points_are_refused_with_the_joint_named(psm):
    with pytest.raises(ValueError, match=r"outer_insertion|insertion"):
        psm.servo_jp([0.0, 0.0, 0.5, 0.0, 0.0, 0.0])
    far = np.eye(4)
    far[:3, 3] = [0.0, 0.0, -1.0]  # 1 m from the RCM: beyond the insertion range
    with pytest.raises(ValueError):
        psm.servo_cp(far)


def test_jaw_set_point(psm):
    psm.servo_jaw(0.6)
    psm.world.run(0.5)
    assert psm.measured_jaw() == pytest.approx(0.6, abs=0.02)


def test_a_model_that_is_not_a_psm_is_refused(tmp_path):
    require_corpus()
    text = (CORPUS / PSM1).read_text()
    # the first arm joint turned by 0.3 rad at zero: the tool no longer moves as the DH model says
    bent = re.sub(
        r"(JOINT yaw link-pitch back link:\n(?:  .*\n|    .*\n)*?  offset: )(-?[0-9.]+)",
        lambda m: m.group(1) + str(float(m.group(2)) + 0.3),
        text,
        count=1,
    )
    assert bent != text
    (tmp_path / "psm1.yaml").write_text(bent)
    for res in ("high_res", "low_res"):  # a body whose visual mesh is not there is not made (AMBF)
        shutil.copytree(CORPUS / PSM1.rsplit("/", 1)[0] / res, tmp_path / res)
    world = open_world(load_scene(tmp_path / "psm1.yaml"), Options(visuals=False, ground=False))
    try:
        with pytest.raises(PSMModelError, match=r"residual"):
            PSM(world, "psm1")
        with pytest.raises(KeyError, match=r"/psm2/"):
            PSM(world, "psm2")
    finally:
        world.close()


def test_tool_in_base_matches_the_calibrated_frames(psm):
    # consistency of the two calibrated frames with a fresh configuration
    q = np.array([-0.5, 0.4, 0.15, -1.0, 0.8, -0.6])
    uid, cid = psm.art.uid, psm.world.cid
    saved = [pb.getJointState(uid, i, physicsClientId=cid)[0] for i in psm.arm]
    for i, v in zip(psm.arm, q):
        pb.resetJointState(uid, i, float(v), physicsClientId=cid)
    try:
        tool_in_base = invert(psm.base.world_matrix()) @ psm.tool.world_matrix()
        assert pose_error(psm.base_to_dh @ psm.kin.fk(q) @ psm.ee_to_tool, tool_in_base) < 3e-4
    finally:
        for i, v in zip(psm.arm, saved):
            pb.resetJointState(uid, i, v, physicsClientId=cid)
