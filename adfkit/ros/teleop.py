"""Teleoperation over ROS: an input device moves a PSM's Cartesian target, which the arm
reaches through its IK (``PSM.reach``, as the viewer's target does); a button closes the jaw
and grasps (the CRTK jaw logic).

- ``geomagic=psm1``: a Geomagic Touch as its ROS driver publishes it (the challenge's
  ``GeomagicDevice``): ``<prefix>pose`` (geometry_msgs/PoseStamped, mm) and ``<prefix>button``
  (geomagic_control/DeviceButtonEvent); prefix ``/Geomagic/``. While the grey button (the
  clutch) is held, the target follows the stylus: its motion since the clutch, scaled by
  ``GEOMAGIC_SCALE``, and its turn; the white button closes the jaw while held.
- ``joy=psm2``: a ``sensor_msgs/Joy`` on ``<prefix>`` (``/joy``): axes 0-2 move the target
  along the PSM base's x, y, z at up to ``JOY_SPEED`` m/s, axes 3-5 turn it about them at up to
  ``JOY_TURN`` rad/s; button 0 closes the jaw while held."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..diagnostics import AdfError, error
from ..runner.rotations import rotation_exp
from .crtk import msg_matrix
from .guard import pose_fault

GEOMAGIC_SCALE = 0.0002  # the challenge's: device mm to 0.2 mm of tool motion
JOY_SPEED = 0.02  # m/s at full deflection
JOY_TURN = 0.5  # rad/s at full deflection
JAW_OPEN = 0.8  # rad: the jaw when the button is released
DEFAULT_PREFIX = {"geomagic": "/Geomagic/", "joy": "/joy"}


def parse(spec: str) -> tuple[str, str, str]:
    """'geomagic=psm1', 'joy:/my_joy=psm2' -> (device, topic prefix, psm)."""
    head, sep, psm = spec.partition("=")
    device, _, prefix = head.partition(":")
    if not sep or device not in DEFAULT_PREFIX or not psm:
        raise AdfError(
            error(
                "bad-option",
                f"--teleop {spec!r}: expected DEVICE=PSM with DEVICE geomagic or joy",
                None,
                "e.g. --teleop geomagic=psm1 or --teleop joy:/joy=psm2",
            )
        )
    return device, prefix or DEFAULT_PREFIX[device], psm


class Teleop:
    """Common part: the PSM, its CRTK jaw logic, the target it holds."""

    def __init__(self, crtk, psm_name: str) -> None:
        arm = next((p for p in crtk.psms if p.name == psm_name), None) if crtk is not None else None
        if arm is None:
            raise AdfError(
                error(
                    "bad-option", f"--teleop: the scene has no PSM {psm_name!r} the PSM kinematics describe", None, None
                )
            )
        self.crtk, self.arm = crtk, arm
        self.target: np.ndarray | None = None
        self.jaw_closed = False

    def _jaw(self, closed: bool) -> None:
        if closed != self.jaw_closed:
            self.jaw_closed = closed
            self.arm._jaw(0.0 if closed else JAW_OPEN)

    def _reach(self, pose: np.ndarray) -> None:
        try:
            self.crtk.bridge.yield_body(self.arm.psm.base)
            self.arm.psm.reach(pose)
            self.target = pose
        except ValueError as exc:
            self.crtk.bridge.note(f"teleop {self.arm.name}: target out of reach ({exc}); held where it was")


class GeomagicTeleop(Teleop):
    def __init__(self, crtk, psm_name: str, prefix: str) -> None:
        super().__init__(crtk, psm_name)
        from geometry_msgs.msg import PoseStamped

        from . import msggen

        msggen.ensure(Path(__file__).parent / "geomagic_control", "geomagic_control")
        from geomagic_control.msg import DeviceButtonEvent

        rospy = crtk.rospy
        self.pose = None
        self.clutch = self.grip = False
        self.anchor = None  # (device pose, PSM target) when the clutch closed
        self.subs = [
            rospy.Subscriber(prefix + "pose", PoseStamped, self._on_pose, queue_size=1),
            rospy.Subscriber(prefix + "button", DeviceButtonEvent, self._on_button, queue_size=1),
        ]

    def _on_pose(self, msg) -> None:
        why = pose_fault(msg.pose)
        if why:  # guard.py: the target is never NaN
            self.crtk.bridge.note(f"teleop {self.arm.name}: a device pose ignored: {why}")
            return
        t = msg_matrix(msg.pose)
        t[:3, 3] *= GEOMAGIC_SCALE
        self.pose = t

    def _on_button(self, msg) -> None:
        self.clutch, self.grip = bool(msg.grey_button), bool(msg.white_button)

    def apply(self) -> None:
        self._jaw(self.grip)
        if not self.clutch or self.pose is None:
            self.anchor = None
            return
        if self.anchor is None:
            self.anchor = (self.pose.copy(), self.arm.psm.setpoint_cp())
            return
        dev0, psm0 = self.anchor
        goal = psm0.copy()
        goal[:3, 3] = psm0[:3, 3] + (self.pose[:3, 3] - dev0[:3, 3])
        goal[:3, :3] = self.pose[:3, :3] @ dev0[:3, :3].T @ psm0[:3, :3]
        self._reach(goal)


class JoyTeleop(Teleop):
    def __init__(self, crtk, psm_name: str, topic: str) -> None:
        super().__init__(crtk, psm_name)
        from sensor_msgs.msg import Joy

        self.axes = np.zeros(6)
        self.button = False
        self.sub = crtk.rospy.Subscriber(topic, Joy, self._on_joy, queue_size=1)

    def _on_joy(self, msg) -> None:
        a = np.zeros(6)
        n = min(6, len(msg.axes))
        a[:n] = np.clip(np.nan_to_num(np.asarray(msg.axes[:n], float), nan=0.0), -1.0, 1.0)  # NaN: at rest
        self.axes = a
        self.button = bool(msg.buttons[0]) if len(msg.buttons) else False

    def apply(self) -> None:
        self._jaw(self.button)
        if not np.any(self.axes):
            self.target = None
            return
        w = self.crtk.bridge.world
        dt = w.dt * w.opt.control_substeps
        base = self.target if self.target is not None else self.arm.psm.setpoint_cp()
        goal = base.copy()
        goal[:3, 3] += self.axes[:3] * JOY_SPEED * dt
        goal[:3, :3] = rotation_exp(self.axes[3:] * JOY_TURN * dt) @ base[:3, :3]
        self._reach(goal)


def make_teleops(bridge, crtk, specs: list[str]) -> list[Teleop]:
    out: list[Teleop] = []
    for spec in specs:
        device, prefix, psm = parse(spec)
        out.append(GeomagicTeleop(crtk, psm, prefix) if device == "geomagic" else JoyTeleop(crtk, psm, prefix))
    return out
