"""Small scenes that each exercise one part of the physics, to be played side by side in AMBF
and adfkit (``adfkit parity``, docs/parity.md): a box dropped onto a slab, an arm on a revolute
joint driven by position, velocity and effort commands (a command file for each), three boxes
settling in a stack, a cube falling into a ghost object, the suture thread falling from a held
needle, a slider pushed onto its limits by efforts (a command file), four pendulums on p2p,
cone-twist, six-dof and six-dof-spring joints, a ball, a cylinder, a capsule and a cone dropped
tilted on the floor, free joints running into their stops, and the thread again with its
elements at the challenge phantom's inertia (5e-5 kg·m², at which AMBF's thread settles; at
its capsules' own it writhes). They need nothing but themselves: no corpus, no meshes. The launch file
lists one model per scene on the same world (a floor); ``-l`` picks one. Beside them, outside
the launch file, ``turned_arm.yaml``: the arm with its inertial frame turned about the joint's
axis (its inertia turned with it), which AMBF reads with the joint's zero turned
(semantics.joint_frames), and its own ``turned_arm_position.txt``."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..adf import atomic_write_text
from ..adf.writer import write_file
from ..model import (
    RGBA,
    Body,
    Colors,
    Geometry,
    Ghost,
    InputDevices,
    Joint,
    JointLimits,
    Launch,
    ModelFile,
    Pose,
    Vec3,
    World,
)
from ..model.common import Friction
from ..model.objects import AxesGains, Inertia, Vec3Range
from ..model.pose import rpy_to_quat
from .suturing_pad import build_floor

GREY = RGBA(r=0.6, g=0.6, b=0.65, a=1.0)
ORANGE = RGBA(r=0.9, g=0.5, b=0.1, a=1.0)

#: the launch file's models, in order (-l INDEX)
SCENES = (
    "drop", "arm", "stack", "ghost", "thread", "slider", "pendulums", "primitives", "ramp", "fixed_pair", "stops",
    "challenge_thread",
)  # fmt: skip

#: command files beside the scenes: (file, scene, lines)
COMMANDS = {
    "arm_position.txt": ("arm", ["0.0, position, base-arm, 0.6", "0.5, position, base-arm, -0.3"]),
    "arm_velocity.txt": ("arm", ["0.0, velocity, base-arm, 1.0", "0.3, velocity, base-arm, -0.5"]),
    "arm_effort.txt": ("arm", ["0.0, effort, base-arm, 0.02", "0.4, effort, base-arm, -0.03"]),
    "slider_effort.txt": ("slider", ["0.0, effort, post-block, 2.0", "0.5, effort, post-block, -3.0"]),
    "turned_arm_position.txt": ("turned_arm", ["0.0, position, base-arm, 0.6", "0.5, position, base-arm, -0.3"]),
}


def _box(ident: str, size, position, rpy=(0.0, 0.0, 0.0), mass: float = 0.0, color: RGBA = GREY) -> Body:
    g = Geometry(x=size[0], y=size[1], z=size[2])
    inertia = None
    if mass > 0:
        x, y, z = size
        inertia = Inertia(
            ix=round(mass * (y * y + z * z) / 12, 9),
            iy=round(mass * (x * x + z * z) / 12, 9),
            iz=round(mass * (x * x + y * y) / 12, 9),
        )
    return Body(
        identifier=f"BODY {ident}",
        name=ident,
        mass=mass,
        inertia=inertia,
        location=Pose(Vec3(*position), rpy_to_quat(*rpy)),
        shape="BOX",
        geometry=g,
        collision_shape="BOX",
        collision_geometry=g,
        color_rgba=color,
    )


def build_drop() -> ModelFile:
    """A 20 cm box, turned about z, dropped 5 cm onto a static slab: free fall, one impact, rest."""
    m = ModelFile(namespace="/ambf/env/drop/")
    m.bodies.append(_box("slab", (0.6, 0.6, 0.1), (0.0, 0.0, 0.05)))
    m.bodies.append(_box("box", (0.2, 0.2, 0.2), (0.0, 0.0, 0.25), (0.0, 0.0, 0.3), mass=1.0, color=ORANGE))
    return m


def _on_a_post(ns: str, post: Body, moving: Body, kind: str, axis: Vec3, child_pivot: Vec3, **joint) -> ModelFile:
    """A model of a static ``post`` and a ``moving`` body on one joint of ``kind`` from the
    post's origin, its axis ``axis`` in both bodies."""
    m = ModelFile(namespace=f"/ambf/env/{ns}/")
    m.bodies += [post, moving]
    p, c = post.name, moving.name
    m.joints.append(
        Joint(
            identifier=f"JOINT {p}-{c}",
            name=f"{p}-{c}",
            parent=f"BODY {p}",
            child=f"BODY {c}",
            type=kind,
            parent_pivot=Vec3(0.0, 0.0, 0.0),
            parent_axis=axis,
            child_pivot=child_pivot,
            child_axis=axis,
            **joint,
        )
    )
    return m


