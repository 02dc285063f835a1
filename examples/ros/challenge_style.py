"""A client in the style of the surgical robotics challenge's scripts, on AMBF's own
``ambf_client`` (nothing of adfkit's server side): a ``PSM`` class (``servo_jp``, ``servo_cp``,
``measured_jp``, ``measured_cp``, ``set_jaw_angle`` with the challenge's grasp logic through
the jaws' sensor and the constraint actuator) and a ``Scene`` class (the needle's and the
Entry/Exit holes' poses). Run against ``adfkit ros`` (or AMBF itself) on the suturing scene:

    adfkit ros sample_scenes/suturing &
    python -m adfkit.ros.pyrun --path AMBF/ambf_ros_modules/ambf_client/python --ambf-msgs \\
        examples/ros/challenge_style.py

It picks the needle up with psm1, lifts it, carries it above Entry1 and prints what it saw as
one JSON line. The PSM's kinematics (the closed-form IK of the dVRK PSM, as the challenge's
``psmKinematics``) come from ``adfkit.runner.psm_kinematics``, plain numpy."""

from __future__ import annotations

import json
import math
import sys
import time

import numpy as np
from ambf_client import Client

from adfkit.runner import psm_kinematics
from adfkit.runner.rotations import matrix_to_quat, pose_matrix
from adfkit.scenes.suturing import layout

RATE = 120.0  # Hz, the challenge's control rate


def frame(obj) -> np.ndarray:
    """4x4 pose of an ambf_client object (its State's pose)."""
    p, q = obj.get_pos(), obj.get_rot()
    return pose_matrix([p.x, p.y, p.z], [q.x, q.y, q.z, q.w])


class PSM:
    def __init__(self, client: Client, name: str) -> None:
        self.name = name
        self.base = client.get_obj_handle(name + "/baselink")
        self.sensor = client.get_obj_handle(name + "/Sensor0")
        self.actuators = [client.get_obj_handle(name + "/Actuator0")]
        time.sleep(0.5)
        self.kd = psm_kinematics.default()
        self.grasped = [False]
        self.graspable_objs_prefix = ["Needle", "Thread", "Puzzle"]
        self.sensed = ""

    def get_T_b_w(self) -> np.ndarray:
        return frame(self.base)

    def servo_jp(self, jp) -> None:
        for i in range(6):
            self.base.set_joint_pos(i, float(jp[i]))

    def measured_jp(self) -> list[float]:
        return [self.base.get_joint_pos(i) for i in range(6)]

    def servo_cp(self, T_t_b: np.ndarray) -> None:
        q = self.kd.ik(T_t_b, check_limits=False)
        self.servo_jp(np.clip(q, self.kd.lower_limits[:6], self.kd.upper_limits[:6]))  # enforce_limits

    def measured_cp(self) -> np.ndarray:
        return self.kd.fk(self.measured_jp())

    def wait_until_at(self, T_t_b: np.ndarray, tolerance: float = 5e-4, timeout: float = 5.0) -> None:
        """Wait for the measured tool pose to come within ``tolerance`` (m) of ``T_t_b``: a simulator
        behind the wall clock (a loaded machine) still gets there before the script goes on."""
        t = time.time()
        while time.time() - t < timeout:
            if np.linalg.norm(self.measured_cp()[:3, 3] - T_t_b[:3, 3]) < tolerance:
                return
            time.sleep(1.0 / RATE)

    def move_cp(self, T_t_b: np.ndarray, seconds: float) -> None:
        """servo_cp along a straight line at the control rate (the challenge's move_cp interpolates)."""
        start = self.measured_cp()
        n = max(1, int(seconds * RATE))
        for k in range(1, n + 1):
            s = k / n
            t = T_t_b.copy()
            t[:3, 3] = (1 - s) * start[:3, 3] + s * T_t_b[:3, 3]
            self.servo_cp(t)
            time.sleep(1.0 / RATE)

    def set_jaw_angle(self, jaw_angle: float) -> None:
        self.base.set_joint_pos(6, jaw_angle)
        self.base.set_joint_pos(7, jaw_angle)
        self.run_grasp_logic(jaw_angle)

    def run_grasp_logic(self, jaw_angle: float) -> None:
        """The challenge's: closed, the first triggered ray's sensed object is actuated on."""
        for i in range(len(self.actuators)):
            if jaw_angle <= 0.2:
                if self.sensor is not None:
                    for r in range(self.sensor.get_count()):
                        if self.sensor.is_triggered(r):
                            sensed_obj = self.sensor.get_sensed_object(r)
                            if any(s in sensed_obj for s in self.graspable_objs_prefix) and not self.grasped[i]:
                                self.actuators[i].actuate(sensed_obj)
                                self.grasped[i] = True
                                self.sensed = sensed_obj
                            break
            else:
                self.actuators[i].deactuate()
                self.grasped[i] = False


