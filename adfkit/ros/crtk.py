"""The CRTK topics of the suturing challenge, served natively (the challenge's
``launch_crtk_interface.py`` serves the same names from its own process on top of
ambf_client), so that a script written against ``/CRTK/...`` runs without the challenge's code:

- each PSM (``/CRTK/psm1/``): ``measured_js`` (sensor_msgs/JointState), ``measured_cp`` (the
  tool tip in the PSM base frame, PoseStamped), ``T_b_w`` (the base in the world); commands
  ``servo_jp``, ``move_jp``, ``servo_jv`` (JointState), ``servo_cp``, ``move_cp`` (PoseStamped,
  the closed-form IK of runner/psm_kinematics.py, joint values clamped to the limits as the
  challenge's ``enforce_limits`` does) and ``jaw/servo_jp`` (the jaw angle; below
  ``GRASP_JAW`` the grasp: the constraint actuator takes what the jaws' sensor or ghosts hold);
- the ECM (``/CRTK/ecm/``): ``measured_cp`` (the camera frame body in the world),
  ``measured_js``, and ``servo_cp`` to move it;
- the scene: ``/CRTK/Needle/measured_cp``, ``/CRTK/Entry1..4/measured_cp``, ``/CRTK/Exit1..4/measured_cp``.

Published at ``RATE_HZ`` (the challenge's 120 Hz); commands are taken between physics steps."""

from __future__ import annotations

import time

import numpy as np

from ..runner.rotations import matrix_to_quat, pose_matrix
from .env import publisher
from .guard import pose_fault, values_fault
from .objects import ambf_name

NAMESPACE = "/CRTK"
RATE_HZ = 120.0
GRASP_JAW = 0.05  # rad: the challenge's grasp_actuation_jaw_angle
MOVE_S = 0.5  # the challenge's move_jp / move_cp execute_time
SCENE_OBJECTS = ("Needle", "Entry1", "Entry2", "Entry3", "Entry4", "Exit1", "Exit2", "Exit3", "Exit4")


def pose_msg(msg, t: np.ndarray, stamp, frame_id: str):
    msg.header.stamp, msg.header.frame_id = stamp, frame_id
    p, o = msg.pose.position, msg.pose.orientation
    p.x, p.y, p.z = (float(v) for v in t[:3, 3])
    o.x, o.y, o.z, o.w = (float(v) for v in matrix_to_quat(t[:3, :3]))
    return msg


def msg_matrix(pose) -> np.ndarray:
    q = np.array([pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w], float)
    n = np.linalg.norm(q)
    return pose_matrix([pose.position.x, pose.position.y, pose.position.z], q / n if n > 0 else [0, 0, 0, 1])


def _fault(topic: str, msg) -> str | None:
    """Why a PSM's CRTK command cannot be carried out (guard.py), or None: a joint command
    needs the six arm joints (the jaw one value), every value a finite number."""
    if topic in ("servo_cp", "move_cp"):
        return pose_fault(msg.pose)
    if topic == "servo_jv":
        return values_fault(msg.velocity, "velocity", 6)
    return values_fault(msg.position, "position", 1 if topic == "jaw/servo_jp" else 6)