def build_arm() -> ModelFile:
    """A 30 cm, 0.5 kg arm on a revolute joint about z (gravity across the axis) from a static
    post: what a joint command does is all that moves it. No `controller`: AMBF's position
    commands go through its default P 10, D 1 velocity controller."""
    base = _box("base", (0.05, 0.05, 0.05), (0.0, 0.0, 0.5))
    arm = _box("arm", (0.3, 0.03, 0.03), (0.2, 0.0, 0.5), mass=0.5, color=ORANGE)
    limits = JointLimits(low=-2.0, high=2.0)
    z, pivot = Vec3(0.0, 0.0, 1.0), Vec3(-0.2, 0.0, 0.0)
    return _on_a_post("arm", base, arm, "revolute", z, pivot, joint_limits=limits, max_motor_impulse=0.05)


def build_slider() -> ModelFile:
    """A 0.5 kg, 10 cm block on a prismatic joint along x (gravity across it) from a static post,
    its limits ±5 cm: an effort pushes it onto a limit and holds it there, then the other way
    (``slider_effort.txt``): how a limit holds a slider against an effort."""
    post = _box("post", (0.05, 0.05, 0.05), (0.0, 0.0, 0.5))
    block = _box("block", (0.1, 0.04, 0.04), (0.15, 0.0, 0.5), mass=0.5, color=ORANGE)
    x, pivot = Vec3(1.0, 0.0, 0.0), Vec3(-0.15, 0.0, 0.0)
    return _on_a_post("slider", post, block, "prismatic", x, pivot, joint_limits=JointLimits(low=-0.05, high=0.05))


#: the pendulums: (name, joint type, where its pivot hangs on the post (y), its tilt (roll, pitch))
PENDULUMS = (
    ("p2p", "p2p", -0.4, (0.0, 0.5)),
    ("cone", "cone twist", -0.15, (0.2, 0.0)),
    ("six", "six dof", 0.15, (0.0, 0.3)),
    ("spring", "six dof spring", 0.4, (0.3, 0.0)),
)


def build_pendulums() -> ModelFile:
    """Four 20 cm, 0.3 kg bobs hanging from a static rail 1 m up, each on a joint of a kind the
    corpus hardly uses (p2p, cone twist, six dof, six dof spring), each tilted in the file about
    its pivot (which sits on the joint): they swing from where the file puts them."""
    m = ModelFile(namespace="/ambf/env/pendulums/")
    m.bodies.append(_box("rail", (0.02, 1.0, 0.02), (0.0, 0.0, 1.0)))
    z = Vec3(0.0, 0.0, 1.0)
    for name, kind, y, (roll, pitch) in PENDULUMS:
        rot = _rpy_matrix(roll, pitch)
        centre = np.array([0.0, y, 1.0]) - rot @ np.array([0.0, 0.0, 0.1])
        bob = _box(f"{name}bob", (0.03, 0.03, 0.2), tuple(round(float(c), 9) for c in centre), (roll, pitch, 0.0), 0.3)
        bob.collision_groups = [1]
        m.bodies.append(bob)
        joint = Joint(
            identifier=f"JOINT rail-{name}bob",
            name=f"rail-{name}bob",
            parent="BODY rail",
            child=f"BODY {name}bob",
            type=kind,
            parent_pivot=Vec3(0.0, y, 0.0),
            child_pivot=Vec3(0.0, 0.0, 0.1),
            parent_axis=z,
            child_axis=z,
        )
        if kind == "cone twist":
            joint.joint_limits = JointLimits(x=0.3, y=0.3, z=0.2)
        elif kind.startswith("six dof"):
            zero = Vec3(0.0, 0.0, 0.0)
            joint.joint_limits = JointLimits(
                linear=Vec3Range(low=Vec3(0.0, 0.0, -0.02 if "spring" in kind else 0.0),
                                 high=Vec3(0.0, 0.0, 0.02 if "spring" in kind else 0.0)),
                angular=Vec3Range(low=Vec3(-0.5, -0.5, 0.0), high=Vec3(0.5, 0.5, 0.0)),
            )  # fmt: skip
            if "spring" in kind:
                joint.stiffness = AxesGains(linear=Vec3(0.0, 0.0, 50.0), angular=Vec3(0.5, 0.5, 0.0))
                joint.damping = AxesGains(linear=Vec3(0.0, 0.0, 0.5), angular=Vec3(0.01, 0.01, 0.0))
                joint.equilibrium_point = AxesGains(linear=zero, angular=zero)
        m.joints.append(joint)
    return m


