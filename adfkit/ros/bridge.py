"""AMBF's ROS interface on a runner world: for every object of ``objects.ros_objects`` a
``<topic>/State`` publisher and a ``<topic>/Command`` subscriber with AMBF's messages and
semantics (ambf_server and the ROS communication plugin of AMBF 2.0):

- a command holds: the last message received is applied at every physics step until the next;
- a watchdog: 0.5 s without a message and the command is reset as AMBF's ``reset_cmd`` does
  (a body's wrench and joint commands to zero effort, an actuator released);
- a state is published at the object's low rate (`publish frequency`, 50 Hz) and, while
  commands arrive, at its high rate (1 kHz): AMBF's CmdWatchDog switches the rate the same way;
- poses are the ADF body frame in the world (AMBF's getLocalPos/Rot), twists the COM's
  velocity, joint lists in AMBF's order (objects.py), names without spaces.

The subscribers' callbacks (rospy's threads) only store the message; the world is touched in
``step`` alone, on the caller's thread."""

from __future__ import annotations

import math
import time

import numpy as np

from ..model.semantics import JointKind
from ..runner.cartesian import PoseSteer
from ..runner.joint_commands import DRIVEN_KINDS, JointCommands
from ..runner.rotations import invert, matrix_to_quat, pose_matrix
from .env import publisher
from .guard import TYPE_FORCE, TYPE_POSITION, TYPE_VELOCITY, body_cmd_fault, pose_fault
from .objects import RosObject, ros_objects, topic_of, world_namespace

WATCHDOG_S = 0.5  # ambf_comm's time out for every object (ObjectCommPlugin, WorldCommPlugin)
MOTORS = (JointKind.REVOLUTE, JointKind.PRISMATIC)  # the joints a position or velocity command moves
# A pose command steers a free body by its Cartesian controller (runner/cartesian.py): without a
# `controller` block AMBF's P 10 (D 1) as a velocity, its D term left out: on a velocity output,
# with the pose AMBF reads one step behind (its motion state), D 1 makes a loop whose roots ring at
# 249.6 Hz and grow by 0.25 % a step at 1 kHz; measured in AMBF (`tests/test_parity_pose.py`), a 1 kg
# box told to move 0.23 m was 1.9 m away after 1 s and 113 m after 3 s. P alone closes the error by
# P·dt a step (0.1 s time constant). With a block, its gains, and its PD as a force where AMBF's is.


def _set_pose(msg_pose, t: np.ndarray) -> None:
    p, o = msg_pose.position, msg_pose.orientation
    p.x, p.y, p.z = (float(v) for v in t[:3, 3])
    o.x, o.y, o.z, o.w = (float(v) for v in matrix_to_quat(t[:3, :3]))


def _pose_matrix(msg_pose) -> np.ndarray:
    p, o = msg_pose.position, msg_pose.orientation
    q = np.array([o.x, o.y, o.z, o.w], float)
    n = np.linalg.norm(q)
    q = q / n if n > 0.1 else np.array([0.0, 0.0, 0.0, 1.0])  # AMBF: an invalid quaternion is w = 1
    return pose_matrix([p.x, p.y, p.z], q)


def camera_rotation(eye, target, up) -> np.ndarray:
    """CHAI3D's camera frame from a look-at (afCamera::setView): x from the target to the eye,
    y = up × x, z = x × y."""
    x = np.asarray(eye, float) - np.asarray(target, float)
    x /= np.linalg.norm(x) or 1.0
    y = np.cross(np.asarray(up, float), x)
    y /= np.linalg.norm(y) or 1.0
    return np.column_stack([x, y, np.cross(x, y)])


