"""A PSM of a played scene driven like the dVRK/CRTK arms of the suturing challenge: joint and
Cartesian set-points through the paper's closed-form inverse kinematics (psm_kinematics.py).

    psm = PSM(world, "psm1")
    psm.measured_cp()              # 4x4 end-effector pose in the PSM base (RCM) frame
    psm.servo_cp(T)                # IK, then the joint position motors take T
    psm.move_cp(T, seconds=0.5)    # the same along a straight line, stepping the world
    psm.servo_jaw(0.0); psm.grasp(True)

The ADF model and the DH parameters describe the same arm in different frames: the DH base
frame sits somewhere in the model's base body, the DH end-effector frame somewhere in the
wrist body. Both constant transforms are found from the played model itself (hand-eye
calibration over joint configurations within the limits) and checked: where the model does
not follow the DH kinematics, ``PSM`` refuses it with the residual it measured.
"""

from __future__ import annotations

import numpy as np

from .psm_kinematics import PSMKinematics, default, pose_error
from .rotations import invert, rotation_exp, rotation_log

#: ADF joint names of the arm (dVRK order q1..q6) and of the two jaw fingers, as in the
#: suturing challenge's PSM files (LND 400006)
ARM_JOINTS = (
    "base link-yaw link",
    "yaw link-pitch back link",
    "pitch end link-main insertion link",
    "main insertion link-tool roll link",
    "tool roll link-tool pitch link",
    "tool pitch link-tool yaw link",
)
JAW_JOINTS = ("tool yaw link-tool gripper1 link", "tool yaw link-tool gripper2 link")
CALIBRATION_TOLERANCE = 1e-3  # m and rad: how far the model may be from the DH kinematics
JAW_OPEN = 0.8  # rad between the fingers when a grasp is released


class PSMModelError(ValueError):
    """The played model is not a PSM the DH kinematics describe."""


def hand_eye(world_poses, model_poses) -> tuple[np.ndarray, np.ndarray]:
    """B and Y with world_poses[i] = B · model_poses[i] · Y for every i (Park & Martin's
    closed form on the motions relative to the first pose). Needs motions about at least two
    non-parallel axes."""
    w0, f0 = world_poses[0], model_poses[0]
    a = [w @ invert(w0) for w in world_poses[1:]]
    c = [f @ invert(f0) for f in model_poses[1:]]
    alpha = np.array([rotation_log(x[:3, :3]) for x in a])
    beta = np.array([rotation_log(x[:3, :3]) for x in c])
    u, _s, vt = np.linalg.svd(beta.T @ alpha)
    d = np.diag([1.0, 1.0, np.sign(np.linalg.det(vt.T @ u.T))])
    rb = vt.T @ d @ u.T
    m = np.vstack([x[:3, :3] - np.eye(3) for x in a])
    rhs = np.concatenate([rb @ y[:3, 3] - x[:3, 3] for x, y in zip(a, c)])
    b = np.eye(4)
    b[:3, :3] = rb
    b[:3, 3] = np.linalg.lstsq(m, rhs, rcond=None)[0]
    return b, invert(f0) @ invert(b) @ w0