def _rpy_matrix(roll: float, pitch: float) -> np.ndarray:
    cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
    return np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]]) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])


def build_turned_arm() -> ModelFile:
    """The arm of :func:`build_arm` with its inertial frame turned 90° about the joint's axis
    (z) and its inertia turned with it: the same body, which AMBF reads with the joint's zero
    turned +90° (it builds joint frames in the bodies' inertial frames)."""
    m = build_arm()
    arm = m.bodies[1]
    i = arm.inertia
    arm.inertia = Inertia(ix=i.iy, iy=i.ix, iz=i.iz)
    arm.inertial_offset = Pose(Vec3(), rpy_to_quat(0.0, 0.0, np.pi / 2))
    return m


def build_stack() -> ModelFile:
    """Three boxes, each turned a little and 2 mm above the one below, settling into a stack on
    the floor: resting contacts, box on box."""
    m = ModelFile(namespace="/ambf/env/stack/")
    z = 0.0
    for i, (size, yaw) in enumerate(((0.2, 0.0), (0.14, 0.3), (0.08, -0.2))):
        z += 0.002 + size / 2
        m.bodies.append(
            _box(f"box{i + 1}", (size, size, size), (0.01 * i, 0.0, z), (0.0, 0.0, yaw), mass=1.0 - 0.3 * i)
        )
        z += size / 2
    return m


def build_ghost() -> ModelFile:
    """A 4 cm cube dropped from 2 cm above a ghost slab hung on a static post (a ghost with a
    parent, as the challenge's holes), and a twin dropped beside the slab: what a ghost does to a
    body that enters it. AMBF (with its ghosts following their parents) stops the cube in it."""
    m = ModelFile(namespace="/ambf/env/ghost/")
    m.bodies.append(_box("post", (0.02, 0.02, 0.3), (0.0, 0.2, 0.15)))
    m.bodies.append(_box("cube", (0.04, 0.04, 0.04), (0.0, 0.0, 0.27), mass=0.2, color=ORANGE))
    m.bodies.append(_box("twin", (0.04, 0.04, 0.04), (0.2, 0.0, 0.27), mass=0.2, color=ORANGE))
    g = Geometry(x=0.1, y=0.3, z=0.05)
    m.ghost_objects.append(
        Ghost(
            identifier="BODY slab",
            name="slab",
            parent="BODY post",
            location=Pose(Vec3(0.0, -0.2, 0.055), rpy_to_quat(0.0, 0.0, 0.0)),  # 0.18-0.23 m up
            shape="BOX",
            geometry=g,
            collision_shape="BOX",
            collision_geometry=g,
            color_rgba=RGBA(r=0.2, g=0.8, b=0.3, a=0.3),
        )
    )
    return m


#: the inertia of each thread element in the challenge's phantom (its file's), kg·m² about each axis
CHALLENGE_THREAD_INERTIA = 5.0e-5


