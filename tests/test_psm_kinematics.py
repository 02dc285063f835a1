"""PSM (LND 400006) kinematics: FK against poses derived by hand, closed-form IK round trips,
joint-limit checking. Pure numpy, fast."""

from __future__ import annotations

import numpy as np
import pytest

from adfkit.runner.psm_kinematics import (
    L_PITCH2YAW,
    L_TOOL2RCM,
    JointLimitError,
    PSMKinematics,
    UnreachablePoseError,
    fk,
    ik,
    pose_error,
    signed_angle,
)

KIN = PSMKinematics()
LO, HI = KIN.lower_limits[:6], KIN.upper_limits[:6]

# Home pose derived by hand from the DH table: the shaft points down -z0 through the RCM
# (base origin); the wrist pitch point sits L_tool2rcm = 0.4389 - 0.416 = 0.0229 m above
# the RCM at q3 = 0, the yaw point (= control point) L_pitch2yaw = 0.009 m further down,
# at z = 0.0139; x_E = y0, y_E = x0, z_E = -z0.
HOME = np.array(
    [
        [0.0, 1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, -1.0, 0.0139],
        [0.0, 0.0, 0.0, 1.0],
    ]
)


def rot(axis, angle) -> np.ndarray:
    """4x4 rotation about a unit axis through the origin (Rodrigues)."""
    k = np.asarray(axis, dtype=float)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    T = np.eye(4)
    T[:3, :3] = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
    return T


def trans(p) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = p
    return T


def about_line(axis, point, angle) -> np.ndarray:
    return trans(point) @ rot(axis, angle) @ trans(-np.asarray(point, dtype=float))


X, Y, Z = np.eye(3)


def poe(q) -> np.ndarray:
    """Independent FK as a product of exponentials with the joint axes read off the home pose:
    outer yaw about -y0 and outer pitch about -x0 (both through the RCM), insertion along -z0,
    roll about -z0, wrist pitch about -x0 through the pitch point (0, 0, 0.0229), wrist yaw
    about -y0 through the yaw point (0, 0, 0.0139)."""
    q1, q2, q3, q4, q5, q6 = q
    return (
        rot(-Y, q1)
        @ rot(-X, q2)
        @ trans(-q3 * Z)
        @ rot(-Z, q4)
        @ about_line(-X, [0, 0, L_TOOL2RCM], q5)
        @ about_line(-Y, [0, 0, L_TOOL2RCM - L_PITCH2YAW], q6)
        @ HOME
    )


def random_configs(n, seed):
    return np.random.default_rng(seed).uniform(LO, HI, size=(n, 6))


# ---------------------------------------------------------------- forward kinematics


def test_fk_home_pose():
    np.testing.assert_allclose(fk(np.zeros(6)), HOME, atol=1e-12)
    assert HOME[2, 3] == pytest.approx(0.4389 - 0.416 - 0.009)


def test_fk_insertion_moves_along_the_shaft():
    T = fk([0, 0, 0.1, 0, 0, 0])
    np.testing.assert_allclose(T[:3, :3], HOME[:3, :3], atol=1e-12)
    np.testing.assert_allclose(T[:3, 3], [0, 0, 0.0139 - 0.1], atol=1e-12)


def test_fk_outer_yaw_rotates_about_base_y_through_rcm():
    # q1 = 0.5 at 0.1 m insertion: the control point swings in the x-z plane,
    # to (0.0861 sin 0.5, 0, -0.0861 cos 0.5)
    T = fk([0.5, 0, 0.1, 0, 0, 0])
    np.testing.assert_allclose(T[:3, 3], [0.0861 * np.sin(0.5), 0, -0.0861 * np.cos(0.5)], atol=1e-12)
    np.testing.assert_allclose(T, rot(-Y, 0.5) @ fk([0, 0, 0.1, 0, 0, 0]), atol=1e-12)


