"""`adfkit ros` driven as the challenge drives AMBF: a ROS master on a free port, the bundled
suturing scene served, and AMBF's own unmodified ambf_client (from ../shared/ambf) in child
processes; the CRTK topics and a joystick through plain rospy."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import ros_support as rs
from conftest import ROOT

from adfkit.ros.teleop import JOY_SPEED

pytest.importorskip("pybullet")


@pytest.fixture(scope="module")
def ros(tmp_path_factory):
    rs.require_client()
    master = rs.Master()
    paths = rs.ambf_client(tmp_path_factory.mktemp("ambf"))
    # AMBF's 0.5 s watchdog, given 2 s: a client starved of the CPU for half a second on a loaded
    # machine (its 120 Hz command thread) let the world's step throttling lapse (3,749 steps for 50)
    server = rs.Server(
        master, rs.SAMPLE, "--teleop", "joy:/test_joy=psm2", "--teleop", "geomagic:/test_geo/=psm1", "--watchdog", "2"
    )
    yield master, paths, server
    err = server.close()
    master.close()
    assert "Traceback" not in err, err


def test_ambf_client_lists_reads_and_commands_psm1(ros):
    master, paths, server = ros
    out = rs.run_client(
        master,
        paths,
        """
        import json, time
        from ambf_client import Client
        c = Client("t_basics"); c.connect(); time.sleep(0.3)
        names = c.get_obj_names()
        base = c.get_obj_handle("psm1/baselink")
        needle = c.get_obj_handle("Needle")
        world = c.get_world_handle()
        time.sleep(0.3)
        q0 = base.get_all_joint_pos()
        base.set_joint_pos(0, q0[0] + 0.2)
        base.set_joint_pos("yawlink-pitchbacklink", q0[1] - 0.1)
        t = time.time()  # AMBF's joint controller (P 10, D 1 to a velocity motor) takes ~0.5 s of sim time
        while time.time() - t < 10 and abs(base.get_joint_pos(0) - q0[0] - 0.2) > 2e-3:
            time.sleep(0.05)
        time.sleep(0.2)
        q1 = base.get_all_joint_pos()
        p = needle.get_pos()
        v = needle.get_linear_vel()
        print(json.dumps({"names": names, "joints": list(base.get_joint_names()), "q0": q0, "q1": q1,
                          "needle": [p.x, p.y, p.z], "speed": (v.x**2 + v.y**2 + v.z**2) ** 0.5,
                          "step": world._state.sim_step, "mass": needle._state.mass,
                          "id": base.get_identifier()}))
        """,
    )
    names = out["names"]
    assert "World" in names and "/ambf/env/psm1/baselinksimple" in names and "/ambf/env/ghosts/psm1/Sensor0" in names
    assert len(names) == 79  # 70 bodies, 2 sensors, 2 actuators, 2 cameras, 2 lights, the world
    assert out["joints"][:2] == ["baselink-yawlink", "yawlink-pitchbacklink"] and len(out["joints"]) == 8
    assert out["id"] == "/ambf/env/psm1/BODY base link simple"
    dq = np.array(out["q1"]) - np.array(out["q0"])
    assert abs(dq[0] - 0.2) < 0.01 and abs(dq[1] + 0.1) < 0.01  # by index and by name
    assert np.all(np.abs(dq[2:]) < 0.01)  # the others held
    from adfkit.scenes.suturing import layout

    assert np.linalg.norm(np.array(out["needle"]) - layout.needle_start()[:3, 3]) < 2e-3  # lying where it was put
    assert out["speed"] < 0.01 and out["mass"] > 0 and out["step"] > 0


def test_challenge_style_script_grasps_the_needle_through_sensor_and_actuator(ros):
    """examples/ros/challenge_style.py: a PSM class on ambf_client (servo_cp, set_jaw_angle with
    the challenge's grasp logic, measured_cp) and a Scene (needle, Entry/Exit poses)."""
    master, paths, server = ros
    script = (ROOT / "examples" / "ros" / "challenge_style.py").read_text()
    out = rs.run_client(master, paths, script, timeout=90)
    assert out["reached_m"] < 5e-3  # the jaws come down onto the wire (they touch it)
    assert any(out["triggered"]) and out["sensed"] == "Needle"  # the jaws' sensor saw the needle
    assert out["lift_m"] > 0.015  # grasped by the actuator: it came up with the jaws
    assert out["needle_moved_m"] > 0.02 and out["needle_to_entry1_m"] < 0.01  # carried over Entry1
    from adfkit.scenes.suturing import layout

    for k in range(1, 5):
        entry, exit_ = layout.hole_poses(k)
        assert np.allclose(out["entries"][k - 1], entry[:3, 3], atol=1e-6)
        assert np.allclose(out["exits"][k - 1], exit_[:3, 3], atol=1e-6)


def test_reset_puts_the_scene_back(ros):
    master, paths, server = ros
    out = rs.run_client(
        master,
        paths,
        """
        import json, time
        from ambf_client import Client
        c = Client("t_reset"); c.connect(); time.sleep(0.3)
        needle = c.get_obj_handle("Needle")
        act = c.get_obj_handle("psm1/Actuator0")
        time.sleep(0.3)
        act.deactuate(); time.sleep(0.2)
        from adfkit.scenes.suturing import layout
        start = layout.needle_start()[:3, 3]
        lifted = (start[0], start[1], start[2] + 0.03)  # carry it away first: the test stands on its own
        t = time.time()
        while time.time() - t < 10:
            needle.set_pos(*lifted)
            p = needle.get_pos()
            if sum((a - b) ** 2 for a, b in zip((p.x, p.y, p.z), lifted)) ** 0.5 < 5e-3:
                break
            time.sleep(0.05)
        before = needle.get_pos(); before = [before.x, before.y, before.z]
        needle.set_force(0, 0, 0)  # let go: the pose command would hold it there through the reset
        time.sleep(0.3)  # topics are not ordered among themselves: the release lands before the reset
        step0 = c.get_world_handle()._state.sim_step
        c.get_world_handle().reset()
        t = time.time()  # the next loop step restores the scene; its state then comes at 50 Hz
        while time.time() - t < 5:
            p = needle.get_pos()
            if sum((a - b) ** 2 for a, b in zip((p.x, p.y, p.z), start)) ** 0.5 < 1e-3:
                break
            time.sleep(0.05)
        time.sleep(0.2)
        after = needle.get_pos(); after = [after.x, after.y, after.z]
        print(json.dumps({"before": before, "after": after, "steps": c.get_world_handle()._state.sim_step - step0}))
        """,
    )
    from adfkit.scenes.suturing import layout

    start = layout.needle_start()[:3, 3]
    assert np.linalg.norm(np.array(out["before"]) - start) > 0.01  # the client carried it away
    assert np.linalg.norm(np.array(out["after"]) - start) < 2e-3  # and reset brought it back
    assert out["steps"] > 0  # the clock ran on


def test_the_client_steps_the_world(ros):
    """AMBF's step throttling: each toggle of the step clock grants n_skip_steps steps."""
    master, paths, server = ros
    out = rs.run_client(
        master,
        paths,
        """
        import json, time
        from ambf_client import Client
        c = Client("t_step"); c.connect(); time.sleep(0.3)
        w = c.get_world_handle()
        w.set_active()  # the client's thread re-sends the world command: AMBF's 0.5 s watchdog stays fed
        # ambf_client's own world watchdog: when update() is not called for 2 s its thread turns
        # throttling off for good (World.run_publisher: clear_cmd), and the world runs free: on a box
        # loaded ~8 five steps took longer than that and 4,912 steps came for 50. Its time out is
        # the client's (WatchDog.set_timeout), not the server's; the steps granted are what is checked
        w.set_timeout(120.0)
        w.enable_throttling(True); w.set_num_step_skips(5)
        w.update()
        # the steps already granted (this update's five, any in flight) come first: on a loaded box
        # they take longer than 0.3 s, so wait for the clock to stand still (at most 30 s)
        last, t = w._state.sim_step, time.time()
        while time.time() - t < 30:
            time.sleep(0.3)
            if w._state.sim_step == last:
                break
            last = w._state.sim_step
        s0 = w._state.sim_step; time.sleep(0.3); held = w._state.sim_step - s0
        start = target = w._state.sim_step
        for _ in range(10):
            w.update()
            target += 5
            t = time.time()
            while w._state.sim_step < target and time.time() - t < 30:  # however slow the loaded box
                time.sleep(0.0005)
        time.sleep(0.3)
        steps = w._state.sim_step - start
        w.enable_throttling(False); w.update(); time.sleep(0.2)
        s1 = w._state.sim_step; t = time.time()
        while w._state.sim_step - s1 < 10 and time.time() - t < 5:  # free again (however loaded the box)
            time.sleep(0.01)
        print(json.dumps({"held": held, "steps": steps, "free": w._state.sim_step - s1}))
        """,
        timeout=360,
    )
    assert out["held"] == 0  # throttled, nothing moves without the clock
    assert out["steps"] == 50  # ten toggles of the step clock, five steps each
    assert out["free"] >= 10  # released: it runs on by itself


def test_crtk_topics_servo_and_measure_psm1(ros):
    master, paths, server = ros
    out = rs.run_client(
        master,
        [],
        """
        import json, time, rospy
        from sensor_msgs.msg import JointState
        from geometry_msgs.msg import PoseStamped
        rospy.init_node("t_crtk")
        got = {}
        rospy.Subscriber("/CRTK/psm1/measured_js", JointState, lambda m: got.__setitem__("js", m))
        rospy.Subscriber("/CRTK/psm1/measured_cp", PoseStamped, lambda m: got.__setitem__("cp", m))
        rospy.Subscriber("/CRTK/Needle/measured_cp", PoseStamped, lambda m: got.__setitem__("needle", m))
        pub = rospy.Publisher("/CRTK/psm1/servo_jp", JointState, queue_size=1)
        time.sleep(1.0)
        q = [0.3, -0.2, 0.12, 0.4, 0.1, -0.1]
        for _ in range(5):
            pub.publish(JointState(position=q)); time.sleep(0.1)
        time.sleep(1.0)
        js, cp = got["js"], got["cp"].pose
        print(json.dumps({"names": list(js.name), "q": list(js.position),
                          "p": [cp.position.x, cp.position.y, cp.position.z],
                          "o": [cp.orientation.x, cp.orientation.y, cp.orientation.z, cp.orientation.w],
                          "frame": got["cp"].header.frame_id, "needle": got["needle"].header.frame_id}))
        """,
    )
    q = [0.3, -0.2, 0.12, 0.4, 0.1, -0.1]
    assert np.allclose(out["q"], q, atol=5e-3)
    assert out["names"][0] == "baselink-yawlink" and out["frame"] == "psm1/baselink" and out["needle"] == "world"
    from adfkit.runner import psm_kinematics
    from adfkit.runner.rotations import quat_to_matrix

    fk = psm_kinematics.fk(out["q"])
    assert np.linalg.norm(fk[:3, 3] - out["p"]) < 1e-3  # measured_cp is the tool tip in the base frame
    assert np.allclose(quat_to_matrix(np.array(out["o"])), fk[:3, :3], atol=1e-2)


def test_a_joystick_moves_psm2_and_its_button_closes_the_jaw(ros):
    master, paths, server = ros
    out = rs.run_client(
        master,
        paths,
        """
        import json, time, rospy
        from sensor_msgs.msg import Joy
        from geometry_msgs.msg import PoseStamped
        from ambf_msgs.msg import RigidBodyState
        rospy.init_node("t_joy")
        got = {}
        rospy.Subscriber("/CRTK/psm2/measured_cp", PoseStamped, lambda m: got.__setitem__("cp", m))
        rospy.Subscriber("/ambf/env/psm2/baselinksimple/State", RigidBodyState, lambda m: got.__setitem__("base", m))
        pub = rospy.Publisher("/test_joy", Joy, queue_size=1)
        time.sleep(1.0)
        p0 = got["cp"].pose.position; p0 = [p0.x, p0.y, p0.z]
        s0 = got["base"].sim_time
        t = time.time()
        while time.time() - t < 1.0:
            pub.publish(Joy(axes=[0.0, 0.0, 1.0], buttons=[1])); time.sleep(0.02)
        s1 = got["base"].sim_time
        pub.publish(Joy(axes=[0.0, 0.0, 0.0], buttons=[1])); time.sleep(0.5)
        p1 = got["cp"].pose.position; p1 = [p1.x, p1.y, p1.z]
        closed = list(got["base"].joint_positions[6:8])
        pub.publish(Joy(axes=[0.0, 0.0, 0.0], buttons=[0])); time.sleep(0.8)
        opened = list(got["base"].joint_positions[6:8])
        print(json.dumps({"p0": p0, "p1": p1, "closed": closed, "opened": opened, "sim": s1 - s0}))
        """,
    )
    d = np.array(out["p1"]) - np.array(out["p0"])
    # up along the base's z at 2 cm/s of simulated time, for as long as the stick was held: about
    # 1 s of it on a quiet box; a loaded box plays slower than real time (1.3 mm moved at a load of 11)
    sim = out["sim"]
    assert sim > 0.02, out  # the world played while the stick was held
    assert 0.4 * JOY_SPEED * sim < d[2] < JOY_SPEED * sim + 0.005, (d, sim)
    assert abs(d[0]) < 1e-3 + 0.1 * d[2] and abs(d[1]) < 1e-3 + 0.1 * d[2]
    assert sum(out["closed"]) < 0.05  # the button held: the jaw closed (nothing between the jaws)
    assert sum(out["opened"]) > 0.4  # let go: open again


def test_a_geomagic_clutch_moves_psm1_by_the_scaled_stylus_motion(ros):
    """Grey button held (the clutch): the stylus's 50 mm along x is 10 mm of the tool (the
    challenge's 0.0002 scale); let go, the stylus moves freely."""
    master, paths, server = ros
    out = rs.run_client(
        master,
        [],
        """
        import json, time, rospy
        from adfkit.ros import msggen
        from pathlib import Path
        import adfkit.ros as pkg
        msggen.ensure(Path(pkg.__file__).parent / "geomagic_control", "geomagic_control")
        from geomagic_control.msg import DeviceButtonEvent
        from geometry_msgs.msg import PoseStamped
        rospy.init_node("t_geo")
        got = {}
        rospy.Subscriber("/CRTK/psm1/measured_cp", PoseStamped, lambda m: got.__setitem__("cp", m))
        pose = rospy.Publisher("/test_geo/pose", PoseStamped, queue_size=1)
        button = rospy.Publisher("/test_geo/button", DeviceButtonEvent, queue_size=1)
        time.sleep(1.0)
        def send(x, grey, seconds):
            t = time.time()
            while time.time() - t < seconds:
                m = PoseStamped(); m.pose.position.x = x; m.pose.orientation.w = 1.0
                pose.publish(m); button.publish(DeviceButtonEvent(grey_button=grey, white_button=0)); time.sleep(0.02)
        send(0.0, 1, 0.5)
        p0 = got["cp"].pose.position; p0 = [p0.x, p0.y, p0.z]
        for k in range(1, 21):
            send(2.5 * k, 1, 0.05)  # 50 mm in 1 s
        send(50.0, 1, 1.5)
        p1 = got["cp"].pose.position; p1 = [p1.x, p1.y, p1.z]
        # the clutch let go where the stylus stands, then the stylus moved: no motion (the button
        # and the pose are two topics, so a pose sent with the release may arrive before it)
        send(50.0, 0, 0.5)
        send(100.0, 0, 1.0)
        p2 = got["cp"].pose.position; p2 = [p2.x, p2.y, p2.z]
        print(json.dumps({"p0": p0, "p1": p1, "p2": p2}))
        """,
    )
    d = np.array(out["p1"]) - np.array(out["p0"])
    assert abs(d[0] - 0.01) < 2e-3 and abs(d[1]) < 1e-3 and abs(d[2]) < 1e-3
    assert np.linalg.norm(np.array(out["p2"]) - np.array(out["p1"])) < 1e-3


def test_no_master_is_a_located_error_not_a_traceback():
    rs.require_ros()
    port = rs.free_port()
    done = subprocess.run(
        [sys.executable, "-m", "adfkit", "ros", str(rs.SAMPLE), "--master", f"http://127.0.0.1:{port}"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2
    assert "error[ros-master]" in done.stderr and "Traceback" not in done.stderr


def test_a_camera_publishes_its_image_and_depth(tmp_path):
    """A box 0.9 m in front of a camera with `publish image` and `publish depth`: the image
    (rgb8, the file's resolution) shows the box's red in its centre and not in its corner; the
    depth cloud puts the box face 0.9 m ahead (AMBF's camera frame: -x ahead)."""
    rs.require_ros()
    from conftest import box_camera_model

    text = box_camera_model().replace(
        "  publish image resolution:",
        "  publish image: true\n  publish depth: true\n  publish image interval: 1\n  publish image resolution:",
    )
    model = tmp_path / "box.yaml"
    model.write_text("namespace: /ambf/env/\n" + text)
    master = rs.Master()
    server = rs.Server(master, model, "--images")
    try:
        out = rs.run_client(
            master,
            [],
            """
            import json, time, rospy, struct
            from sensor_msgs.msg import Image, PointCloud2
            rospy.init_node("t_cam")
            got = {}
            rospy.Subscriber("/ambf/env/cam/ImageData", Image, lambda m: got.__setitem__("img", m))
            rospy.Subscriber("/ambf/env/cam/DepthData", PointCloud2, lambda m: got.__setitem__("pc", m))
            t = time.time()
            while len(got) < 2 and time.time() - t < 20:
                time.sleep(0.05)
            img, pc = got["img"], got["pc"]
            px = lambda u, v: list(img.data[(v * img.width + u) * 3:(v * img.width + u) * 3 + 3])
            c = 24 * 64 + 32  # the centre pixel's point
            x, y, z = struct.unpack_from("<fff", pc.data, c * pc.point_step)
            print(json.dumps({"enc": img.encoding, "w": img.width, "h": img.height, "centre": px(32, 24),
                              "corner": px(1, 1), "n": pc.width * pc.height, "xyz": [x, y, z]}))
            """,
        )
    finally:
        err = server.close()
        master.close()
    assert "Traceback" not in err, err
    assert (out["enc"], out["w"], out["h"]) == ("rgb8", 64, 48) and out["n"] == 64 * 48
    r, g, b = out["centre"]
    assert r > 120 and r > 1.5 * g and r > 1.5 * b  # the box (red, lit)
    assert out["corner"] != out["centre"]
    assert abs(out["xyz"][0] + 0.9) < 0.02 and abs(out["xyz"][1]) < 0.02 and abs(out["xyz"][2]) < 0.02