def build_thread(inertia: float | None = None) -> ModelFile:
    """The suture thread of the sample scene (40 capsules on six-dof springs, with the published
    stiffness and damping, which the sample scene's own thread leaves out) held at one end by a
    static stand-in for the needle 0.2 m up, lying level at the start: it falls and swings down
    until it hangs. ``inertia`` (kg·m² about each axis) replaces
    the elements' own, their capsules' (the challenge phantom's elements carry 5e-5)."""
    from .suturing import layout as L
    from .suturing.thread import PUBLISHED_DAMPING, PUBLISHED_STIFFNESS, thread_bodies_and_joints

    needle_world = np.eye(4)
    rest = L.SLAB[2] + L.THREAD_RADIUS + 0.00001  # the height the builder lays the thread at
    needle_world[:3, 3] = (L.NEEDLE_RADIUS, 0.0, rest)  # its tail (angle pi) at x = 0, level
    bodies, joints = thread_bodies_and_joints(needle_world, PUBLISHED_STIFFNESS, PUBLISHED_DAMPING)
    lift = 0.2 - rest
    m = ModelFile(namespace="/ambf/env/thread/")
    needle = _box("Needle", (0.004, 0.004, 0.004), (L.NEEDLE_RADIUS, 0.0, 0.2))
    m.bodies.append(needle)
    for b in bodies:
        p = b.location.position
        b.location = Pose(Vec3(p.x, p.y, round(p.z + lift, 9)), b.location.orientation)
        if inertia is not None:
            b.inertia = Inertia(ix=inertia, iy=inertia, iz=inertia)
        m.bodies.append(b)
    m.joints.extend(joints)
    return m


def _primitive(ident: str, shape: str, geometry: Geometry, inertia: Inertia, position, rpy, **keys) -> Body:
    """A 0.2 kg body of one primitive shape (sphere, cylinder, capsule, cone), its inertia given."""
    return Body(
        identifier=f"BODY {ident}",
        name=ident,
        mass=0.2,
        inertia=inertia,
        location=Pose(Vec3(*position), rpy_to_quat(*rpy)),
        shape=shape,
        geometry=geometry,
        collision_shape=shape,
        collision_geometry=geometry,
        color_rgba=ORANGE,
        **keys,
    )


def _about_axis(along: float, across: float) -> Inertia:
    """A body's inertia about its centre with ``along`` about its axis (z) and ``across`` about
    the two others, rounded as the files write it."""
    return Inertia(ix=round(across, 9), iy=round(across, 9), iz=round(along, 9))


#: the primitives: (name, shape, geometry, inertia of 0.2 kg, where its centre starts, its tilt (roll, pitch, yaw))
PRIMITIVES = (
    ("ball", "SPHERE", Geometry(radius=0.03), _about_axis(7.2e-5, 7.2e-5), (-0.3, -0.6, 0.06), (0.0, 0.0, 0.0)),
    (
        "cylinder",
        "CYLINDER",
        Geometry(radius=0.03, height=0.1, axis="z"),
        _about_axis(0.2 * 0.03**2 / 2, 0.2 * (3 * 0.03**2 + 0.1**2) / 12),
        (-0.1, -0.6, 0.08),
        (1.0, 0.3, 0.0),
    ),
    (
        "capsule",
        "CAPSULE",
        Geometry(radius=0.02, height=0.12, axis="z"),
        _about_axis(0.2 * 0.02**2 / 2, 0.2 * (3 * 0.02**2 + 0.12**2) / 12),
        (0.1, -0.6, 0.1),
        (0.0, 0.45, 0.0),
    ),
    (
        "cone",
        "CONE",
        Geometry(radius=0.03, height=0.1, axis="z"),
        _about_axis(0.2 * 3 * 0.03**2 / 10, 0.2 * (3 * 0.03**2 / 20 + 3 * 0.1**2 / 80)),
        (0.3, -0.6, 0.08),
        (0.9, 0.0, 0.2),
    ),
)


def build_primitives() -> ModelFile:
    """A ball, a cylinder, a capsule and a cone, each 0.2 kg and 20 cm apart, dropped tilted
    from a few centimetres onto the floor: the ball lands and stays, the cylinder lands on its
    rim and topples onto its side, the capsule on one end and rolls over it onto its side, the
    cone on its rim and onto its side, AMBF's default rolling friction (0.01) slowing each: how
    each primitive collides and rolls."""
    m = ModelFile(namespace="/ambf/env/primitives/")
    for name, shape, geometry, inertia, position, rpy in PRIMITIVES:
        m.bodies.append(_primitive(name, shape, geometry, inertia, position, rpy))
    return m


#: the ramp's slope (rad, 25°): past atan(0.01 / 0.03), where AMBF's default rolling friction
#: (0.01 m) no longer holds a 3 cm ball still on it
RAMP_SLOPE = 0.44