class Scene:
    def __init__(self, client: Client) -> None:
        self._needle = client.get_obj_handle("Needle")
        self._entry = [client.get_obj_handle(f"phantom/Entry{k}") for k in range(1, 5)]
        self._exit = [client.get_obj_handle(f"phantom/Exit{k}") for k in range(1, 5)]
        time.sleep(0.1)

    def needle_measured_cp(self) -> np.ndarray:
        return frame(self._needle)

    def entry_measured_cp(self, k: int) -> np.ndarray:
        return frame(self._entry[k - 1])

    def exit_measured_cp(self, k: int) -> np.ndarray:
        return frame(self._exit[k - 1])


def main() -> int:
    client = Client("challenge_style")
    client.connect()
    time.sleep(0.5)
    psm, scene = PSM(client, "psm1"), Scene(client)
    if psm.base is None or scene._needle is None:
        print(json.dumps({"error": "no psm1 or Needle on the ROS master"}))
        return 1
    t_b_w = psm.get_T_b_w()
    to_base = np.linalg.inv(t_b_w)
    needle0 = scene.needle_measured_cp()
    angle = layout.NEEDLE_GRASP_ANGLE
    grasp = to_base @ layout.grasp_ee_pose(needle0, angle, layout.shaft_direction("psm1", needle0, angle))
    above = grasp.copy()
    above[:3, 3] += to_base[:3, :3] @ np.array([0.0, 0.0, 0.02])
    psm.set_jaw_angle(0.4)
    psm.move_cp(above, 1.0)
    psm.move_cp(grasp, 0.6)
    psm.wait_until_at(grasp, 2e-3)
    time.sleep(0.4)
    reached = float(np.linalg.norm(psm.measured_cp()[:3, 3] - grasp[:3, 3]))
    triggered = [bool(psm.sensor.is_triggered(r)) for r in range(psm.sensor.get_count())]
    psm.set_jaw_angle(0.0)
    time.sleep(0.3)
    psm.move_cp(above, 0.8)
    psm.wait_until_at(above, 2e-3)
    time.sleep(0.4)
    needle1 = scene.needle_measured_cp()
    entry1 = scene.entry_measured_cp(1)
    carry = above.copy()
    carry[:3, 3] = (to_base @ np.r_[entry1[:3, 3] + [0.0, 0.0, 0.03], 1.0])[:3]
    psm.move_cp(carry, 1.0)
    psm.wait_until_at(carry, 2e-3)
    time.sleep(0.4)
    needle2 = scene.needle_measured_cp()
    out = {
        "reached_m": reached,
        "triggered": triggered,
        "sensed": psm.sensed,
        "lift_m": float(needle1[2, 3] - needle0[2, 3]),
        "needle_moved_m": float(np.linalg.norm(needle2[:3, 3] - needle1[:3, 3])),
        "needle_to_entry1_m": float(np.linalg.norm(needle2[:2, 3] - entry1[:2, 3])),
        "needle_quat": [float(x) for x in matrix_to_quat(needle2[:3, :3])],
        "entries": [scene.entry_measured_cp(k)[:3, 3].tolist() for k in range(1, 5)],
        "exits": [scene.exit_measured_cp(k)[:3, 3].tolist() for k in range(1, 5)],
        "tip_height_m": float(needle2[2, 3]),
        "jaw": [psm.base.get_joint_pos(6), psm.base.get_joint_pos(7)],
        "angle": math.degrees(angle),
    }
    print(json.dumps(out))
    sys.stdout.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
