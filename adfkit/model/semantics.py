"""What AMBF makes of the raw values: canonical kinds for the spellings it accepts, and
the effective defaults it uses for keys a file leaves out (adf-format.md §7–§11)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import Enum

from .common import Geometry, ShapeEntry
from .pose import IDENTITY, Pose, Quat, Vec3


class JointKind(str, Enum):
    REVOLUTE = "revolute"  # revolute, hinge, continuous
    PRISMATIC = "prismatic"  # prismatic, slider
    FIXED = "fixed"
    LINEAR_SPRING = "linear spring"
    TORSION_SPRING = "torsion spring"
    P2P = "p2p"
    CONE_TWIST = "cone twist"
    SIX_DOF = "six dof"
    SIX_DOF_SPRING = "six dof spring"


JOINT_TYPE_NAMES: dict[str, JointKind] = {
    "revolute": JointKind.REVOLUTE,
    "hinge": JointKind.REVOLUTE,
    "continuous": JointKind.REVOLUTE,
    "prismatic": JointKind.PRISMATIC,
    "slider": JointKind.PRISMATIC,
    "fixed": JointKind.FIXED,
    "linear spring": JointKind.LINEAR_SPRING,
    "spring": JointKind.LINEAR_SPRING,
    "torsion spring": JointKind.TORSION_SPRING,
    "torsional spring": JointKind.TORSION_SPRING,
    "angular spring": JointKind.TORSION_SPRING,
    "p2p": JointKind.P2P,
    "cone twist": JointKind.CONE_TWIST,
    "six dof": JointKind.SIX_DOF,
    "six dof spring": JointKind.SIX_DOF_SPRING,
}

# Reference axis d of §8.1: the axis of the Bullet constraint frame the ADF axis maps onto.
REFERENCE_AXIS = {JointKind.PRISMATIC: Vec3(1.0, 0.0, 0.0)}


def joint_kind(type_text: str | None) -> JointKind | None:
    """The joint kind AMBF builds for a `type` string (exact, case-sensitive), or None."""
    return JOINT_TYPE_NAMES.get(type_text) if type_text is not None else None


def reference_axis(kind: JointKind) -> Vec3:
    return REFERENCE_AXIS.get(kind, Vec3(0.0, 0.0, 1.0))


class ShapeKind(str, Enum):
    BOX = "box"
    SPHERE = "sphere"
    CYLINDER = "cylinder"
    CAPSULE = "capsule"
    CONE = "cone"
    PLANE = "plane"


def shape_kind(text: str | None) -> ShapeKind | None:
    """`Box`, `box` or `BOX` → BOX; any other spelling → None (AMBF: undefined behaviour)."""
    if text is None:
        return None
    for k in ShapeKind:
        if text in (k.value, k.value.capitalize(), k.value.upper()):
            return k
    return None


SHAPE_KEYS = {
    ShapeKind.BOX: ("x", "y", "z"),
    ShapeKind.SPHERE: ("radius",),
    ShapeKind.CYLINDER: ("radius", "height"),
    ShapeKind.CAPSULE: ("radius", "height"),
    ShapeKind.CONE: ("radius", "height"),
    ShapeKind.PLANE: ("normal", "offset"),
}


def axis_vector(axis: str | None) -> Vec3:
    """`axis` of cylinders, capsules and cones; Z when absent or unknown (AMBF warns)."""
    return {"x": Vec3(1, 0, 0), "y": Vec3(0, 1, 0)}.get((axis or "z").lower(), Vec3(0, 0, 1))


CONE_SIDES = 24  # a cone collides as this many-sided hull where an engine has no cone


def cone_vertices(radius: float, height: float, sides: int = CONE_SIDES) -> list[tuple[float, float, float]]:
    """A cone along +z centred on half its height (Bullet's btConeShapeZ), as the apex, the base
    centre and ``sides`` points around the base: its hull is the cone an engine without one plays."""
    out = [(0.0, 0.0, height / 2), (0.0, 0.0, -height / 2)]
    for i in range(sides):
        a = 2 * math.pi * i / sides
        out.append((radius * math.cos(a), radius * math.sin(a), -height / 2))
    return out


def plane_pose(geometry) -> Pose:
    """Where a PLANE shape's surface lies in its frame: the point `offset` along the unit
    `normal` (Bullet's btStaticPlaneShape n·x = offset), its +z axis along the normal."""
    n = normalized_or(geometry.normal, Vec3(0.0, 0.0, 1.0))
    d = geometry.offset or 0.0
    return Pose(Vec3(n[0] * d, n[1] * d, n[2] * d), shortest_arc(Vec3(0.0, 0.0, 1.0), n))


class CollisionMeshType(str, Enum):
    CONVEX_HULL = "convex hull"
    CONVEX_MESH = "convex mesh"
    CONCAVE_MESH = "concave mesh"
    POINT_CLOUD = "point cloud"


_MESH_TYPES = {
    "CONVEX_HULL": CollisionMeshType.CONVEX_HULL,
    "convex_hull": CollisionMeshType.CONVEX_HULL,
    "hull": CollisionMeshType.CONVEX_HULL,
    "CONVEX_MESH": CollisionMeshType.CONVEX_MESH,
    "convex_mesh": CollisionMeshType.CONVEX_MESH,
    "CONCAVE_MESH": CollisionMeshType.CONCAVE_MESH,
    "TRIMESH": CollisionMeshType.CONCAVE_MESH,
    "trimesh": CollisionMeshType.CONCAVE_MESH,
    "POINT_CLOUD": CollisionMeshType.POINT_CLOUD,
    "point_cloud": CollisionMeshType.POINT_CLOUD,
}


def collision_mesh_type(text: str | None) -> tuple[CollisionMeshType, bool]:
    """(effective type, spelling accepted). Unknown or empty spellings fall back to concave."""
    if text is None:
        return CollisionMeshType.CONCAVE_MESH, True
    t = _MESH_TYPES.get(text)
    return (t, True) if t else (CollisionMeshType.CONCAVE_MESH, False)


SENSOR_TYPES = {
    "Proximity": "proximity",
    "proximity": "proximity",
    "PROXIMITY": "proximity",
    "Resistance": "resistance",
    "resistance": "resistance",
    "RESISTANCE": "resistance",
}
ACTUATOR_TYPES = {"Constraint": "constraint", "constraint": "constraint", "CONSTRAINT": "constraint"}
CONTROLLER_OUTPUT_TYPES = {
    "FORCE": "force",
    "EFFORT": "force",
    "force": "force",
    "effort": "force",
    "VELOCITY": "velocity",
    "velocity": "velocity",
    "POSITION": "position",
    "position": "position",
}


# --- effective defaults --------------------------------------------------------------------

DEFAULT_MASS = 1.0
DEFAULT_FRICTION_STATIC = 0.5
DEFAULT_FRICTION_ROLLING = 0.01
DEFAULT_RESTITUTION = 0.1
DEFAULT_LINEAR_DAMPING = 0.04
DEFAULT_ANGULAR_DAMPING = 0.1
DEFAULT_COLLISION_MARGIN = 0.001
DEFAULT_GRAVITY = Vec3(0.0, 0.0, -9.8)
DEFAULT_MAX_ITERATIONS = 10
DEFAULT_JOINT_MAX_MOTOR_IMPULSE = 0.1
DEFAULT_JOINT_ERP = 0.1
#: btHingeConstraint::setLimit's default bias factor, which AMBF's hinges keep: a hinge's limit row
#: asks for 0.3·erp·error/dt
HINGE_LIMIT_BIAS = 0.3
#: the world's ERP (btContactSolverInfo's default, which AMBF keeps): btSliderConstraint's limit rows'
SLIDER_LIMIT_ERP = 0.2
#: the one-axis springs, which AMBF makes btGeneric6DofSpring2Constraints (their limit rows at the joint's erp)
ONE_AXIS_SPRINGS = (JointKind.TORSION_SPRING, JointKind.LINEAR_SPRING)
DEFAULT_JOINT_CFM = 0.1
DEFAULT_SENSOR_RANGE = 0.5
DEFAULT_ACTUATOR_MAX_IMPULSE = 10.0
DEFAULT_ACTUATOR_TAU = 1.0
DEFAULT_CAMERA_FOV = 0.7
DEFAULT_CAMERA_NEAR = 0.1
DEFAULT_CAMERA_FAR = 10.0
DEFAULT_IMAGE_SIZE = (640, 480)
DEFAULT_SIX_DOF_LIMIT = 1.2
DEFAULT_SIX_DOF_SPRING = {"stiffness": 1.0, "damping": 0.7, "equilibrium point": 0.0}


def effective_mass(body) -> float:
    return DEFAULT_MASS if body.mass is None else body.mass


def holds_no_joint(body) -> bool:
    """A static body (mass 0) with no collision shape of any kind and no `inertia`: AMBF makes it a
    btEmptyShape ("COLLISION TYPE NOT UNDERSTOOD") and a hinge, slider, fixed or p2p joint hung
    from it holds nothing (measured in AMBF 2.0; runner/plan.py holds_nothing, the validator's
    `joint-static-parent`)."""
    shaped = body.collision_shape or body.compound_collision_shape or body.collision_mesh or body.mesh
    return body.mass == 0 and body.inertia is None and not shaped


def pose_or_identity(p: Pose | None) -> Pose:
    return p if p is not None else Pose()


def inertial_offset(body) -> Pose:
    """The COM frame in the body frame (identity unless written and mass is written), or AMBF's
    estimate from the collision mesh where the runner gave the body one (runner/ambf_bodies.py
    attach_com_estimates, geometry/chai3d_com.py)."""
    est = getattr(body, "ambf_com", None)
    if est is not None:
        return Pose(Vec3(*est))
    if body.mass is None:
        return Pose()
    return pose_or_identity(body.inertial_offset)


def com_estimated(body) -> bool:
    """AMBF estimates the body's centre of mass from its collision mesh (adf-format.md §7.2):
    the body collides with a mesh and its file gives no `inertial offset`, or no `mass` (then
    none of its inertial keys is read)."""
    if body.mass is not None and body.inertial_offset is not None:
        return False
    return collision_primitives(body) is None


def collision_mesh_pose(body) -> Pose:
    """Pose of the collision mesh in the body frame: the body frame itself, or AMBF's estimated
    inertial frame where the runner gave the body one (AMBF builds the mesh's shape in it)."""
    est = getattr(body, "ambf_com", None)
    return Pose(Vec3(*est)) if est is not None else Pose()


def collision_offset(body) -> Pose:
    """Pose of a single collision primitive: `collision offset`, else the inertial offset (§7.4)."""
    if body.collision_offset is not None:
        return body.collision_offset
    return pose_or_identity(getattr(body, "inertial_offset", None))


@dataclass(frozen=True)
class Primitive:
    """A primitive shape with its pose in the body frame, dimensions in metres, ADF meaning."""

    kind: ShapeKind
    geometry: Geometry
    pose: Pose = Pose()

    @property
    def axis(self) -> Vec3:
        return axis_vector(self.geometry.axis)


def collision_primitives(body) -> list[Primitive] | None:
    """The body's collision primitives in precedence order (§7.4), or None when collision
    comes from a mesh. Entries with an unknown shape name are left out."""
    if body.collision_shape:
        k = shape_kind(body.collision_shape)
        if k is None or body.collision_geometry is None:
            return []
        return [Primitive(k, body.collision_geometry, collision_offset(body))]
    if body.compound_collision_shape:
        out = []
        for e in body.compound_collision_shape:
            k = shape_kind(e.shape)
            if k is not None and e.geometry is not None:
                out.append(Primitive(k, e.geometry, pose_or_identity(e.offset)))
        return out
    return None


def concave_mesh(body) -> bool:
    """The body collides with a mesh AMBF keeps concave (a triangle mesh: `collision mesh type`
    CONCAVE_MESH, its default), which an engine may take the convex hull of."""
    return collision_primitives(body) is None and collision_mesh_type(body.collision_mesh_type)[0] is (
        CollisionMeshType.CONCAVE_MESH
    )


def normalized_or(v: Vec3 | None, fallback: Vec3) -> Vec3:
    if v is None:
        return fallback
    n = math.hypot(v[0], v[1], v[2])  # never overflows (1e308 ** 2 raises OverflowError)
    return Vec3(v[0] / n, v[1] / n, v[2] / n) if 0.0 < n < math.inf else fallback


def shortest_arc(u: Vec3, v: Vec3) -> Quat:
    """AMBF's Rmin(u→v) (§8.2): identity below 0.001 rad; antiparallel: 180° about u×X
    (or about v×Y when u is parallel to X)."""
    u = Vec3(*u).normalized()
    v = Vec3(*v).normalized()
    d = max(-1.0, min(1.0, u.dot(v)))
    angle = math.acos(d)
    if angle < 0.001:
        return IDENTITY
    if math.pi - angle < 0.001:
        axis = u.cross(Vec3(1, 0, 0))
        if axis.norm() < 1e-9:
            axis = v.cross(Vec3(0, 1, 0))
        return Quat.from_axis_angle(axis, math.pi)
    return Quat.from_axis_angle(u.cross(v), angle)


def joint_frames(
    joint,
    parent_scale: float = 1.0,
    child_scale: float = 1.0,
    parent_inertial: Quat = IDENTITY,
    child_inertial: Quat = IDENTITY,
) -> tuple[Pose, Pose]:
    """Frames A (in the parent body frame) and B (in the child body frame) of §8.2, as AMBF
    builds them (afJoint::createFromAttribs): the axes are first turned into the bodies'
    inertial frames (``parent_inertial``, ``child_inertial``: the rotations of their `inertial
    offset`), the frames are built there (the shortest arc from the reference axis is taken in
    the inertial frame) and are given here in the body frames. With a turned inertial frame the
    joint's zero is therefore turned about its axis from the one the body frames would give
    (:func:`inertial_joint_twist`).

    At joint value zero they coincide in the world.
    """
    kind = joint_kind(joint.type) or JointKind.REVOLUTE
    d = reference_axis(kind)
    a = parent_inertial.inverse().rotate(normalized_or(joint.parent_axis, Vec3(0, 0, 1)))
    b = child_inertial.inverse().rotate(normalized_or(joint.child_axis, Vec3(0, 0, 1)))
    joint_offset = joint.joint_offset or 0.0
    offset = joint.offset if joint.offset is not None else (joint.child_offset or 0.0)
    r_a = Quat.from_axis_angle(a, joint_offset) * shortest_arc(d, a)
    r_b = (
        shortest_arc(b, a).inverse()
        * Quat.from_axis_angle(a, offset).inverse()
        * Quat.from_axis_angle(a, joint_offset)
        * shortest_arc(d, a)
    )
    pa = Vec3(*(joint.parent_pivot or Vec3())).scaled(parent_scale)
    pb = Vec3(*(joint.child_pivot or Vec3())).scaled(child_scale)
    return Pose(pa, (parent_inertial * r_a).normalized()), Pose(pb, (child_inertial * r_b).normalized())


def inertial_rotation(body) -> Quat:
    """The rotation of the body's inertial frame in its body frame (identity for a body
    without one, e.g. the world)."""
    if body is None or not hasattr(body, "inertial_offset"):
        return IDENTITY
    return inertial_offset(body).orientation


class ReversedJoint:
    """A joint a kinematic tree takes from its child's side (the file's child reached first, its
    parent hanging on it): the two bodies swapped, everything else the file's. Its frames
    (body_joint_frames) are the file's swapped and turned half a turn across the joint's axis, so
    that its value, limits and motor are the file's joint's, sign included."""

    def __init__(self, joint) -> None:
        self.joint = joint

    def __getattr__(self, name: str):
        return getattr(self.joint, name)

    @property
    def parent(self):
        return self.joint.child

    @property
    def child(self):
        return self.joint.parent


#: half a turn about z (a slide along x reverses) and about x (a turn about z reverses)
_HALF_TURN_Z = Pose(Vec3(), Quat(0.0, 0.0, 1.0, 0.0))
_HALF_TURN_X = Pose(Vec3(), Quat(1.0, 0.0, 0.0, 0.0))


def body_joint_frames(joint, parent, child) -> tuple[Pose, Pose]:
    """:func:`joint_frames` of ``joint`` between the ADF bodies ``parent`` and ``child`` (their
    scales and inertial frames). A ReversedJoint's are its file joint's (between ``child`` and
    ``parent``) swapped, each turned by the same half turn across the joint's axis: the child
    frame then moves about (along) the parent's as the file's child moved about its parent's,
    by the same value."""
    if isinstance(joint, ReversedJoint):
        a, b = body_joint_frames(joint.joint, child, parent)
        turn = _HALF_TURN_Z if joint_kind(joint.type) is JointKind.PRISMATIC else _HALF_TURN_X
        return b * turn, a * turn
    ps = getattr(parent, "scale", None) or 1.0
    cs = getattr(child, "scale", None) or 1.0
    return joint_frames(joint, ps, cs, inertial_rotation(parent), inertial_rotation(child))


def _angle_about(q: Quat, axis: Vec3) -> float:
    """The angle of ``q``, a rotation about ``axis`` (unit)."""
    return 2.0 * math.atan2(Vec3(q.x, q.y, q.z).dot(axis), q.w)


def offsets_for_body_frames(joint, parent, child) -> tuple[float, float]:
    """(`joint offset`, `offset`) with which AMBF, building the joint's frames in the bodies'
    inertial frames, builds the ones :func:`joint_frames` gives in the body frames with the
    joint's own: a file whose inertial frames are turned then means in AMBF what its body
    frames say. Both are the joint's own when no inertial frame is turned."""
    a0, b0 = joint_frames(joint)
    jo = joint.joint_offset or 0.0
    off = joint.offset if joint.offset is not None else (joint.child_offset or 0.0)
    a1, _ = body_joint_frames(joint, parent, child)
    axis_a = a0.orientation.rotate(reference_axis(joint_kind(joint.type) or JointKind.REVOLUTE))
    jo2 = jo + _angle_about(a0.orientation * a1.orientation.inverse(), axis_a)
    turned = replace(joint, joint_offset=jo2, offset=off)
    _, b1 = body_joint_frames(turned, parent, child)
    axis_b = b0.orientation.rotate(reference_axis(joint_kind(joint.type) or JointKind.REVOLUTE))
    off2 = off - _angle_about(b0.orientation * b1.orientation.inverse(), axis_b)
    return math.remainder(jo2, 2 * math.pi), math.remainder(off2, 2 * math.pi)


def snapped_axis_tilt(joint, parent, child) -> float:
    """How far (rad) AMBF's shortest arcs, the identity below 1e-3 rad (§8.2), tilt the joint
    from what its file says: the arcs AMBF takes from the reference axis to the parent's axis and
    from the child's axis to the parent's, both in the bodies' inertial frames (as
    :func:`joint_frames` builds them), summed where one is snapped (between 1e-12 and 1e-3 rad);
    0 for a joint whose arcs are exact or large enough to be kept."""
    d = reference_axis(joint_kind(joint.type) or JointKind.REVOLUTE)
    a = inertial_rotation(parent).inverse().rotate(normalized_or(joint.parent_axis, Vec3(0, 0, 1)))
    b = inertial_rotation(child).inverse().rotate(normalized_or(joint.child_axis, Vec3(0, 0, 1)))
    return sum(t for t in (d.cross(a).norm(), a.cross(b).norm()) if 1e-12 < t < 1e-3)


def inertial_joint_twist(joint, parent, child) -> float:
    """How far (rad, in [-π, π]) AMBF turns the joint's frames about its axis from the ones the
    body frames give: 0 unless a body's inertial frame is turned. For a revolute joint AMBF
    reads its value at a pose as the body frames' value plus this; a prismatic or fixed joint
    holds its child turned by this about the axis from where the body frames hold it."""
    a0, b0 = joint_frames(joint)
    a1, b1 = body_joint_frames(joint, parent, child)
    rel = (a1.orientation.inverse() * a0.orientation) * (b0.orientation.inverse() * b1.orientation)
    d = reference_axis(joint_kind(joint.type) or JointKind.REVOLUTE)
    return math.remainder(2.0 * math.atan2(Vec3(rel.x, rel.y, rel.z).dot(d), rel.w), 2 * math.pi)


__all__ = [n for n in dir() if not n.startswith("_")] + ["ShapeEntry"]


def camera_pose(cam) -> Pose | None:
    """An ADF camera's frame in its parent's, as AMBF's ``afCamera::setView`` makes it (x from
    the point looked at towards the eye, z along `up`, y = z × x); a camera may be the parent of
    cameras and lights. None for a view AMBF leaves unset (look at = location, or up along it)."""
    loc, at, up = cam.location or Vec3(), cam.look_at or Vec3(), cam.up or Vec3(0.0, 0.0, 1.0)
    x = loc - at
    if x.norm() < 1e-12 or up.cross(x).norm() < 1e-12 * max(x.norm(), 1.0):
        return None
    x = x.normalized()
    y = up.cross(x).normalized()
    z = x.cross(y)
    return Pose(loc, Quat.from_matrix(((x.x, y.x, z.x), (x.y, y.y, z.y), (x.z, y.z, z.z))))
