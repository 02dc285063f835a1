"""One side of a parity run as a trace: what it created (bodies, joints, ghosts, sensors,
actuators, by the names AMBF gives them) and its bodies' poses and joints' values sampled over
time. The AMBF trace comes from the plugin's record; the adfkit trace from playing the same
scene, driven by the same commands, in one of adfkit's engines."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..runner.names import merge_namespace
from ..runner.rotations import pose_matrix

#: what each side lists as created, in this order
KINDS = ("body", "soft body", "ghost", "joint", "sensor", "actuator")


@dataclass
class Trace:
    side: str  # "ambf", "pybullet", "mujoco"
    made: dict[str, list[str]]  # kind -> the names of what was created
    body_names: list[str]
    times: np.ndarray  # (S,)
    poses: np.ndarray  # (S, B, 7): position, quaternion x y z w of each body's ADF frame
    joint_names: list[str]
    joints: np.ndarray  # (S, J), NaN where the side has no value
    wall_s: float  # stepping alone
    notes: list[str] = field(default_factory=list)
    clock: np.ndarray | None = None  # (S,) a paced AMBF replay's command clock at each sample
    angular_joints: frozenset[str] = frozenset()  # the joints whose values are angles (AMBF's in (-π, π])


def ambf_name(key: str, obj) -> str:
    """The name AMBF gives an object adfkit built as ``key`` (namespace + identifier): the
    same namespace and the object's `name` with its spaces removed (AMBF's loader removes them)."""
    cut = key.rfind(obj.identifier)
    prefix = key[:cut] if cut >= 0 else ""
    return prefix + (obj.name or "").replace(" ", "")


def joint_key(world, joint) -> str:
    """The namespaced key of an ADF joint: its model's namespace merged with its own."""
    for m in world.scene.all_models():
        if any(j is joint for j in m.joints):
            return merge_namespace(m.namespace or "", joint.namespace) + joint.identifier
    return joint.identifier


def made_by(world) -> dict[str, list[str]]:
    """What an adfkit world created, by AMBF's names."""
    soft = getattr(world, "soft", None)
    return {
        "body": [ambf_name(sb.key, sb.body) for sb in rigid_bodies(world)],
        "soft body": [ambf_name(s.key, s.soft) for s in (soft.items if soft is not None else [])],
        "ghost": [ambf_name(g.key, g.ghost) for g in world.ghosts],
        "joint": [ambf_name(joint_key(world, j), j) for j, _p, _c in world.joints_made + world.inert_joints()],
        "sensor": [ambf_name(s.key, s.sensor) for s in world.sensors],
        "actuator": [ambf_name(a.key, a.actuator) for a in world.actuators],
    }


def rigid_bodies(world) -> list:
    """The world's rigid bodies, less the iso-surfaces it plays volumes as (AMBF's volumes are
    not rigid bodies)."""
    return [sb for sb in world.bodies if getattr(sb, "surface", None) is None]


def made_by_ambf(created: dict) -> dict[str, list[str]]:
    return {
        "body": [b["qname"] for b in created["bodies"]],
        "soft body": [b["qname"] for b in created["soft_bodies"]],
        "ghost": [g["qname"] for g in created["ghosts"]],
        "joint": [j["qname"] for j in created["joints"]],
        "sensor": [s["qname"] for s in created["sensors"]],
        "actuator": [a["qname"] for a in created["actuators"]],
    }


def from_ambf(rec, staged: tuple[str, ...] = ()) -> Trace:
    """The trace of an AMBF run (parity.ambf.AmbfRecord), less the ``staged`` bodies (the
    stage's own floor)."""
    made = made_by_ambf(rec.created)
    s = rec.samples
    poses = np.array([x["bodies"] for x in s], dtype=float).reshape(len(s), len(made["body"]), 7)
    keep = [i for i, n in enumerate(made["body"]) if n not in staged]
    made["body"] = [made["body"][i] for i in keep]
    joints = np.array([[np.nan if v is None else v for v in x["joints"]] for x in s], dtype=float).reshape(
        len(s), len(made["joint"])
    )
    times = np.array([x["t"] for x in s])
    # Bullet's btSliderConstraint computes its position in its solver step: before AMBF's first,
    # a prismatic joint reads whatever its memory held (measured: 1.0, 2.9e-311)
    sliders = [k for k, j in enumerate(rec.created["joints"]) if j.get("type") == "prismatic"]
    if sliders and times.size and times[0] == 0.0:
        joints[0, sliders] = np.nan
    clock = np.array([x.get("clock", x["t"]) for x in s])
    angular = frozenset(
        n for n, j in zip(made["joint"], rec.created["joints"]) if j.get("type") in ("revolute", "torsion spring")
    )
    return Trace(
        "ambf",
        made,
        made["body"],
        times,
        poses[:, keep],
        made["joint"],
        joints,
        rec.wall_s,
        clock=clock,
        angular_joints=angular,
    )


def _pose(sb) -> list[float]:
    from ..runner.rotations import matrix_to_pq

    p, q = matrix_to_pq(sb.world_matrix())
    return [*p, *q]