class Handler:
    """One object's State publisher, Command subscriber, held command and watchdog."""

    state_type = cmd_type = None

    def __init__(self, bridge, obj: RosObject) -> None:
        self.bridge, self.obj = bridge, obj
        rospy, msgs = bridge.rospy, bridge.msgs
        self.state = getattr(msgs, self.state_type)()
        self.state.name.data = obj.name
        self.state.identifier.data = obj.identifier
        self.pub = publisher(rospy, obj.topic + "/State", type(self.state))
        self.sub = rospy.Subscriber(obj.topic + "/Command", getattr(msgs, self.cmd_type), self._on_cmd, queue_size=10)
        self.cmd = None
        self.heard = -math.inf  # monotonic time of the last command message
        self.next_pub = 0.0
        self.rebind(obj)

    def rebind(self, obj: RosObject) -> None:
        """Take ``obj``'s engine object (a world rebuilt from the same scene gives new ones)."""
        self.obj = obj

    def _on_cmd(self, msg) -> None:
        why = self.fault(msg)
        if why:  # guard.py: never into the physics; the last good command holds
            self.bridge.note(f"{self.obj.topic}/Command ignored: {why} (not a finite number)")
            return
        self.cmd = msg
        self.heard = time.monotonic()

    def fault(self, msg) -> str | None:
        """Why ``msg`` must not be applied (guard.py), or None."""
        return None

    def live(self, now: float) -> bool:
        """A command arrived within the watchdog's time out."""
        return now - self.heard <= self.bridge.watchdog_s

    def apply(self, now: float) -> None:
        """Apply the held command (every physics step)."""

    def fill(self) -> None:
        """Bring the state message up to date."""

    def publish(self, now: float, stamp) -> None:
        if now < self.next_pub:
            return
        self.next_pub = now + 1.0 / (self.obj.max_hz if self.live(now) else self.obj.min_hz)
        if self.pub.get_num_connections() == 0:
            return
        self.fill()
        st = self.state
        st.header.stamp = stamp
        st.sim_step, st.sim_time, st.wall_time = self.bridge.steps, self.bridge.world.sim_time, self.bridge.wall
        self.pub.publish(st)

    def close(self) -> None:
        self.pub.unregister()
        self.sub.unregister()


