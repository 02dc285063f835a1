"""Two da Vinci PSMs with the Large Needle Driver, built from the LND 400006 modified-DH
parameters (adfkit.runner.psm_kinematics) with primitive link geometry.

Every link body's frame IS its DH frame, and every joint is written so that joint value 0 is
DH value 0 with the same sign: a revolute joint's parent pivot and axis are those of
RotX(alpha)·TransX(a)·TransZ(d) in the parent frame, its ``offset`` the DH offset; the
insertion's DH offset (-L_rcc) goes into the pivot. So ``adfkit.runner.psm.PSM`` calibrates
to rounding error and the closed-form IK drives the arm exactly.

Names follow the suturing challenge's ``LND_400006_SIMPLE`` files (body and joint names,
the ``/ambf/env/psmN/`` and ``/ambf/env/ghosts/psmN/`` namespaces, finger ghosts, the
``Constraint`` actuator ``Actuator0`` on the tool yaw link), so scripts written for one
scene run on the other; a ``Proximity`` sensor ``Sensor0`` looks between the jaws.
"""

from __future__ import annotations

import math

import numpy as np

from ...model import (
    RGBA,
    Actuator,
    Body,
    Friction,
    Geometry,
    Ghost,
    Inertia,
    Joint,
    JointLimits,
    ModelFile,
    Pose,
    Ray,
    Sensor,
    Vec3,
    VelocityDamping,
)
from ...runner.psm_kinematics import PRISMATIC, default
from .frames import for_ambf, pose, r, rot_z, translation, vec

ARM_BODIES = (
    "base link simple",
    "yaw link simple",
    "pitch end link simple",
    "main insertion link simple",
    "tool roll link simple",
    "tool pitch link simple",
    "tool yaw link simple",
)
ARM_JOINTS = (
    "base link-yaw link",
    "yaw link-pitch back link",
    "pitch end link-main insertion link",
    "main insertion link-tool roll link",
    "tool roll link-tool pitch link",
    "tool pitch link-tool yaw link",
)
FINGERS = ("tool gripper1 simple", "tool gripper2 simple")
JAW_JOINTS = ("tool yaw link-tool gripper1 link", "tool yaw link-tool gripper2 link")
#: mass (kg), as the challenge's PSM files give them
MASSES = (0.0, 5.0, 5.0, 2.0, 1.0, 1.0, 1.0)
FINGER_MASS = 1.0
MAX_IMPULSE = (50.0, 50.0, 2000.0, 50.0, 50.0, 50.0)
JOINT_DAMPING = (5.0, 0.0, 100.0, 0.001, 0.05, 0.0)
FINGER_LIMITS = (-0.349066, 0.698132)  # each finger takes half of the jaw's -0.698..1.396 rad
JAW_LENGTH = 0.011  # m, fingers along +y of the tool yaw link
GRASP_POINT = 0.006  # m along the jaws: the actuator and where a needle is held
FINGER_GAP = 0.0002  # m from the jaw plane to each finger's inner face (closed)
FINGER_WIDTH = 0.001
GHOST_REACH = 0.0024  # m a finger ghost reaches past the jaw plane
GHOST_LENGTH = 0.006  # m of jaw the ghosts cover, centred at GRASP_POINT
SENSOR_START = 0.0035  # m along the jaws where the sensor's rays start

ARM = RGBA(r=0.93, g=0.93, b=0.95, a=1.0)
DARK = RGBA(r=0.15, g=0.15, b=0.17, a=1.0)
BLUE = RGBA(r=0.14, g=0.16, b=0.45, a=1.0)
GHOST = RGBA(r=0.8, g=0.04, b=0.02, a=0.4)


def _box_inertia(m, x, y, z) -> Inertia:
    return Inertia(ix=r(m * (y * y + z * z) / 12), iy=r(m * (x * x + z * z) / 12), iz=r(m * (x * x + y * y) / 12))


