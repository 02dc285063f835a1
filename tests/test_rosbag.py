"""`adfkit suture --record --format rosbag`: the episode as a ROS 1 bag written by rosbags, read
back by rosbags and, where Debian's ROS is installed, by ROS's own rosbag (an independent reader)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import box_camera_model

pytest.importorskip("pybullet")
pytest.importorskip("rosbags")

from adfkit.adf import load_scene
from adfkit.cli import main
from adfkit.dataset.rosbag import RosbagWriter
from adfkit.runner import Options, open_world


def _bag(tmp_path):
    model = tmp_path / "box.yaml"
    model.write_text(box_camera_model())
    world = open_world(load_scene(model, None, []), Options())
    needle = np.eye(4)
    needle[:3, 3] = (0.1, 0.2, 0.3)
    ee = np.eye(4)
    ee[:3, 3] = (0.0, 0.05, 0.1)
    poses = {
        "needle": needle,
        "psms": {"psm1": {"T_world_ee": ee, "T_world_base": np.eye(4), "jp": [0.1] * 6, "jaw": 0.4}},
    }
    bag = tmp_path / "out" / "episode.bag"
    try:
        w = RosbagWriter(world, bag)
        for step in range(3):
            world.step(10)
            w.write(step, poses)
        assert not bag.exists()  # written under a temporary name until closed
        w.close()
    finally:
        world.close()
    return bag


def test_the_bag_reads_back_with_images_depth_joints_and_tf(tmp_path):
    from rosbags.highlevel import AnyReader

    bag = _bag(tmp_path)
    seen: dict[str, list] = {}
    with AnyReader([bag]) as reader:
        for conn, t, raw in reader.messages():
            seen.setdefault(conn.topic, []).append((t, reader.deserialize(raw, conn.msgtype), conn.msgtype))
    assert {topic: len(v) for topic, v in seen.items()} == {
        "/ambf/env/cameras/cam/ImageData": 3,
        "/ambf/env/cameras/cam/depth": 3,
        "/ambf/env/cameras/cam/camera_info": 3,
        "/joint_states": 3,
        "/tf": 3,
    }
    _, img, kind = seen["/ambf/env/cameras/cam/ImageData"][0]
    assert kind == "sensor_msgs/msg/Image" and (img.width, img.height, img.encoding) == (64, 48, "rgb8")
    rgb = np.asarray(img.data).reshape(48, 64, 3)
    assert rgb[24, 32, 0] > 120 and rgb[24, 32, 0] > 1.5 * rgb[24, 32, 1]  # the red box in the middle
    _, depth, _ = seen["/ambf/env/cameras/cam/depth"][0]
    d = np.frombuffer(bytes(depth.data), dtype=np.float32).reshape(48, 64)
    assert depth.encoding == "32FC1" and abs(d[24, 32] - 0.9) < 0.02  # the box's face 0.9 m away
    _, js, _ = seen["/joint_states"][0]
    assert list(js.name) == [f"psm1/q{i}" for i in range(1, 7)] + ["psm1/jaw"] and js.position[-1] == 0.4
    _, tf, _ = seen["/tf"][0]
    frames = {x.child_frame_id: x for x in tf.transforms}
    assert set(frames) == {"Needle", "psm1/base", "psm1/tool", "cam_optical"}
    n = frames["Needle"].transform.translation
    assert (n.x, n.y, n.z) == (0.1, 0.2, 0.3)
    stamps = [t for t, _, _ in seen["/tf"]]
    assert np.allclose(np.diff(stamps), 10 * 4e-3 * 1e9)  # simulated time: 10 control steps of 4 ms


def test_ros_own_rosbag_opens_it(tmp_path):
    """Debian's rosbag (python3-rosbag, with ROS 1) reads what rosbags wrote, MD5 sums and all."""
    from adfkit.ros.env import ros_available

    why = ros_available()
    if why:
        pytest.skip(f"ROS 1 is not installed here (make ros): {why}")
    try:
        import rosbag
    except ImportError:
        pytest.skip("Debian's python3-rosbag is not installed")
    bag = _bag(tmp_path)
    with rosbag.Bag(str(bag)) as b:
        info = b.get_type_and_topic_info()
        counts = {t: v.message_count for t, v in info.topics.items()}
        types = {t: v.msg_type for t, v in info.topics.items()}
        msgs = list(b.read_messages(topics=["/tf"]))
    assert counts["/tf"] == 3 and types["/tf"] == "tf2_msgs/TFMessage"
    assert types["/ambf/env/cameras/cam/ImageData"] == "sensor_msgs/Image"
    assert {x.child_frame_id for x in msgs[0].message.transforms} >= {"Needle", "psm1/tool"}


def test_format_without_record_is_a_usage_error(capsys):
    assert main(["suture", "--format", "rosbag"]) == 2
    assert "error[bad-option]" in capsys.readouterr().err