def build_ramp() -> ModelFile:
    """A 3 cm ball and a 3 cm cylinder lying across the slope, each 0.2 kg, released 1 mm above
    a static 1.6 m ramp at 25°, 60 cm up it, and beside them a ball without rolling friction: in
    AMBF the first two slide down it without turning, their rolling friction (AMBF's default 0.01
    m, the ball's times the ramp's friction and the ramp's times the ball's: 0.01) holding them
    against the friction's torque (0.25 × 3 cm × the normal force), where the third's (0.005)
    does not; all stay on it for 1 s."""
    m = ModelFile(namespace="/ambf/env/ramp/")
    m.bodies.append(_box("ramp", (1.6, 0.5, 0.02), (0.0, 0.6, 0.4), (0.0, RAMP_SLOPE, 0.0)))
    r = 0.03
    normal = np.array([np.sin(RAMP_SLOPE), 0.0, np.cos(RAMP_SLOPE)])
    up_the_slope = np.array([-np.cos(RAMP_SLOPE), 0.0, np.sin(RAMP_SLOPE)])
    ball = Geometry(radius=r), _about_axis(7.2e-5, 7.2e-5)
    roller = Geometry(radius=r, height=0.06, axis="y"), _about_axis(0.2 * r * r / 2, 0.2 * (3 * r * r + 0.06**2) / 12)
    roller = roller[0], Inertia(ix=roller[1].ix, iy=roller[1].iz, iz=roller[1].iy)  # its axis along y
    for ident, y, shape, (geometry, inertia), rolling in (
        ("ball", 0.45, "SPHERE", ball, None),
        ("roller", 0.6, "CYLINDER", roller, None),
        ("rolling", 0.75, "SPHERE", ball, 0.0),
    ):
        centre = np.array([0.0, y, 0.4]) + (0.01 + r + 0.001) * normal + 0.6 * up_the_slope
        keys = {"friction": Friction(static=0.5, rolling=rolling)} if rolling is not None else {}
        position = tuple(round(float(c), 9) for c in centre)
        m.bodies.append(_primitive(ident, shape, geometry, inertia, position, (0.0, RAMP_SLOPE, 0.0), **keys))
    return m


def build_fixed_pair() -> ModelFile:
    """Two free boxes (0.3 and 0.1 kg) held together by a fixed joint, an L turned 0.4 rad about
    x, dropped 3 cm onto the floor: the pair falls, lands on an edge and settles as one body."""
    m = ModelFile(namespace="/ambf/env/fixed_pair/")
    rpy = (0.4, 0.0, 0.0)
    m.bodies.append(_box("block", (0.1, 0.1, 0.1), (0.6, -0.6, 0.12), rpy, mass=0.3, color=ORANGE))
    m.bodies.append(_box("lug", (0.06, 0.04, 0.04), (0.68, -0.6, 0.12), rpy, mass=0.1, color=ORANGE))
    m.joints.append(
        Joint(
            identifier="JOINT block-lug",
            name="block-lug",
            parent="BODY block",
            child="BODY lug",
            type="fixed",
            parent_pivot=Vec3(0.08, 0.0, 0.0),
            parent_axis=Vec3(0.0, 0.0, 1.0),
            child_pivot=Vec3(0.0, 0.0, 0.0),
            child_axis=Vec3(0.0, 0.0, 1.0),
        )
    )
    return m