def _cyl_inertia(m, rad, h) -> Inertia:  # axis z
    t = m * (3 * rad * rad + h * h) / 12
    return Inertia(ix=r(t), iy=r(t), iz=r(m * rad * rad / 2))


#: link geometry in the DH frame of each body: (shape, Geometry, centre)
def _link_shapes():
    lt = default().l_tool
    return {
        "base link simple": ("Sphere", Geometry(radius=0.006), (0, 0, 0)),
        "yaw link simple": ("Cylinder", Geometry(radius=0.012, height=0.05, axis="z"), (0, 0, 0)),
        # the carriage rail runs back along the shaft (the shaft points along -y of this frame)
        "pitch end link simple": ("Box", Geometry(x=0.012, y=0.35, z=0.03), (0.022, 0.295, 0)),
        "main insertion link simple": ("Box", Geometry(x=0.025, y=0.025, z=0.05), (0, 0, -0.01)),
        "tool roll link simple": (
            "Cylinder",
            Geometry(radius=0.0042, height=lt - 0.004, axis="z"),
            (0, 0, -(lt + 0.004) / 2),
        ),
        "tool pitch link simple": ("Box", Geometry(x=0.009, y=0.005, z=0.004), (0.0045, 0, 0)),
        "tool yaw link simple": ("Cylinder", Geometry(radius=0.0018, height=0.004, axis="z"), (0, 0, 0)),
    }


def _inertia(shape, g, m):
    if m == 0:
        return None
    if shape == "Box":
        return _box_inertia(m, g.x, g.y, g.z)
    if shape == "Cylinder":
        return _cyl_inertia(m, g.radius, g.height)
    i = 0.4 * m * g.radius**2
    return Inertia(ix=r(i), iy=r(i), iz=r(i))


def mesh_name(body: str) -> str:
    return body.replace(" ", "_") + ".OBJ"


def _offset(centre) -> bool:
    return any(abs(c) > 0 for c in centre)


def _body(name, world: np.ndarray, shape, g, centre, mass, colour, joint_offset: float = 0.0) -> Body:
    """A link: a primitive collision shape at ``centre``; drawn by that primitive when it sits
    at the body origin (ADF draws a primitive ``shape`` there), else by a mesh of it.

    The inertial frame is put at the body origin, turned by -``joint_offset`` about z: that is
    the joint's frame B in this body, so the runner's link frame and PyBullet's inertial frame
    coincide (measured: with them apart, the same inertia written unturned, PyBullet's arm
    tracked its set-points 4.2° off in insert 1 instead of 0.9°, and pair 2 failed). AMBF builds
    joint frames in the inertial frames: :func:`for_ambf` writes the joints for that."""
    off = Pose(vec(centre))
    inertia = _inertia(shape, g, mass)
    if inertia is not None and abs(math.sin(joint_offset)) > 0.5:  # turned by ±90°: x and y swap
        inertia = Inertia(ix=inertia.iy, iy=inertia.ix, iz=inertia.iz)
    com = pose(rot_z(-joint_offset))
    visual = {"mesh": mesh_name(name)} if _offset(centre) else {"shape": shape, "geometry": g}
    return Body(
        identifier=f"BODY {name}",
        name=name,
        mass=mass,
        location=pose(world),
        inertia=inertia,
        inertial_offset=com if mass else None,
        **visual,
        collision_shape=shape,
        collision_geometry=g,
        collision_offset=off,
        collision_margin=0.0001,
        color_rgba=colour,
        friction=Friction(static=0.5, rolling=0.0),
        restitution=0.0,
        damping=VelocityDamping(linear=0.04, angular=0.1),
    )