class PsmCrtk:
    def __init__(self, crtk, name: str, psm) -> None:
        from geometry_msgs.msg import PoseStamped
        from sensor_msgs.msg import JointState

        rospy = crtk.rospy
        self.crtk, self.name, self.psm = crtk, name, psm
        ns = f"{NAMESPACE}/{name}/"
        self.js_pub = publisher(rospy, ns + "measured_js", JointState)
        self.cp_pub = publisher(rospy, ns + "measured_cp", PoseStamped)
        self.tbw_pub = publisher(rospy, ns + "T_b_w", PoseStamped)
        self.subs = [
            rospy.Subscriber(ns + topic, kind, lambda m, t=topic: self._hold(t, m), queue_size=1)
            for topic, kind in (
                ("servo_jp", JointState),
                ("move_jp", JointState),
                ("servo_jv", JointState),
                ("servo_cp", PoseStamped),
                ("move_cp", PoseStamped),
                ("jaw/servo_jp", JointState),
            )
        ]
        self.js, self.cp, self.tbw = JointState(), PoseStamped(), PoseStamped()
        self.js.name = [ambf_name(psm.art.records[i][0]) for i in psm.arm]
        self.pending: dict[str, object] = {}
        self.move = None  # (start q, goal q, start sim time)
        self.velocity = None
        self.grasped = False

    def _hold(self, topic: str, msg) -> None:
        why = _fault(topic, msg)
        if why:  # guard.py: never into the physics or the IK
            self.crtk.bridge.note(f"{NAMESPACE}/{self.name}/{topic} ignored: {why}")
            return
        self.pending[topic] = msg

    def _clamp(self, q) -> np.ndarray:
        k = self.psm.kin
        return np.clip(np.asarray(q, float)[:6], k.lower_limits[:6], k.upper_limits[:6])

    def _ik(self, msg) -> np.ndarray | None:
        try:
            return self._clamp(self.psm.kin.ik(msg_matrix(msg.pose), check_limits=False))
        except ValueError as exc:
            self.crtk.bridge.note(f"{self.name}: pose out of reach ({exc}); ignored")
            return None

    def apply(self) -> None:
        w, psm = self.crtk.bridge.world, self.psm
        pending, self.pending = self.pending, {}
        if pending:
            self.crtk.bridge.yield_body(psm.base)
        for topic, msg in pending.items():
            if topic == "servo_jp":
                self.move = self.velocity = None
                psm.servo_jp(self._clamp(msg.position))
            elif topic == "servo_cp":
                q = self._ik(msg)
                if q is not None:
                    self.move = self.velocity = None
                    psm.servo_jp(q)
            elif topic in ("move_jp", "move_cp"):
                q = self._clamp(msg.position) if topic == "move_jp" else None
                q = self._ik(msg) if topic == "move_cp" else q
                if q is not None:
                    self.velocity = None
                    self.move = (psm.measured_jp(), q, w.sim_time)
            elif topic == "servo_jv":
                self.move, self.velocity = None, [float(v) for v in msg.velocity[:6]]
            elif topic == "jaw/servo_jp":
                self._jaw(float(msg.position[0]))
        if self.move is not None:
            q0, q1, t0 = self.move
            s = min((w.sim_time - t0) / MOVE_S, 1.0)
            s = s * s * (3 - 2 * s)  # a smooth start and stop, as the challenge's interpolation
            psm.servo_jp(q0 + s * (q1 - q0))
            if s >= 1.0:
                self.move = None
        if self.velocity is not None:
            jc = self.crtk.bridge.joints
            for i, v in zip(psm.arm, self.velocity):
                jc.command(psm.art.records[i][0], psm.art.records[i][3], "velocity", v)
            self.velocity = None  # held by the joint commands until the next CRTK command

    def _jaw(self, angle: float) -> None:
        """The challenge's set_jaw_angle and run_grasp_logic: both fingers at ``angle``; closed
        below GRASP_JAW, the actuator takes what lies between the jaws; opened, it lets go."""
        w = self.crtk.bridge.world
        if angle < GRASP_JAW:
            if not self.grasped:
                self.grasped = w.grasp(self.name, True) is not None
        else:
            if self.grasped:
                w.grasp(self.name, False)
            self.grasped = False
        self.psm.servo_jaw(angle)

    def publish(self, stamp) -> None:
        psm = self.psm
        if self.js_pub.get_num_connections():
            q, dq = self.crtk.bridge.world.joint_state(psm.art, psm.arm)
            self.js.header.stamp = stamp
            self.js.position, self.js.velocity = [float(v) for v in q], [float(v) for v in dq]
            self.js_pub.publish(self.js)
        if self.cp_pub.get_num_connections():
            self.cp_pub.publish(pose_msg(self.cp, psm.measured_cp(), stamp, self.name + "/baselink"))
        if self.tbw_pub.get_num_connections():
            self.tbw_pub.publish(pose_msg(self.tbw, psm.base_in_world(), stamp, "world"))