def build_stops() -> ModelFile:
    """Free joints running into their stops, nothing commanding them: a 0.2 kg, 20 cm rod hinged
    at one end on a static post, released level into its 1 rad stop (at 10.8 rad/s: AMBF's rod
    comes back off it to 0.994 rad and rests on it); a 0.3 kg bob sliding down a prismatic rail
    tilted 37° into its stop 10 cm down; two links (0.3 and 0.2 kg) hinged one on the other,
    falling into their stops at 0.8 and 0.6 rad: how a stop turns back what comes into it."""
    m = ModelFile(namespace="/ambf/env/stops/")
    y = Vec3(0.0, 1.0, 0.0)

    def joint(kind: str, parent: str, child: str, pivot: Vec3, child_pivot: Vec3, axis: Vec3, limit: float) -> Joint:
        return Joint(
            identifier=f"JOINT {parent}-{child}",
            name=f"{parent}-{child}",
            parent=f"BODY {parent}",
            child=f"BODY {child}",
            type=kind,
            parent_pivot=pivot,
            parent_axis=axis,
            child_pivot=child_pivot,
            child_axis=axis,
            joint_limits=JointLimits(low=-limit, high=limit),
        )

    zero = Vec3(0.0, 0.0, 0.0)
    m.bodies.append(_box("post", (0.02, 0.02, 0.02), (0.0, -0.4, 0.5)))
    m.bodies.append(_box("rod", (0.2, 0.01, 0.01), (0.11, -0.4, 0.5), mass=0.2, color=ORANGE))
    m.joints.append(joint("revolute", "post", "rod", zero, Vec3(-0.11, 0.0, 0.0), y, 1.0))
    m.bodies.append(_box("rail", (0.02, 0.02, 0.02), (0.0, 0.0, 0.5)))
    m.bodies.append(_box("bob", (0.04, 0.04, 0.04), (0.1, 0.0, 0.5), mass=0.3, color=ORANGE))
    m.joints.append(joint("prismatic", "rail", "bob", Vec3(0.1, 0.0, 0.0), zero, Vec3(0.0, 0.6, 0.8), 0.1))
    m.bodies.append(_box("base", (0.02, 0.02, 0.02), (0.0, 0.4, 0.6)))
    m.bodies.append(_box("upper", (0.2, 0.02, 0.02), (0.11, 0.4, 0.6), mass=0.3, color=ORANGE))
    m.bodies.append(_box("lower", (0.15, 0.015, 0.015), (0.305, 0.45, 0.6), mass=0.2, color=ORANGE))
    m.joints.append(joint("revolute", "base", "upper", zero, Vec3(-0.11, 0.0, 0.0), y, 0.8))
    m.joints.append(joint("revolute", "upper", "lower", Vec3(0.11, 0.05, 0.0), Vec3(-0.085, 0.0, 0.0), y, 0.6))
    return m


BUILD = {
    "drop": build_drop,
    "arm": build_arm,
    "stack": build_stack,
    "ghost": build_ghost,
    "thread": build_thread,
    "slider": build_slider,
    "pendulums": build_pendulums,
    "primitives": build_primitives,
    "ramp": build_ramp,
    "fixed_pair": build_fixed_pair,
    "stops": build_stops,
    "challenge_thread": lambda: build_thread(CHALLENGE_THREAD_INERTIA),
}


def write_parity(out_dir: str | Path) -> Path:
    """Write launch.yaml (the scenes of SCENES in order), world.yaml, floor.yaml, one model file
    per scene, the command files of COMMANDS, input_devices.yaml and colors.yaml into
    ``out_dir``; returns the launch file path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for name in SCENES:
        write_file(BUILD[name](), out / f"{name}.yaml")
    write_file(build_turned_arm(), out / "turned_arm.yaml")
    for fname, (scene, lines) in COMMANDS.items():
        which = f"-l {SCENES.index(scene)}" if scene in SCENES else "a model file of its own"
        head = f"# {scene}.yaml ({which}): TIME, KIND, JOINT, VALUE (adfkit parity --commands)\n"
        atomic_write_text(out / fname, head + "\n".join(lines) + "\n")
    write_file(build_floor(), out / "floor.yaml")
    write_file(World(namespace="/ambf/env/", gravity=Vec3(0, 0, -9.81), environment="floor.yaml"), out / "world.yaml")
    write_file(InputDevices(present_lists={"input devices"}), out / "input_devices.yaml")
    write_file(Colors(colors={"grey": GREY, "orange": ORANGE}), out / "colors.yaml")
    launch = Launch(
        world_config="world.yaml",
        color_config="colors.yaml",
        input_devices_config="input_devices.yaml",
        multibody_configs=[f"{n}.yaml" for n in SCENES],
    )
    return write_file(launch, out / "launch.yaml")


__all__ = [
    "SCENES",
    "COMMANDS",
    "write_parity",
    "build_drop",
    "build_arm",
    "build_turned_arm",
    "build_stack",
    "build_ghost",
    "build_thread",
    "CHALLENGE_THREAD_INERTIA",
    "build_slider",
    "build_pendulums",
    "build_primitives",
    "build_ramp",
    "build_fixed_pair",
]