def _dh_joint(name, parent, child, link, limits, impulse, damping) -> Joint:
    """Joint i of the DH chain between the bodies of frames i-1 and i (see the module doc)."""
    sa, ca = math.sin(link.alpha), math.cos(link.alpha)
    axis = vec((0.0, -sa, ca))
    d = link.d + (link.offset if link.joint_type == PRISMATIC else 0.0)
    pivot = vec((link.a, -d * sa, d * ca))
    return Joint(
        identifier=f"JOINT {name}",
        name=name,
        parent=f"BODY {parent}",
        child=f"BODY {child}",
        type="prismatic" if link.joint_type == PRISMATIC else "revolute",
        parent_pivot=pivot,
        child_pivot=Vec3(0.0, 0.0, 0.0),
        parent_axis=axis,
        child_axis=Vec3(0.0, 0.0, 1.0),
        offset=0.0 if link.joint_type == PRISMATIC else r(link.offset),
        joint_limits=JointLimits(low=r(limits[0]), high=r(limits[1])),
        damping=damping,
        max_motor_impulse=impulse,
        controller_output_type="VELOCITY",
        passive=False,
    )


def build_psm(name: str, base: np.ndarray, q_home, jaw_home: float = 0.8) -> ModelFile:
    """The arm ``name`` (psm1, psm2) with its DH base frame (the RCM) at ``base`` (4x4, world)
    and its joints at ``q_home`` (6 values) and ``jaw_home`` (rad between the fingers)."""
    kin = default()
    frames = kin.fk_all(q_home)
    shapes = _link_shapes()
    m = ModelFile(
        namespace=f"/ambf/env/{name}/",
        ignore_inter_collision=True,
        gravity=Vec3(0.0, 0.0, 0.0),
        high_resolution_path="./meshes/",
        low_resolution_path="./meshes/",
    )
    for i, body in enumerate(ARM_BODIES):
        shape, g, centre = shapes[body]
        colour = DARK if body.startswith("tool") and "roll" not in body else (BLUE if i in (1, 2) else ARM)
        link_offset = kin.links[i - 1].offset if i > 0 and kin.links[i - 1].joint_type != PRISMATIC else 0.0
        m.bodies.append(_body(body, base @ frames[i], shape, g, centre, MASSES[i], colour, link_offset))
    for i, joint in enumerate(ARM_JOINTS):
        link = kin.links[i]
        m.joints.append(
            _dh_joint(
                joint,
                ARM_BODIES[i],
                ARM_BODIES[i + 1],
                link,
                (link.lower, link.upper),
                MAX_IMPULSE[i],
                JOINT_DAMPING[i],
            )
        )
    wrist = base @ frames[6]
    for k, (finger, joint) in enumerate(zip(FINGERS, JAW_JOINTS)):
        sign, g, centre = _finger_shape(k)
        m.bodies.append(_body(finger, wrist @ rot_z(sign * jaw_home / 2), "Box", g, centre, FINGER_MASS, DARK))
        axis = Vec3(0.0, 0.0, sign)
        m.joints.append(
            Joint(
                identifier=f"JOINT {joint}",
                name=joint,
                parent="BODY tool yaw link simple",
                child=f"BODY {finger}",
                type="revolute",
                parent_pivot=Vec3(0.0, 0.0, 0.0),
                child_pivot=Vec3(0.0, 0.0, 0.0),
                parent_axis=axis,
                child_axis=axis,
                offset=0.0,
                joint_limits=JointLimits(low=FINGER_LIMITS[0], high=FINGER_LIMITS[1]),
                damping=0.005,
                max_motor_impulse=50.0,
                controller_output_type="VELOCITY",
                passive=False,
            )
        )
    return for_ambf(m)


def _finger_shape(k: int):
    sign = 1.0 if k == 0 else -1.0  # finger 1 turns about +z of the yaw link, finger 2 about -z
    g = Geometry(x=FINGER_WIDTH, y=JAW_LENGTH, z=0.0016)
    centre = (r(-sign * (FINGER_GAP + FINGER_WIDTH / 2)), r(JAW_LENGTH / 2 + 0.0005), 0.0)
    return sign, g, centre