class BodyHandler(Handler):
    state_type, cmd_type = "RigidBodyState", "RigidBodyCmd"

    velocity_warned = False

    def rebind(self, obj: RosObject) -> None:
        self.obj, self.sb = obj, obj.target
        self.steer: PoseSteer | None = None
        st = self.state
        st.mass = float(self.sb.mass)
        inertia = getattr(self.sb, "inertia", (0.0, 0.0, 0.0))
        st.pInertia.x, st.pInertia.y, st.pInertia.z = (float(v) for v in inertia)
        names = [j.name for j in obj.joints]
        self.joint_names, self.children = names, [j.child for j in obj.joints]
        self.groups: dict[int, tuple] = {}  # id(articulation) -> (articulation, [(slot, record index)])
        for k, j in enumerate(obj.joints):
            if j.art is not None:
                self.groups.setdefault(id(j.art), (j.art, []))[1].append((k, j.index))

    # ---- commands ------------------------------------------------------------------------
    def fault(self, msg) -> str | None:
        return body_cmd_fault(msg, len(self.obj.joints))

    def apply(self, now: float) -> None:
        cmd = self.cmd
        if cmd is None:
            return
        w = self.bridge.world
        if not self.live(now):  # RigidBodyRosCom::reset_cmd
            cart, wrench = TYPE_FORCE, None
            joint_cmds = [0.0] * len(cmd.joint_cmds)
            types = [TYPE_FORCE] * len(cmd.joint_cmds)
        else:
            cart, wrench = cmd.cartesian_cmd_type, cmd.wrench
            joint_cmds = list(cmd.joint_cmds)
            types = list(cmd.joint_cmds_types) + [TYPE_FORCE] * (len(joint_cmds) - len(cmd.joint_cmds_types))
        sb = self.sb
        if cart == TYPE_FORCE:
            if wrench is not None and not sb.static:
                f, t = wrench.force, wrench.torque
                if f.x or f.y or f.z:
                    sb.force((f.x, f.y, f.z), sb.com_position())
                if t.x or t.y or t.z:
                    sb.torque((t.x, t.y, t.z))
        elif cart == TYPE_POSITION:
            self._position(w, _pose_matrix(cmd.pose))
        elif cart == TYPE_VELOCITY:
            self._velocity(w, cmd.twist)
        jc, driven = self.bridge.joints, {}
        for entry, value, kind in zip(self.obj.joints, joint_cmds, types):
            if kind not in (TYPE_FORCE, TYPE_POSITION, TYPE_VELOCITY):
                self.bridge.note(
                    f'WARNING! FOR JOINT "{entry.name}" COMMAND TYPE {kind} NOT UNDERSTOOD, SUPPORTED TYPES ARE'
                    " 0 -> FORCE, 1 -> POSITION, 2 -> VELOCITY"
                )  # AMBF's words (ObjectCommPlugin.cpp), said once
                continue
            if entry.kind not in (MOTORS if kind != TYPE_FORCE else DRIVEN_KINDS):
                # afJoint::commandPosition/Velocity move a hinge or a slider, commandEffort also a
                # spring; any other joint (fixed, p2p, cone twist, six dof) AMBF leaves as it is
                if value != 0.0 or kind != TYPE_FORCE:  # the zero efforts ambf_client pads with: silent
                    what = {TYPE_FORCE: "effort", TYPE_POSITION: "position", TYPE_VELOCITY: "velocity"}[kind]
                    self.bridge.note(
                        f"{self.obj.topic}: joint {entry.name} is a {entry.kind.value} joint, which AMBF moves"
                        f" by no {what} command; ignored"
                    )
                continue
            if entry.art is None:
                self.bridge.note(
                    f"{self.obj.topic}: joint {entry.name} is not driven by this engine; its commands are ignored"
                )
                continue
            if kind == TYPE_POSITION:  # the joint's position motor (docs/ros.md says why not AMBF's PID)
                jc.joints.pop(id(entry.joint), None)
                entry.art.targets[entry.index] = float(value)
                driven[id(entry.art)] = entry.art
            else:
                jc.command(entry.joint, entry.child_body, "velocity" if kind == TYPE_VELOCITY else "effort", value)
        for art in driven.values():
            art.drive()

    def _position(self, w, target: np.ndarray) -> None:
        sb = self.sb
        if sb.static:
            cur = sb.world_matrix()
            if np.linalg.norm(cur[:3, 3] - target[:3, 3]) > 1e-5 or _angle(cur, target) > 1e-4:
                if hasattr(w, "place_body") and sb.articulation is None:
                    w.place_body(sb, target)
                elif hasattr(w, "move_base"):
                    w.move_base(sb, target)
            return
        if self.steer is None:  # the body's own Cartesian controller, kept from command to command
            self.steer = PoseSteer.of(sb.body)
        cur = sb.world_matrix() @ sb.com_in_body
        cdt = w.dt * w.opt.control_substeps
        lin, ang = self.steer.step(cur, target @ sb.com_in_body, cdt, w.opt.control_substeps == 1)
        if self.steer.force:  # a `controller` block: AMBF's force and torque, held over the control step
            sb.force(lin, sb.com_position())
            sb.torque(ang)
        else:
            self._set_velocity(w, lin, ang)

    def _velocity(self, w, twist) -> None:
        lin = np.array([twist.linear.x, twist.linear.y, twist.linear.z])
        ang = np.array([twist.angular.x, twist.angular.y, twist.angular.z])
        sb = self.sb
        if sb.static:  # AMBF moves a static body's COM frame by the twist each step (a multibody's root too)
            from ..runner.rotations import rotation_exp

            c = sb.world_matrix() @ sb.com_in_body
            cdt = w.dt * w.opt.control_substeps
            c[:3, 3] += lin * cdt
            c[:3, :3] = rotation_exp(ang * cdt) @ c[:3, :3]
            t = c @ invert(sb.com_in_body)
            if hasattr(w, "place_body") and sb.articulation is None:
                w.place_body(sb, t)
                return
            if sb.articulation is not None and hasattr(w, "move_base"):
                w.move_base(sb, t)
                return
        self._set_velocity(w, lin, ang)

    def _set_velocity(self, w, lin, ang) -> None:
        if not w.set_body_velocity(self.sb, lin, ang) and not self.velocity_warned:
            self.velocity_warned = True
            self.bridge.note(
                f"{self.obj.topic}: a pose or twist command moves a free body only; ignored for a linked body"
            )

    # ---- state ---------------------------------------------------------------------------
    def fill(self) -> None:
        st, sb = self.state, self.sb
        p, q, v, om = sb.state()
        t = pose_matrix(p, q) @ invert(sb.com_in_body)
        _set_pose(st.pose, t)
        st.twist.linear.x, st.twist.linear.y, st.twist.linear.z = (float(x) for x in v)
        st.twist.angular.x, st.twist.angular.y, st.twist.angular.z = (float(x) for x in om)
        flags = self.obj.flags
        cmd = self.cmd
        want_children = flags[0] or (cmd is not None and cmd.publish_children_names)
        want_names = flags[1] or (cmd is not None and cmd.publish_joint_names)
        want_positions = flags[2] or (cmd is not None and cmd.publish_joint_positions)
        st.children_names = self.children if want_children else []
        st.joint_names = self.joint_names if want_names else []
        if want_positions and self.obj.joints:
            n = len(self.obj.joints)
            pos, vel = [0.0] * n, [0.0] * n
            for art, slots in self.groups.values():
                q_, dq = self.bridge.world.joint_state(art, [i for _, i in slots])
                for (k, _), a, b in zip(slots, q_, dq):
                    pos[k], vel[k] = float(a), float(b)
            st.joint_positions, st.joint_velocities, st.joint_efforts = pos, vel, [0.0] * n
        else:
            st.joint_positions, st.joint_velocities, st.joint_efforts = [], [], []