def tool_tips(bodies: list[str], joints: list[tuple]) -> list[str]:
    """The tool tips of the scene's jointed trees: the bodies ending its longest chains, each
    a joint's child and no joint's parent, the most joints from its tree's root (a PSM's two
    jaws, the KUKA's link7). ``bodies``: (name, engine body) pairs; ``joints``: (joint, parent
    body, child body) as the world made them."""
    name = {id(sb): n for n, sb in bodies}
    children: dict[int, list[int]] = {}
    is_child = set()
    for _j, parent, child in joints:
        children.setdefault(id(parent), []).append(id(child))
        is_child.add(id(child))
    tips = []
    for root in [k for k in children if k not in is_child]:
        depth, frontier, seen = {root: 0}, [root], {root}
        while frontier:  # breadth first: a loop's body at its shortest distance from the root
            nxt = []
            for k in frontier:
                for c in children.get(k, []):
                    if c not in seen:
                        seen.add(c)
                        depth[c] = depth[k] + 1
                        nxt.append(c)
            frontier = nxt
        leaves = [k for k in depth if k not in children and k in name]
        deepest = max((depth[k] for k in leaves), default=0)
        tips += [name[k] for k in leaves if deepest > 0 and depth[k] == deepest]
    return tips


class AdfkitPlayer:
    """A scene played in an adfkit world, sampled as the AMBF plugin samples it, driven by the
    same commands: each takes effect at the first control step at or after its time (AMBF: the
    first 1 ms physics step), joint commands through runner.joint_commands as AMBF applies
    them, grasp and release through the world's constraint actuators, a pose command as
    ``adfkit ros`` steers a free body under one (the body's Cartesian controller,
    runner/cartesian.py: AMBF's P as a velocity without its D, or its PD as a force)."""

    def __init__(self, world) -> None:
        from ..runner.joint_commands import JointCommands

        self.world = world
        self.made = made_by(world)
        self.bodies = rigid_bodies(world)
        self.joints = list(world.joints_made) + world.inert_joints()  # the inert last: no value
        self.by_name = {
            "joint": {n: (j, c) for n, (j, _p, c) in zip(self.made["joint"], self.joints)},
            "actuator": dict(zip(self.made["actuator"], world.actuators)),
            "body": dict(zip(self.made["body"], self.bodies)),
        }
        self.commands = JointCommands(world)
        self.inert = {id(j) for j, _p, _c in world.inert_joints()}  # AMBF keeps them; they move nothing
        self.per = world.dt * world.opt.control_substeps
        self.poses: dict[str, np.ndarray] = {}  # a body's pose command, its body frame (4x4)
        self.steers: dict = {}  # a body's Cartesian controller under its pose commands (runner/cartesian.py)

    def _activate(self, cmds, t: float) -> None:
        w = self.world
        for c in cmds:
            if c.kind == "grasp":
                act = self.by_name["actuator"][c.target]
                w.release(act)
                w.actuate(act, self.by_name["body"][c.body])
            elif c.kind == "release":
                w.release(self.by_name["actuator"][c.target])
            elif c.kind == "pose":
                self.poses[c.target] = pose_matrix(c.numbers[:3], c.numbers[3:])
            else:
                j, child = self.by_name["joint"][c.target]
                if id(j) not in self.inert:  # a command to an inert joint moves nothing, as in AMBF
                    self.commands.command(j, child, c.kind, c.value)

    def _steer(self) -> None:
        from ..runner.cartesian import PoseSteer

        for name, goal in self.poses.items():
            sb = self.by_name["body"][name]
            steer = self.steers.setdefault(name, PoseSteer.of(sb.body))
            cur = sb.world_matrix() @ sb.com_in_body
            lin, ang = steer.step(cur, goal @ sb.com_in_body, self.per, self.world.opt.control_substeps == 1)
            if steer.force:  # the body's own `controller`: a force and a torque, as AMBF's
                sb.force(lin, sb.com_position())
                sb.torque(ang)
            else:
                self.world.set_body_velocity(sb, lin, ang)

    def _joint_values(self) -> list[float]:
        out = []
        w = self.world
        for j, _p, child in self.joints:
            dj = self.commands.joints.get(id(j)) or self.commands.drivable(j, child)
            out.append(float(w.joint_state(dj.art, [dj.index])[0][0]) if dj is not None else np.nan)
        return out

    def play(self, seconds: float, every: float, commands=(), progress=None) -> Trace:
        n = int(round(seconds / self.per))
        k_every = max(1, int(round(every / self.per))) if every > 0 else n
        pending = sorted(commands, key=lambda c: c.t)
        times, poses, joints = [0.0], [[_pose(sb) for sb in self.bodies]], [self._joint_values()]
        due = [c for c in pending if c.t <= 1e-9]
        pending = pending[len(due) :]
        self._activate(due, 0.0)
        wall = 0.0
        for k in range(1, n + 1):
            t0 = time.perf_counter()
            self.world.step(1)
            t = k * self.per
            due = [c for c in pending if c.t <= t + 1e-9]
            if due:
                pending = pending[len(due) :]
                self._activate(due, t)
            self.commands.apply(t)
            self._steer()
            wall += time.perf_counter() - t0
            if k % k_every == 0 or k == n:
                times.append(t)
                poses.append([_pose(sb) for sb in self.bodies])
                joints.append(self._joint_values())
            if progress is not None:
                progress.update(1)
        return Trace(
            self.world.engine,
            self.made,
            self.made["body"],
            np.array(times),
            np.array(poses, dtype=float).reshape(len(times), len(self.bodies), 7),
            self.made["joint"],
            np.array(joints, dtype=float).reshape(len(times), len(self.joints)),
            wall,
        )