def link_meshes() -> dict[str, str]:
    """OBJ text of every link drawn by a mesh, by file name (the same for both PSMs)."""
    from .meshes import box_mesh, cylinder_mesh, obj_text

    items = list(_link_shapes().items()) + [(f, ("Box",) + _finger_shape(k)[1:]) for k, f in enumerate(FINGERS)]
    out = {}
    for body, (shape, g, centre) in items:
        if not _offset(centre):
            continue
        if shape == "Box":
            v, f = box_mesh((g.x, g.y, g.z), centre)
        else:
            v, f = cylinder_mesh(g.radius, g.height, centre)
        out[mesh_name(body)] = obj_text(v, f, comment=f"PSM {body} (LND 400006), written by adfkit")
    return out


def build_psm_ghosts(name: str) -> ModelFile:
    """Finger ghosts, the grasp's constraint actuator and the proximity sensor of one PSM."""
    ns = f"/ambf/env/{name}/"
    m = ModelFile(namespace=f"/ambf/env/ghosts/{name}/", ignore_inter_collision=True)
    # Each ghost reaches from its finger's outer face GHOST_REACH across the jaw plane, over
    # the middle of the jaws: it holds what lies between them whether they are closed or open
    # (at 0.8 rad the fingers are 2.5 mm from the middle at the grasp point).
    g = Geometry(x=FINGER_GAP + FINGER_WIDTH + GHOST_REACH, y=GHOST_LENGTH, z=0.002)
    for k, (side, finger) in enumerate((("right", FINGERS[0]), ("left", FINGERS[1]))):
        sign = 1.0 if k == 0 else -1.0
        outer = -sign * (FINGER_GAP + FINGER_WIDTH)
        at = Vec3(r(outer + sign * g.x / 2), r(GRASP_POINT), 0.0)
        m.ghost_objects.append(
            Ghost(
                identifier=f"GHOST {side} finger",
                name=f"{side}_finger_ghost",
                parent=f"{ns}BODY {finger}",
                location=Pose(at),
                shape="Box",
                geometry=g,
                collision_shape="Box",
                collision_geometry=g,
                collision_margin=0.0001,
                passive=False,
                color_rgba=GHOST,
            )
        )
    m.actuators.append(
        Actuator(
            identifier="ACTUATOR Actuator0",
            name="Actuator0",
            type="Constraint",
            parent=f"{ns}BODY tool yaw link simple",
            location=Pose(Vec3(0.0, GRASP_POINT, 0.0)),
            visible=False,
            visible_size=0.00055,
        )
    )
    # rays along the middle of the jaws from where open fingers are clear of it (PyBullet's
    # ray test reports only the first hit, so a ray must not start at a finger)
    rays = [Ray(offset=Vec3(0.0, SENSOR_START, z), direction=Vec3(0.0, 1.0, 0.0)) for z in (-0.0004, 0.0, 0.0004)]
    m.sensors.append(
        Sensor(
            identifier="SENSOR Sensor0",
            name="Sensor0",
            type="Proximity",
            parent=f"{ns}BODY tool yaw link simple",
            location=Pose(Vec3(0.0, 0.0, 0.0)),
            range=r(JAW_LENGTH + 0.0005 - SENSOR_START),
            array=rays,
            visible=False,
            visible_size=0.0003,
        )
    )
    return m


def grasp_offset() -> np.ndarray:
    """Pose of the grasp point (the actuator) in the PSM's end-effector (DH) frame: the wrist
    yaw frame is the end frame turned by RotX(pi/2)·RotZ(-pi/2)."""
    kin = default()
    f = kin.fk_all(np.zeros(6))
    return np.linalg.inv(f[7]) @ f[6] @ translation(0.0, GRASP_POINT, 0.0)


__all__ = ["build_psm", "build_psm_ghosts", "grasp_offset", "ARM_BODIES", "ARM_JOINTS", "FINGERS", "JAW_JOINTS"]
