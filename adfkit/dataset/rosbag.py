"""An episode as a ROS 1 bag (``adfkit suture --record --format rosbag``), written with the
``rosbags`` library (pure Python; no ROS needed), for rosbag, rqt_bag and Foxglove:

    /ambf/env/cameras/<camera>/ImageData    sensor_msgs/Image rgb8 (AMBF's image topic)
    /ambf/env/cameras/<camera>/depth        sensor_msgs/Image 32FC1, metres along the optical axis
    /ambf/env/cameras/<camera>/camera_info  sensor_msgs/CameraInfo (K, P; no distortion)
    /joint_states                           sensor_msgs/JointState: each PSM's q1..q6 and jaw
    /tf                                     tf2_msgs/TFMessage: world -> Needle, psmN/base,
                                            psmN/tool, and each camera's optical frame

Each frame is stamped with the simulated time after the episode's start (the bag's clock
starts at the wall-clock second it was made). Written to a temporary name and renamed when
closed, so a failed episode leaves no half bag under the final name."""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

from ..runner.rotations import matrix_to_quat
from ..scratch import temp_beside
from .writer import camera_to_world

TF_MESSAGE = "geometry_msgs/TransformStamped[] transforms"


def _typestore():
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC)
    if "tf2_msgs/msg/TFMessage" not in ts.types:
        ts.register(get_types_from_msg(TF_MESSAGE, "tf2_msgs/msg/TFMessage"))
    return ts


def _frame_id(name: str) -> str:
    return name.strip("/").replace(" ", "_") or "world"


class RosbagWriter:
    """The DatasetWriter's interface (``write(step, poses, phase)``, ``frames``, ``close()``)."""

    def __init__(self, world, path, cameras=None) -> None:
        from rosbags.rosbag1 import Writer

        self.world, self.path = world, Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        # a name of this process's own (two recordings into one folder do not share it); the
        # writer creates the file itself
        fd, tmp = temp_beside(self.path, ".part")
        os.close(fd)
        self.tmp = Path(tmp)
        self.tmp.unlink()
        self.ts = _typestore()
        self.types = self.ts.types
        self.cameras = [c for c in world.cameras if cameras is None or c.name in cameras]
        self.t0 = int(time.time()) * 10**9
        self.writer = Writer(self.tmp)
        self.writer.open()
        self.conn = {}
        for cam in self.cameras:
            base = f"/ambf/env/cameras/{cam.name}"
            self._connect(f"{base}/ImageData", "sensor_msgs/msg/Image")
            self._connect(f"{base}/depth", "sensor_msgs/msg/Image")
            self._connect(f"{base}/camera_info", "sensor_msgs/msg/CameraInfo")
        self._connect("/joint_states", "sensor_msgs/msg/JointState")
        self._connect("/tf", "tf2_msgs/msg/TFMessage")
        self.frames = 0
        self.seq = 0

    def _connect(self, topic: str, msgtype: str) -> None:
        self.conn[topic] = (self.writer.add_connection(topic, msgtype, typestore=self.ts), msgtype)

    def _put(self, topic: str, msg, stamp_ns: int) -> None:
        conn, msgtype = self.conn[topic]
        self.writer.write(conn, stamp_ns, bytes(self.ts.serialize_ros1(msg, msgtype)))

    def _header(self, stamp_ns: int, frame: str):
        t = self.types
        self.seq += 1
        return t["std_msgs/msg/Header"](
            seq=self.seq,
            stamp=t["builtin_interfaces/msg/Time"](sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9),
            frame_id=frame,
        )

    def _transform(self, stamp_ns: int, parent: str, child: str, m: np.ndarray):
        t = self.types
        q = matrix_to_quat(np.asarray(m)[:3, :3])
        p = np.asarray(m)[:3, 3]
        return t["geometry_msgs/msg/TransformStamped"](
            header=self._header(stamp_ns, parent),
            child_frame_id=child,
            transform=t["geometry_msgs/msg/Transform"](
                translation=t["geometry_msgs/msg/Vector3"](x=float(p[0]), y=float(p[1]), z=float(p[2])),
                rotation=t["geometry_msgs/msg/Quaternion"](x=float(q[0]), y=float(q[1]), z=float(q[2]), w=float(q[3])),
            ),
        )

    def _image(self, stamp_ns: int, frame: str, data: np.ndarray, encoding: str):
        h, w = data.shape[:2]
        step = data.strides[0]
        return self.types["sensor_msgs/msg/Image"](
            header=self._header(stamp_ns, frame),
            height=h,
            width=w,
            encoding=encoding,
            is_bigendian=0,
            step=step,
            data=np.frombuffer(np.ascontiguousarray(data).tobytes(), dtype=np.uint8),
        )

    def write(self, step: int, poses: dict, phase: str = "") -> list:
        """One frame: every camera's image, depth and intrinsics, the PSMs' joints, the frames."""
        t = self.types
        stamp = self.t0 + int(round(self.world.sim_time * 1e9))
        tfs = []
        if poses.get("needle") is not None:
            tfs.append(self._transform(stamp, "world", "Needle", poses["needle"]))
        names, q = [], []
        for psm, state in poses.get("psms", {}).items():
            if "T_world_base" in state:
                tfs.append(self._transform(stamp, "world", f"{psm}/base", state["T_world_base"]))
            tfs.append(self._transform(stamp, "world", f"{psm}/tool", state["T_world_ee"]))
            names += [f"{psm}/q{i + 1}" for i in range(len(state["jp"]))] + [f"{psm}/jaw"]
            q += [float(v) for v in state["jp"]] + [float(state["jaw"])]
        for cam in self.cameras:
            frame = cam.render(self.world)
            optical = f"{_frame_id(cam.name)}_optical"
            base = f"/ambf/env/cameras/{cam.name}"
            tfs.append(self._transform(stamp, "world", optical, camera_to_world(*cam.view(self.world))))
            rgb = np.ascontiguousarray(np.asarray(frame["rgb"], dtype=np.uint8)[..., :3])
            depth = np.ascontiguousarray(np.asarray(frame["depth"], dtype=np.float32))
            self._put(f"{base}/ImageData", self._image(stamp, optical, rgb, "rgb8"), stamp)
            self._put(f"{base}/depth", self._image(stamp, optical, depth, "32FC1"), stamp)
            k = cam.intrinsics()
            info = t["sensor_msgs/msg/CameraInfo"](
                header=self._header(stamp, optical),
                height=cam.height,
                width=cam.width,
                distortion_model="plumb_bob",
                D=np.zeros(5),
                K=k.ravel().astype(float),
                R=np.eye(3).ravel(),
                P=np.hstack([k, np.zeros((3, 1))]).ravel().astype(float),
                binning_x=0,
                binning_y=0,
                roi=t["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0, do_rectify=False),
            )
            self._put(f"{base}/camera_info", info, stamp)
            self.frames += 1
        if names:
            js = t["sensor_msgs/msg/JointState"](
                header=self._header(stamp, ""),
                name=names,
                position=np.array(q, dtype=float),
                velocity=np.zeros(0),
                effort=np.zeros(0),
            )
            self._put("/joint_states", js, stamp)
        self._put("/tf", t["tf2_msgs/msg/TFMessage"](transforms=tfs), stamp)
        return []

    def close(self) -> None:
        self.writer.close()
        self.tmp.replace(self.path)