def test_fk_outer_pitch_rotates_about_base_x_through_rcm():
    T = fk([0, 0.4, 0.1, 0, 0, 0])
    np.testing.assert_allclose(T[:3, 3], [0, -0.0861 * np.sin(0.4), -0.0861 * np.cos(0.4)], atol=1e-12)
    np.testing.assert_allclose(T, rot(-X, 0.4) @ fk([0, 0, 0.1, 0, 0, 0]), atol=1e-12)


def test_fk_roll_and_wrist_by_hand():
    # roll turns the end frame about the shaft (-z0) and leaves the point on the axis
    np.testing.assert_allclose(fk([0, 0, 0, 0.7, 0, 0]), rot(-Z, 0.7) @ HOME, atol=1e-12)
    # wrist pitch 0.3: the 9 mm palm swings about -x0 through the pitch point:
    # yaw point = (0, -0.009 sin 0.3, 0.0229 - 0.009 cos 0.3)
    T = fk([0, 0, 0, 0, 0.3, 0])
    np.testing.assert_allclose(T[:3, 3], [0, -0.009 * np.sin(0.3), 0.0229 - 0.009 * np.cos(0.3)], atol=1e-12)
    # wrist yaw turns the frame about -y0 at the control point; the point stays put
    T = fk([0, 0, 0, 0, 0, -0.6])
    np.testing.assert_allclose(T[:3, 3], HOME[:3, 3], atol=1e-12)
    np.testing.assert_allclose(T[:3, :3], rot(-Y, -0.6)[:3, :3] @ HOME[:3, :3], atol=1e-12)


def test_fk_matches_product_of_exponentials():
    for q in random_configs(200, seed=11):
        np.testing.assert_allclose(KIN.fk(q), poe(q), atol=1e-12)


def test_fk_all_frames_and_jaw():
    q = np.array([0.2, -0.3, 0.12, 0.5, -0.4, 0.3])
    frames = KIN.fk_all(q)
    assert frames.shape == (8, 4, 4)
    np.testing.assert_allclose(frames[0], np.eye(4))
    np.testing.assert_allclose(frames[7], KIN.fk(q))
    # frames 1, 2 sit at the RCM; the pitch point (frames 4, 5) is q3 - 0.0229 down the shaft
    np.testing.assert_allclose(frames[1][:3, 3], 0, atol=1e-15)
    np.testing.assert_allclose(frames[2][:3, 3], 0, atol=1e-15)
    assert np.linalg.norm(frames[4][:3, 3]) == pytest.approx(0.12 - L_TOOL2RCM, abs=1e-12)
    np.testing.assert_allclose(frames[5][:3, 3], frames[4][:3, 3], atol=1e-15)
    assert np.linalg.norm(frames[6][:3, 3] - frames[5][:3, 3]) == pytest.approx(0.009, abs=1e-12)
    # the jaw does not move the end frame
    np.testing.assert_allclose(KIN.fk(np.append(q, 0.8)), KIN.fk(q), atol=0)
    with pytest.raises(ValueError, match="6 joint values"):
        KIN.fk([0, 0, 0])


def test_limits_arrays():
    np.testing.assert_allclose(KIN.lower_limits, [-1.588, -0.925025, 0, -3.05433, -1.39626, -1.39626, -0.698132])
    np.testing.assert_allclose(KIN.upper_limits, [1.588, 0.925025, 0.24, 3.05433, 1.39626, 1.39626, 1.39626])
    assert KIN.joint_names[2] == "outer_insertion" and KIN.joint_names[6] == "jaw"


# ---------------------------------------------------------------- inverse kinematics


def test_ik_round_trip_500_random_configurations():
    worst_pose = worst_q = 0.0
    for q in random_configs(500, seed=2024):
        T = KIN.fk(q)
        q_ik = KIN.ik(T)
        assert KIN.within_limits(q_ik)
        worst_pose = max(worst_pose, pose_error(KIN.fk(q_ik), T))
        worst_q = max(worst_q, float(np.abs(q_ik - q).max()))
    assert worst_pose < 1e-9  # FK(IK(T)) = T, metres and radians
    assert worst_q < 1e-8  # IK(FK(q)) = q: the limits leave one solution