class PSM:
    """One PSM of a SimWorld (see the module docstring)."""

    def __init__(
        self, world, name: str = "psm1", kinematics: PSMKinematics | None = None, samples: int = 12, seed: int = 0
    ) -> None:
        self.world, self.name = world, name
        self.kin = kinematics or default()
        tag = f"/{name}/"
        arts = [a for a in world.articulations if tag in a.root.key]
        if len(arts) != 1:
            found = ", ".join(a.root.key for a in world.articulations) or "none"
            raise KeyError(f"no single multibody under the namespace {tag!r} (multibodies: {found})")
        self.art = art = arts[0]
        by_name = {r[0].name or r[0].identifier.removeprefix("JOINT "): n for n, r in enumerate(art.records)}
        missing = [j for j in ARM_JOINTS + JAW_JOINTS if j not in by_name]
        if missing:
            raise PSMModelError(
                f"{name}: the model lacks the PSM joints {', '.join(missing)}; it has {', '.join(sorted(by_name))}"
            )
        self.arm = [by_name[j] for j in ARM_JOINTS]
        self.jaws = [by_name[j] for j in JAW_JOINTS]
        self.base = art.root
        self.tool = art.records[self.arm[-1]][3]
        self.base_to_dh, self.ee_to_tool, self.calibration_error = self._calibrate(samples, seed)

    # ---- calibration ---------------------------------------------------------------------
    def _tool_in_base(self) -> np.ndarray:
        return invert(self.base.world_matrix()) @ self.tool.world_matrix()

    def _calibrate(self, samples: int, seed: int):
        """Constant frames between the model's bodies and the DH frames, from the model's own
        joint motion; the joints are put back where they were."""
        saved = self.world.joint_state(self.art, self.arm)
        rng = np.random.default_rng(seed)
        lo, hi = self.kin.lower_limits[:6], self.kin.upper_limits[:6]
        mid = (lo + hi) / 2
        qs = [mid] + [mid + 0.8 * (rng.random(6) - 0.5) * (hi - lo) for _ in range(samples)]
        world_poses, model_poses = [], []
        try:
            for q in qs:
                self.world.reset_joints(self.art, self.arm, q)
                world_poses.append(self._tool_in_base())
                model_poses.append(self.kin.fk(q))
        finally:
            self.world.reset_joints(self.art, self.arm, *saved)
        b, y = hand_eye(world_poses, model_poses)
        err = max(pose_error(b @ f @ y, w) for w, f in zip(world_poses, model_poses))
        if err > CALIBRATION_TOLERANCE:
            raise PSMModelError(
                f"{self.name}: the model's joints do not move its tool as the PSM's DH "
                f"kinematics do (residual {err:.3g} m/rad after calibration); check the "
                "joint axes, offsets and order of the arm"
            )
        return b, y, err

    # ---- frames --------------------------------------------------------------------------
    def base_in_world(self) -> np.ndarray:
        """Pose of the DH base frame (the RCM) in the world."""
        return self.base.world_matrix() @ self.base_to_dh

    # ---- joint space -------------------------------------------------------------------
    def measured_jp(self) -> np.ndarray:
        """q1..q6 as the simulation has them."""
        return self.world.joint_state(self.art, self.arm)[0]

    def setpoint_jp(self) -> np.ndarray:
        return np.array([self.art.targets[i] for i in self.arm])

    def servo_jp(self, q) -> None:
        """Joint position set-point for q1..q6; values outside the DH limits are refused."""
        q = np.asarray(q, dtype=float)
        bad = self.kin.violations(q)
        if bad:
            raise ValueError(
                "joint values outside the PSM's limits: "
                + ", ".join(f"{n} = {v:.4g} (limits {lo:.4g}…{hi:.4g})" for n, v, lo, hi in bad)
            )
        for i, v in zip(self.arm, q):
            self.art.targets[i] = float(v)
        self.art.drive()

    def reset_jp(self, q) -> None:
        """Put q1..q6 at ``q`` at once, at rest, and hold them there (a reset, not a motion)."""
        q = np.asarray(q, dtype=float)
        self.world.reset_joints(self.art, self.arm, q)
        self.servo_jp(q)

    # ---- Cartesian space ---------------------------------------------------------------
    def measured_cp(self) -> np.ndarray:
        """End-effector pose T_E^0 in the DH base frame, from the simulated bodies."""
        return invert(self.base_to_dh) @ self._tool_in_base() @ invert(self.ee_to_tool)

    def setpoint_cp(self) -> np.ndarray:
        return self.kin.fk(self.setpoint_jp())

    def servo_cp(self, pose) -> np.ndarray:
        """Cartesian set-point (4x4 in the DH base frame) through the closed-form IK; returns
        the joint values commanded. Unreachable poses and limit violations raise ValueError."""
        q = self.kin.ik(np.asarray(pose, dtype=float))
        self.servo_jp(q)
        return q

    def reach(self, pose, jump: bool = False) -> np.ndarray:
        """A Cartesian target (4x4 in the DH base frame) through the IK: the joint motors take it
        (``jump``: the joints are put there at once, at rest, as a reset). Returns the joint
        values; an unreachable pose or a limit violation is a ValueError and changes nothing.
        The viewer's target and the ROS teleoperation both aim the arm with this."""
        q = self.kin.ik(np.asarray(pose, dtype=float))
        if jump:
            self.reset_jp(q)
        else:
            self.servo_jp(q)
        return q

    def move_cp(self, pose, seconds: float) -> None:
        """Go to ``pose`` along a straight line (orientation interpolated about one axis) in
        ``seconds``, a set-point each control step, stepping the world."""
        start = self.setpoint_cp()
        goal = np.asarray(pose, dtype=float)
        steps = max(1, int(round(seconds / (self.world.dt * self.world.opt.control_substeps))))
        axis_angle = rotation_log(start[:3, :3].T @ goal[:3, :3])
        for n in range(1, steps + 1):
            s = n / steps
            t = np.eye(4)
            t[:3, :3] = start[:3, :3] @ rotation_exp(s * axis_angle)
            t[:3, 3] = (1 - s) * start[:3, 3] + s * goal[:3, 3]
            self.servo_cp(t)
            self.world.step(1)

    # ---- jaw and grasp -------------------------------------------------------------------
    def measured_jaw(self) -> float:
        """Angle between the two fingers, rad."""
        return float(sum(self.world.joint_state(self.art, self.jaws)[0]))

    def servo_jaw(self, angle: float) -> None:
        """Open the fingers ``angle`` rad apart (each finger takes half)."""
        for i in self.jaws:
            self.art.targets[i] = float(angle) / 2
        self.art.drive()

    def grasp(self, on: bool):
        """Close the jaws and fix what lies between them to the tool (the scene's constraint
        actuator), or release it and open them. Returns the grasped body, or None."""
        got = self.world.grasp(self.name, on)
        self.servo_jaw(0.0 if on else JAW_OPEN)
        return got