def _not_found(name: str, hits) -> str:
    """AMBF's warning for a body name that names no body or several (getBaseObject)."""
    if len(hits) > 1:
        shown = ", ".join(hits[:8]) + (", ..." if len(hits) > 8 else "")
        return f'MULTIPLE OBJECTS WITH SUB-STRING: "{name}" FOUND. PLEASE SPECIFY FURTHER ({shown})'
    if hits:
        return f'"{name}" ({hits[0]}) is not a rigid body; ignored'
    return f'CAN\'T FIND ANY OBJECTS NAMED: "{name}"; ignored'


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    c = (np.trace(a[:3, :3].T @ b[:3, :3]) - 1.0) / 2.0
    return float(math.acos(max(-1.0, min(1.0, c))))


class SensorHandler(Handler):
    state_type, cmd_type = "SensorState", "SensorCmd"  # AMBF reads no sensor command

    def rebind(self, obj: RosObject) -> None:
        self.obj, self.s = obj, obj.target
        st = self.state
        st.type.data = "PROXIMITY"
        st.parent_name.data = self.s.sensor.parent or ""
        st.count = len(self.s.starts)
        rng = float(np.linalg.norm(self.s.ends[0] - self.s.starts[0])) if len(self.s.starts) else 0.0
        st.range = [rng]
        _set_pose(st.pose, self.s.location)

    def fill(self) -> None:
        from .objects import ambf_name

        st, rays = self.state, self.s.rays or [(None, 1.0)] * len(self.s.starts)
        st.triggered = [b is not None for b, _ in rays]
        st.measurement = [1.0 - f if b is not None else 0.0 for b, f in rays]  # AMBF's depth fraction
        names = [ambf_name(b.body) if b is not None else "" for b, _ in rays]
        if len(st.sensed_objects) != len(names):
            st.sensed_objects = [type(st.type)() for _ in names]
        for m, n in zip(st.sensed_objects, names):
            m.data = n


class ActuatorHandler(Handler):
    state_type, cmd_type = "ActuatorState", "ActuatorCmd"

    def rebind(self, obj: RosObject) -> None:
        self.obj, self.a = obj, obj.target
        self.state.type.data = "CONSTRAINT"
        self.state.parent_name.data = self.a.actuator.parent or ""
        _set_pose(self.state.pose, self.a.location)

    def apply(self, now: float) -> None:
        """afObjectCommunicationPlugin::actuatorFetchCommand: actuate (once; a held grasp
        ignores the request) on the body named, or on what the named sensor senses; release
        otherwise (also when the watchdog resets the command)."""
        cmd = self.cmd
        if cmd is None:
            return
        w = self.bridge.world
        if not cmd.actuate or not self.live(now):
            if self.a.target is not None:
                w.release(self.a)
            return
        if self.a.target is not None:
            return
        body = None
        if cmd.use_sensor_data:
            name = cmd.sensor_identifier.data
            key, s = self.bridge.find_sensor(name)
            if s is not None:
                body = next((b for b, _ in (s.rays or []) if b is not None), None)
            else:  # AMBF's words (actuatorFetchCommand), said once
                self.bridge.note(
                    f"ERROR! IN ACTUATOR CALLBACK {self.obj.name}, REQUESTED SENSOR NAME {name} NOT FOUND. IGNORING!"
                )
        else:
            name = cmd.body_name.data
            key, hit = w.registry.find(name)
            body = hit if key is not None and isinstance(hit, w.body_type) else None
            if body is None:
                self.bridge.note(f"{self.obj.topic}: actuate: {_not_found(name, hit if key is None else [key])}")
        if body is not None and body is not self.a.parent:
            w.actuate(self.a, body)

    def fill(self) -> None:
        self.state.actuated = self.a.target is not None