def test_ik_deep_insertion_uses_the_reference_branch():
    # q3 > L_tool2rcm: steps 1-3 of the reference directly (q3 = |P| + L_tool2rcm)
    q = np.array([-0.8, 0.6, 0.2, 2.5, -1.2, 1.3])
    np.testing.assert_allclose(ik(fk(q)), q, atol=1e-10)


def test_ik_tool_tip_behind_the_rcm():
    # 0 <= q3 < 0.0229: the pitch point is on the far side of the RCM
    for q in ([0.3, -0.2, 0.005, 0.4, 0.9, -1.0], [-1.2, 0.8, 0.0, -2.9, -1.3, 1.3]):
        np.testing.assert_allclose(ik(fk(q)), q, atol=1e-10)


def test_ik_with_a_control_point_beyond_the_yaw_axis():
    # step 1 with L2 != 0 (the classic dVRK 10.6 mm yaw-to-tip): the yaw point is -L2 along z_E
    kin = PSMKinematics(l_yaw2ctrlpnt=0.0106)
    T0 = kin.fk(np.zeros(6))
    assert T0[2, 3] == pytest.approx(0.0139 - 0.0106, abs=1e-12)
    for q in random_configs(100, seed=5):
        np.testing.assert_allclose(kin.ik(kin.fk(q)), q, atol=1e-9)


def test_ik_at_joint_limits():
    for q in (LO, HI):
        q_ik = KIN.ik(KIN.fk(q))
        np.testing.assert_allclose(q_ik, q, atol=1e-9)
        assert KIN.within_limits(q_ik)


def test_ik_out_of_reach_insertion_is_reported():
    T = fk([0.1, 0.1, 0.40, 0, 0, 0])  # the pitch point 0.377 m from the RCM
    with pytest.raises(JointLimitError) as info:
        ik(T)
    assert [v[0] for v in info.value.violations] == ["outer_insertion"]
    assert info.value.violations[0][1] == pytest.approx(0.40, abs=1e-12)
    assert "outer_insertion = 0.4 outside [0, 0.24]" in str(info.value)
    assert isinstance(info.value, ValueError)
    np.testing.assert_allclose(KIN.ik(T, check_limits=False), [0.1, 0.1, 0.40, 0, 0, 0], atol=1e-12)


def test_ik_out_of_reach_yaw_and_wrist_are_reported():
    q = np.array([2.0, 0.0, 0.15, 0.0, 1.5, 0.0])
    with pytest.raises(JointLimitError) as info:
        KIN.ik(KIN.fk(q))
    assert [v[0] for v in info.value.violations] == ["outer_yaw", "outer_wrist_pitch"]
    np.testing.assert_allclose(info.value.q, q, atol=1e-10)
    assert KIN.violations(np.append(q, 2.0))[-1][0] == "jaw"


def test_ik_rejects_malformed_poses():
    with pytest.raises(ValueError, match="4x4"):
        KIN.ik(np.eye(3))
    bad = HOME.copy()
    bad[:3, :3] *= 2.0
    with pytest.raises(ValueError, match="rotation"):
        KIN.ik(bad)
    at_rcm = np.eye(4)  # the yaw point at the RCM on the x_E axis: no palm direction
    with pytest.raises(UnreachablePoseError):
        KIN.ik(at_rcm)


def test_signed_angle():
    assert signed_angle(X, Y, Z) == pytest.approx(np.pi / 2)
    assert signed_angle(X, Y, -Z) == pytest.approx(-np.pi / 2)
    assert signed_angle(X, X * 3.0, Z) == 0.0
    assert abs(signed_angle(X, np.array([1.0, 1e-10, 0]), Z) - 1e-10) < 1e-20
