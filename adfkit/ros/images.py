"""Cameras on AMBF's image topics (VideoStreamerPlugin, DepthStreamerPlugin): a camera with
`publish image` sends ``<camera>/ImageData`` (sensor_msgs/Image, rgb8) every `publish image
interval` graphics frames, one with `publish depth` sends ``<camera>/DepthData``
(sensor_msgs/PointCloud2: x, y, z float32 and packed rgb, in the camera's frame: AMBF's, x
from what it looks at back to the eye, z up) every `publish depth interval` frames. The
graphics loop is 60 frames a second of wall time, as AMBF's at a 60 Hz display; a frame is
drawn only when someone listens."""

from __future__ import annotations

import time

import numpy as np

GRAPHICS_HZ = 60.0


class CameraStream:
    def __init__(self, bridge, handler) -> None:
        from sensor_msgs.msg import Image, PointCloud2, PointField

        rospy = bridge.rospy
        self.bridge, self.handler = bridge, handler
        c = handler.cams[0].camera
        self.image_every = max(int(c.publish_image_interval or 1), 1) / GRAPHICS_HZ
        self.depth_every = max(int(c.publish_depth_interval or 10), 1) / GRAPHICS_HZ
        self.image_pub = (
            rospy.Publisher(handler.obj.topic + "/ImageData", Image, queue_size=1) if c.publish_image else None
        )
        self.depth_pub = (
            rospy.Publisher(handler.obj.topic + "/DepthData", PointCloud2, queue_size=1) if c.publish_depth else None
        )
        self.Image, self.PointCloud2, self.PointField = Image, PointCloud2, PointField
        self.next_image = self.next_depth = 0.0

    def publish(self) -> None:
        now = time.monotonic()
        want_img = self.image_pub is not None and now >= self.next_image and self.image_pub.get_num_connections()
        want_depth = self.depth_pub is not None and now >= self.next_depth and self.depth_pub.get_num_connections()
        if not want_img and not want_depth:
            return
        cam = self.handler.cams[0]
        frame = cam.render(self.bridge.world, rgb_only=not want_depth)
        stamp = self.bridge.rospy.Time.now()
        if want_img:
            self.next_image = now + self.image_every
            self.image_pub.publish(self.image_msg(frame["rgb"], stamp, cam.name))
        if want_depth:
            self.next_depth = now + self.depth_every
            self.depth_pub.publish(self.cloud_msg(cam, frame, stamp))

    def image_msg(self, rgb: np.ndarray, stamp, frame_id: str):
        h, w = rgb.shape[:2]
        msg = self.Image(height=h, width=w, encoding="rgb8", is_bigendian=0, step=3 * w)
        msg.data = np.ascontiguousarray(rgb[..., :3], dtype=np.uint8).tobytes()
        msg.header.stamp, msg.header.frame_id = stamp, frame_id
        return msg

    def cloud_msg(self, cam, frame: dict, stamp):
        depth = np.asarray(frame["depth"], np.float32)
        h, w = depth.shape
        k = cam.intrinsics()
        u, v = np.meshgrid(np.arange(w, dtype=np.float32), np.arange(h, dtype=np.float32))
        z = np.where(np.isfinite(depth), depth, np.nan)
        x_opt = (u + 0.5 - k[0, 2]) / k[0, 0] * z  # right
        y_opt = (v + 0.5 - k[1, 2]) / k[1, 1] * z  # down
        pts = np.zeros((h * w,), dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("pad", "<f4"), ("rgb", "<u4")])
        pts["x"], pts["y"], pts["z"] = (-z).ravel(), x_opt.ravel(), (-y_opt).ravel()  # AMBF: x back, y right, z up
        rgb = np.asarray(frame["rgb"], np.uint32)[..., :3].reshape(-1, 3)
        pts["rgb"] = (rgb[:, 0] << 16) | (rgb[:, 1] << 8) | rgb[:, 2]
        f = self.PointField
        msg = self.PointCloud2(height=1, width=h * w, is_bigendian=False, point_step=20, row_step=20 * h * w)
        msg.fields = [
            f(name="x", offset=0, datatype=f.FLOAT32, count=1),
            f(name="y", offset=4, datatype=f.FLOAT32, count=1),
            f(name="z", offset=8, datatype=f.FLOAT32, count=1),
            f(name="rgb", offset=16, datatype=f.FLOAT32, count=1),
        ]
        msg.is_dense = False
        msg.data = pts.tobytes()
        msg.header.stamp, msg.header.frame_id = stamp, self.handler.obj.name
        return msg