class CameraHandler(Handler):
    state_type, cmd_type = "CameraState", "CameraCmd"

    def rebind(self, obj: RosObject) -> None:
        self.obj, self.cams = obj, obj.target
        self.state.parent_name.data = self.cams[0].camera.parent or ""

    def fault(self, msg) -> str | None:
        return pose_fault(msg.pose) if msg.enable_position_controller else None

    def apply(self, now: float) -> None:
        cmd = self.cmd
        if cmd is None or not cmd.enable_position_controller or not self.live(now):
            return
        t = _pose_matrix(cmd.pose)
        for c in self.cams:  # CHAI3D's camera looks along -x, z up
            c.eye, c.target, c.up = t[:3, 3].copy(), t[:3, 3] - t[:3, 0], t[:3, 2].copy()

    def fill(self) -> None:
        c = self.cams[0]
        t = np.eye(4)
        t[:3, :3] = camera_rotation(c.eye, c.target, c.up)
        t[:3, 3] = c.eye
        _set_pose(self.state.pose, t)


class LightHandler(Handler):
    state_type, cmd_type = "LightState", "LightCmd"

    def rebind(self, obj: RosObject) -> None:
        self.obj, light = obj, obj.target
        self.state.parent_name.data = light.parent or ""
        t = np.eye(4)  # the light's `direction` is its +x axis (adf-format.md §10)
        t[:3, 3] = light.location or (0.0, 0.0, 0.0)
        x = np.array(light.direction or (1.0, 0.0, 0.0), float)
        if np.linalg.norm(x) > 0:
            x /= np.linalg.norm(x)
            helper = np.array([0.0, 0.0, 1.0]) if abs(x[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
            y = np.cross(helper, x)
            y /= np.linalg.norm(y)
            t[:3, :3] = np.column_stack([x, y, np.cross(x, y)])
        _set_pose(self.state.pose, t)


HANDLERS = {
    "rigid_body": BodyHandler,
    "sensor": SensorHandler,
    "actuator": ActuatorHandler,
    "camera": CameraHandler,
    "light": LightHandler,
}


class WorldHandler:
    """``/<world namespace>/World``: WorldState, WorldCmd (step throttling), Command/Reset and
    Command/Reset/Bodies (WorldRosCom, World.cpp)."""

    def __init__(self, bridge) -> None:
        rospy, msgs = bridge.rospy, bridge.msgs
        from std_msgs.msg import Empty

        self.bridge = bridge
        self.topic = topic_of(world_namespace(bridge.world), "World")
        self.state = msgs.WorldState()
        self.pub = publisher(rospy, self.topic + "/State", msgs.WorldState)
        self.subs = [
            rospy.Subscriber(self.topic + "/Command", msgs.WorldCmd, self._on_cmd, queue_size=10),
            rospy.Subscriber(self.topic + "/Command/Reset", Empty, self._on_reset, queue_size=1),
            rospy.Subscriber(self.topic + "/Command/Reset/Bodies", Empty, self._on_reset_bodies, queue_size=1),
        ]
        self.heard = -math.inf
        self.throttle = False
        self.clock = False
        self.allowed = 0  # steps granted by the client's step clock
        self.skip = 10
        self.reset_asked = self.reset_bodies_asked = False
        self.next_pub = 0.0
        self.grant = None  # threading.Event the loop waits on while throttled (set by the server)

    def _on_cmd(self, msg) -> None:
        self.heard = time.monotonic()
        self.skip = int(msg.n_skip_steps)
        if msg.enable_step_throttling:
            # World::increment_sim_step stops stepping after n_skip_steps; a toggled step clock
            # starts it again (WorldRosCom::sub_cb). n_skip_steps 0 never stops (AMBF warns).
            grant = self.skip if self.skip > 0 else 1 << 30
            if not self.throttle or (self.allowed == 0 and bool(msg.step_clock) != self.clock):
                self.allowed = grant
            self.throttle = True
        else:
            self.throttle = False
        self.clock = bool(msg.step_clock)
        if self.grant is not None:
            self.grant.set()

    def _on_reset(self, _msg) -> None:
        self.reset_asked = True
        if self.grant is not None:
            self.grant.set()

    def _on_reset_bodies(self, _msg) -> None:
        self.reset_bodies_asked = True
        if self.grant is not None:
            self.grant.set()

    def may_step(self, now: float) -> bool:
        """AMBF's step_sim(): free running, or a step the client's clock granted; the watchdog
        (0.5 s without a world command) ends throttling."""
        if self.throttle and now - self.heard > self.bridge.watchdog_s:
            self.throttle = False
        if not self.throttle:
            return True
        return self.allowed > 0

    def stepped(self) -> None:
        if self.throttle and self.allowed > 0:
            self.allowed -= 1

    def publish(self, now: float, stamp, rate_hz: float) -> None:
        live = now - self.heard <= self.bridge.watchdog_s
        if now < self.next_pub and not self.throttle:
            return
        self.next_pub = now + (1.0 / 1000 if live else 1.0 / 50)
        if self.pub.get_num_connections() == 0:
            return
        st, w = self.state, self.bridge.world
        st.header.stamp = stamp
        st.sim_step, st.sim_time, st.wall_time = self.bridge.steps, w.sim_time, self.bridge.wall
        st.dynamic_loop_freq = int(round(rate_hz))
        st.graphics_loop_freq = int(round(self.bridge.graphics_hz))
        st.n_devices = 0
        self.pub.publish(st)

    def close(self) -> None:
        self.pub.unregister()
        for s in self.subs:
            s.unregister()


class Bridge:
    """Every handler of a world (see the module docstring)."""

    def __init__(self, world, rospy, msgs, log=print, watchdog_s: float = WATCHDOG_S) -> None:
        self.world, self.rospy, self.msgs, self.log = world, rospy, msgs, log
        self.watchdog_s = watchdog_s  # AMBF's 0.5 s unless asked otherwise (adfkit ros --watchdog)
        self.t0 = time.monotonic()
        self.steps = 0  # loop steps: AMBF's sim_step counts physics updates, however many 1 ms steps each is
        self.graphics_hz = 0.0
        self.notes: set[str] = set()
        self.joints = JointCommands(world)
        self.objects = ros_objects(world)
        self.handlers = [HANDLERS[o.kind](self, o) for o in self.objects]
        self.world_handler = WorldHandler(self)

    @property
    def wall(self) -> float:
        return time.monotonic() - self.t0

    def note(self, text: str) -> None:
        """Say once what a command asked that this world does not carry out."""
        if text not in self.notes:
            self.notes.add(text)
            self.log(f"adfkit ros: {text}")

    def find_sensor(self, name: str):
        for h in self.handlers:
            if (
                isinstance(h, SensorHandler)
                and name
                and (name == h.obj.identifier or name in h.obj.identifier or name in h.obj.topic)
            ):
                return h.obj.identifier, h.s
        return None, None

    def yield_body(self, sb) -> None:
        """Drop the commands held for body ``sb`` and its joints: another source (the CRTK
        topics, a teleoperation device) commands it now; the next Command message takes it back."""
        for h in self.handlers:
            if isinstance(h, BodyHandler) and h.sb is sb:
                h.cmd, h.heard = None, -math.inf
                for e in h.obj.joints:
                    self.joints.joints.pop(id(e.joint), None)

    def apply(self) -> None:
        """Every held command, once a loop step: bodies, actuators, cameras, then every joint's
        last command as AMBF's joint controller plays it (runner/joint_commands.py)."""
        now = time.monotonic()
        for h in self.handlers:
            if h.cmd is not None:
                h.apply(now)
        if self.joints.joints:
            self.joints.apply(self.world.sim_time)

    def publish(self, rate_hz: float) -> None:
        now = time.monotonic()
        stamp = self.rospy.Time.now()
        self.world_handler.publish(now, stamp, rate_hz)
        for h in self.handlers:
            h.publish(now, stamp)

    def rebind(self, world) -> None:
        """Point every handler at the objects of ``world``, a world rebuilt from the same scene."""
        self.world = world
        self.joints = JointCommands(world)
        fresh = {o.topic: o for o in ros_objects(world)}
        for h in self.handlers:
            o = fresh.get(h.obj.topic)
            if o is not None:
                h.rebind(o)

    def close(self) -> None:
        for h in self.handlers:
            h.close()
        self.world_handler.close()