class EcmCrtk:
    def __init__(self, crtk, body) -> None:
        from geometry_msgs.msg import PoseStamped
        from sensor_msgs.msg import JointState

        rospy = crtk.rospy
        self.crtk, self.body = crtk, body
        ns = f"{NAMESPACE}/ecm/"
        self.cp_pub = publisher(rospy, ns + "measured_cp", PoseStamped)
        self.js_pub = publisher(rospy, ns + "measured_js", JointState)
        self.sub = rospy.Subscriber(ns + "servo_cp", PoseStamped, self._hold, queue_size=1)
        self.cp, self.js = PoseStamped(), JointState(name=["j0", "j1", "j2", "j3"], position=[0.0] * 4)
        self.pending = None

    def _hold(self, msg) -> None:
        why = pose_fault(msg.pose)
        if why:
            self.crtk.bridge.note(f"{NAMESPACE}/ecm/servo_cp ignored: {why}")
            return
        self.pending = msg

    def apply(self) -> None:
        msg, self.pending = self.pending, None
        if msg is None:
            return
        w = self.crtk.bridge.world
        t = msg_matrix(msg.pose)
        if hasattr(w, "place_body") and self.body.articulation is None:
            w.place_body(self.body, t)
        else:
            self.crtk.bridge.note("ecm: this engine cannot move the camera frame body; servo_cp ignored")

    def publish(self, stamp) -> None:
        if self.cp_pub.get_num_connections():
            self.cp_pub.publish(pose_msg(self.cp, self.body.world_matrix(), stamp, "world"))
        if self.js_pub.get_num_connections():
            self.js.header.stamp = stamp
            self.js_pub.publish(self.js)


class Crtk:
    """The CRTK topics of every PSM the scene has (a multibody under ``/psmN/`` that the PSM
    kinematics describe), its ECM (a body named CameraFrame) and its scene objects."""

    def __init__(self, bridge, log=print) -> None:
        from geometry_msgs.msg import PoseStamped

        from ..runner.psm import PSM

        self.bridge, self.rospy, self.log = bridge, bridge.rospy, log
        w = bridge.world
        self.psms: list[PsmCrtk] = []
        names = sorted({p for a in w.articulations for p in a.root.key.split("/") if p.startswith("psm")})
        for name in names:
            try:
                self.psms.append(PsmCrtk(self, name, PSM(w, name)))
            except (KeyError, ValueError) as exc:
                log(f"adfkit ros: no CRTK topics for {name}: {exc}")
        self.ecm = None
        cam_body = self._body("CameraFrame")
        if cam_body is not None:
            self.ecm = EcmCrtk(self, cam_body)
        self.scene = []
        for name in SCENE_OBJECTS:
            sb = self._body(name)
            if sb is not None:
                pub = publisher(self.rospy, f"{NAMESPACE}/{name}/measured_cp", PoseStamped)
                self.scene.append((sb, pub, PoseStamped()))
        self.next_pub = 0.0

    def _body(self, name: str):
        hits = [sb for sb in self.bridge.world.bodies if ambf_name(sb.body) == name]
        return hits[0] if len(hits) == 1 else None

    def rebind(self, world) -> None:
        """A world rebuilt from the same scene: the PSMs calibrated on it again, the bodies found."""
        from ..runner.psm import PSM

        for p in self.psms:
            p.psm = PSM(world, p.name)
        if self.ecm is not None:
            self.ecm.body = self._body("CameraFrame") or self.ecm.body
        self.scene = [(self._body(ambf_name(sb.body)) or sb, pub, msg) for sb, pub, msg in self.scene]

    def apply(self) -> None:
        for p in self.psms:
            if p.pending or p.move is not None or p.velocity is not None:
                p.apply()
        if self.ecm is not None and self.ecm.pending is not None:
            self.ecm.apply()

    def publish(self) -> None:
        now = time.monotonic()
        if now < self.next_pub:
            return
        self.next_pub = now + 1.0 / RATE_HZ
        stamp = self.rospy.Time.now()
        for p in self.psms:
            p.publish(stamp)
        if self.ecm is not None:
            self.ecm.publish(stamp)
        for sb, pub, msg in self.scene:
            if pub.get_num_connections():
                pub.publish(pose_msg(msg, sb.world_matrix(), stamp, "world"))
