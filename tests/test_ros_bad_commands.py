"""Commands no one should send, sent the way clients in the field slip: NaN and inf through
AMBF's unmodified ambf_client and through plain rospy (a joint, a pose, a wrench, a twist, a
camera, the CRTK topics), a joint command type AMBF does not know, an actuator asked for a body
or sensor that is not there, a CRTK joint command with too few values. Each is refused with a
line saying why (AMBF's words where AMBF has some), the world stays finite, the last good command
holds, and `adfkit ros` keeps serving (before: one NaN joint command made psm1 NaN and stopped
the server with numpy's "SVD did not converge"; a NaN servo_jp stopped it at once)."""

from __future__ import annotations

import math
from types import SimpleNamespace as NS

import ros_support as rs

from adfkit.ros import guard


def _vec(x=0.0, y=0.0, z=0.0):
    return NS(x=x, y=y, z=z)


def _cmd(cart=0, force=(0.0, 0.0, 0.0), joint_cmds=(), types=()):
    pose = NS(position=_vec(), orientation=NS(x=0.0, y=0.0, z=0.0, w=1.0))
    return NS(
        cartesian_cmd_type=cart,
        wrench=NS(force=_vec(*force), torque=_vec()),
        pose=pose,
        twist=NS(linear=_vec(), angular=_vec()),
        joint_cmds=list(joint_cmds),
        joint_cmds_types=list(types),
    )


def test_guard_names_the_first_value_that_is_not_finite():
    nan, inf = float("nan"), float("inf")
    assert guard.body_cmd_fault(_cmd(joint_cmds=[0.1, 0.2], types=[1, 1]), 8) is None
    assert guard.body_cmd_fault(_cmd(joint_cmds=[0.1, nan], types=[1, 2]), 8) == "joint_cmds[1] is nan"
    assert guard.body_cmd_fault(_cmd(force=(0.0, inf, 0.0)), 0) == "wrench.force[1] is inf"
    # what never reaches a joint is not looked at: past the body's joints, or of an unknown type
    assert guard.body_cmd_fault(_cmd(joint_cmds=[0.1, nan], types=[1, 1]), 1) is None
    assert guard.body_cmd_fault(_cmd(joint_cmds=[nan], types=[7]), 8) is None
    # a pose command's wrench is not used: a NaN there is harmless
    bad_wrench_pose = _cmd(cart=1, force=(nan, 0.0, 0.0))
    assert guard.body_cmd_fault(bad_wrench_pose, 0) is None
    bad_wrench_pose.pose.orientation.w = nan
    assert guard.body_cmd_fault(bad_wrench_pose, 0) == "pose.orientation[3] is nan"
    assert guard.values_fault([0.1] * 2, "position", 6) == "position has 2 values, 6 needed"
    assert guard.values_fault([-inf], "position", 1) == "position is -inf"
    assert guard.values_fault([0.0] * 7, "velocity", 6) is None


def test_bad_commands_are_refused_and_the_server_keeps_serving(tmp_path):
    rs.require_client()
    paths = rs.ambf_client(tmp_path)
    out, alive, err = rs.served(rs.SAMPLE, lambda master: _drive(master, paths))
    assert alive and "Traceback" not in err, err
    assert all(map(math.isfinite, out["q_bad"])) and abs(out["q_bad"][0] - 0.2) < 0.01  # the last good one held
    assert all(map(math.isfinite, out["needle"]))
    assert all(map(math.isfinite, out["q_after"])) and abs(out["q_after"][0] + 0.1) < 0.01
    for said in (
        "/ambf/env/psm1/baselinksimple/Command ignored: joint_cmds[0] is nan",
        "/ambf/env/psm1/baselinksimple/Command ignored: joint_cmds[0] is inf",
        "/ambf/env/phantom/Needle/Command ignored: pose.position[0] is nan",
        'FOR JOINT "baselink-yawlink" COMMAND TYPE 7 NOT UNDERSTOOD',
        'CAN\'T FIND ANY OBJECTS NAMED: "NoSuchBody"',
        "REQUESTED SENSOR NAME NoSensor NOT FOUND. IGNORING!",
        "/CRTK/psm1/servo_jp ignored: position[0] is nan",
        "/CRTK/psm1/servo_jp ignored: position has 2 values, 6 needed",
        "/CRTK/psm1/jaw/servo_jp ignored: position is nan",
    ):
        assert said in err, (said, err)


def _drive(master, paths) -> dict:
    return rs.run_client(
        master,
        paths,
        """
        import json, math, time, rospy
        from ambf_client import Client
        from ambf_msgs.msg import ActuatorCmd, RigidBodyCmd
        from geometry_msgs.msg import PoseStamped
        from sensor_msgs.msg import JointState
        c = Client("t_bad"); c.connect(); time.sleep(0.3)
        base = c.get_obj_handle("psm1/baselink"); needle = c.get_obj_handle("Needle")
        time.sleep(0.3)
        def settle(j, goal):
            t = time.time()
            while time.time() - t < 10 and abs(base.get_joint_pos(j) - goal) > 2e-3:
                time.sleep(0.05)
        base.set_joint_pos(0, 0.2); settle(0, 0.2)
        for bad in (float("nan"), float("inf")):  # ambf_client re-sends it at 120 Hz
            base.set_joint_pos(0, bad); time.sleep(0.3)
        q_bad = base.get_all_joint_pos()
        P = lambda t, T: rospy.Publisher(t, T, queue_size=10)
        body = P("/ambf/env/phantom/Needle/Command", RigidBodyCmd)
        act = P("/ambf/env/ghosts/psm1/Actuator0/Command", ActuatorCmd)
        jp = P("/CRTK/psm1/servo_jp", JointState)
        jaw = P("/CRTK/psm1/jaw/servo_jp", JointState)
        time.sleep(1.0)
        nan_pose = RigidBodyCmd(cartesian_cmd_type=1); nan_pose.pose.position.x = float("nan")
        typed = RigidBodyCmd(joint_cmds=[0.0], joint_cmds_types=[7])
        wrong = ActuatorCmd(actuate=True); wrong.body_name.data = "NoSuchBody"
        blind = ActuatorCmd(actuate=True, use_sensor_data=True); blind.sensor_identifier.data = "NoSensor"
        for _ in range(20):
            body.publish(nan_pose)
            act.publish(wrong)
            jp.publish(JointState(position=[float("nan"), 0, 0.1, 0, 0, 0]))
            jaw.publish(JointState(position=[float("nan")]))
            time.sleep(0.01)
        for _ in range(10):
            act.publish(blind); jp.publish(JointState(position=[0.3, 0.0])); time.sleep(0.01)
        other = P("/ambf/env/psm2/baselinksimple/Command", RigidBodyCmd); time.sleep(0.5)
        for _ in range(10):
            other.publish(typed); time.sleep(0.01)
        n = needle.get_pos()
        base.set_joint_pos(0, -0.1); settle(0, -0.1)  # still served: a good command moves it
        q_after = base.get_all_joint_pos()
        print(json.dumps({"q_bad": q_bad, "needle": [n.x, n.y, n.z], "q_after": q_after}))
        """,
        timeout=90,
    )
