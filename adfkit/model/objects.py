"""The ADF objects of a model file (adf-format.md §7–§11): bodies, soft bodies, ghosts,
joints, sensors, actuators, cameras, lights, vehicles and volumes."""

from __future__ import annotations

from dataclasses import dataclass

from .common import (
    PID,
    RGBA,
    CartesianController,
    ColorComponents,
    Friction,
    Geometry,
    Node,
    Plugin,
    PublishFrequency,
    Shaders,
    ShapeEntry,
    VelocityDamping,
)
from .pose import Pose, Vec3
from .spec import FloatOr, ListOf, Obj, key

# --- key groups shared by several objects ---------------------------------------------


@dataclass(kw_only=True)
class _Ident(Obj):
    name: str | None = key("name", "str")
    namespace: str | None = key("namespace", "str")


@dataclass(kw_only=True)
class _Visual(Node):
    mesh: str | None = key("mesh", "str")
    mesh_remove_duplicates: bool | None = key("mesh remove duplicates", "bool")
    shape: str | None = key("shape", "str")
    geometry: Geometry | None = key("geometry", Geometry)
    compound_shape: list[ShapeEntry] | None = key("compound shape", ListOf(ShapeEntry))
    visible: bool | None = key("visible", "bool")
    shaders: Shaders | None = key("shaders", Shaders)
    color_rgba: RGBA | None = key("color rgba", RGBA)
    color_components: ColorComponents | None = key("color components", ColorComponents)
    use_material: bool | None = key("use material", "bool")
    color: str | None = key("color", "str")


@dataclass(kw_only=True)
class _Collision(Node):
    collision_shape: str | None = key("collision shape", "str")
    collision_geometry: Geometry | None = key("collision geometry", Geometry)
    collision_offset: Pose | None = key("collision offset", "pose")
    compound_collision_shape: list[ShapeEntry] | None = key("compound collision shape", ListOf(ShapeEntry))
    collision_mesh: str | None = key("collision mesh", "str")
    collision_mesh_type: str | None = key("collision mesh type", "str")
    collision_margin: float | None = key("collision margin", "float")
    collision_groups: list[int] | None = key("collision groups", ListOf("int"))
    high_resolution_path: str | None = key("high resolution path", "str")
    low_resolution_path: str | None = key("low resolution path", "str")


@dataclass(kw_only=True)
class _Comm(Node):
    passive: bool | None = key("passive", "bool")
    publish_frequency: PublishFrequency | None = key("publish frequency", PublishFrequency)
    plugins: list[Plugin] | None = key("plugins", ListOf(Plugin))


# --- rigid body ---------------------------------------------------------------------------


@dataclass(kw_only=True)
class Inertia(Node):
    ix: float | None = key("ix", "float")
    iy: float | None = key("iy", "float")
    iz: float | None = key("iz", "float")


@dataclass(kw_only=True)
class Body(_Comm, _Collision, _Visual, _Ident):
    """A rigid body (§7). ``location`` is the body (mesh) frame in the world."""

    location: Pose | None = key("location", "pose")
    scale: float | None = key("scale", "float")
    mass: float | None = key("mass", "float")
    inertia: Inertia | None = key("inertia", Inertia)
    inertial_offset: Pose | None = key("inertial offset", "pose")
    gravity: Vec3 | None = key("gravity", "vec3")
    friction: Friction | None = key("friction", Friction)
    restitution: float | None = key("restitution", "float")
    damping: VelocityDamping | None = key("damping", VelocityDamping)
    controller: CartesianController | None = key("controller", CartesianController)
    controller_output_type: str | None = key("controller output type", "str")
    publish_children_names: bool | None = key("publish children names", "bool")
    publish_joint_names: bool | None = key("publish joint names", "bool")
    publish_joint_positions: bool | None = key("publish joint positions", "bool")


# --- soft body ----------------------------------------------------------------------------


@dataclass(kw_only=True)
class SoftBodyConfig(Node):
    """Bullet btSoftBody settings (§7.8)."""

    kLST: float | None = key("kLST", "float")
    kAST: float | None = key("kAST", "float")
    kVST: float | None = key("kVST", "float")
    kVCF: float | None = key("kVCF", "float")
    kDP: float | None = key("kDP", "float")
    kDG: float | None = key("kDG", "float")
    kLF: float | None = key("kLF", "float")
    kPR: float | None = key("kPR", "float")
    kVC: float | None = key("kVC", "float")
    kDF: float | None = key("kDF", "float")
    kMT: float | None = key("kMT", "float")
    kCHR: float | None = key("kCHR", "float")
    kKHR: float | None = key("kKHR", "float")
    kSHR: float | None = key("kSHR", "float")
    kAHR: float | None = key("kAHR", "float")
    kSRHR_CL: float | None = key("kSRHR_CL", "float")
    kSKHR_CL: float | None = key("kSKHR_CL", "float")
    kSSHR_CL: float | None = key("kSSHR_CL", "float")
    kSR_SPLT_CL: float | None = key("kSR_SPLT_CL", "float")
    kSK_SPLT_CL: float | None = key("kSK_SPLT_CL", "float")
    kSS_SPLT_CL: float | None = key("kSS_SPLT_CL", "float")
    maxvolume: float | None = key("maxvolume", "float")
    timescale: float | None = key("timescale", "float")
    viterations: int | None = key("viterations", "int")
    piterations: int | None = key("piterations", "int")
    diterations: int | None = key("diterations", "int")
    citerations: int | None = key("citerations", "int")
    flags: int | None = key("flags", "int")
    bending_constraint: int | None = key("bending constraint", "int")
    clusters: int | None = key("clusters", "int")
    fixed_nodes: list[int] | None = key("fixed nodes", ListOf("int"))


@dataclass(kw_only=True)
class SoftBody(_Comm, _Collision, _Visual, _Ident):
    """A soft body (§7.8): a btSoftBody whose nodes are the unique vertices of the collision
    mesh. AMBF reads the keys declared here; `linear gain`, `angular gain` and
    `config.cutting` are read into nodes but never used, and `config.margin` is not read at
    all: those stay in ``extras`` (written back unchanged, reported as ignored keys)."""

    location: Pose | None = key("location", "pose")
    scale: float | None = key("scale", "float")
    mass: float | None = key("mass", "float")
    inertial_offset: Pose | None = key("inertial offset", "pose")
    gravity: Vec3 | None = key("gravity", "vec3")
    controller: CartesianController | None = key("controller", CartesianController)
    config: SoftBodyConfig | None = key("config", SoftBodyConfig)
    randomize_constraints: bool | None = key("randomize constraints", "bool")


# --- ghost object -------------------------------------------------------------------------


@dataclass(kw_only=True)
class Ghost(_Comm, _Collision, _Visual, _Ident):
    """A non-colliding trigger volume (§7.9); ``location`` is relative to ``parent`` if set."""

    parent: str | None = key("parent", "str")
    location: Pose | None = key("location", "pose")
    scale: float | None = key("scale", "float")


# --- joints -------------------------------------------------------------------------------


@dataclass(kw_only=True)
class Vec3Range(Node):
    low: Vec3 | None = key("low", "vec3")
    high: Vec3 | None = key("high", "vec3")


@dataclass(kw_only=True)
class JointLimits(Node):
    """`joint limits`: {low, high} for 1-DoF types, {x, y, z} for cone twist, and
    {linear: {low, high}, angular: {low, high}} of Vec3 for six-dof types."""

    low: float | None = key("low", "float")
    high: float | None = key("high", "float")
    x: float | None = key("x", "float")
    y: float | None = key("y", "float")
    z: float | None = key("z", "float")
    linear: Vec3Range | None = key("linear", Vec3Range)
    angular: Vec3Range | None = key("angular", Vec3Range)


@dataclass(kw_only=True)
class AxesGains(Node):
    """Per-axis six-dof-spring gains: {linear: {x,y,z}, angular: {x,y,z}}."""

    linear: Vec3 | None = key("linear", "vec3")
    angular: Vec3 | None = key("angular", "vec3")


@dataclass(kw_only=True)
class Joint(_Comm, _Ident):
    """A joint (§8). Pivots and axes are in the parent and child body frames."""

    parent: str | None = key("parent", "str")
    child: str | None = key("child", "str")
    type: str | None = key("type", "str")
    parent_pivot: Vec3 | None = key("parent pivot", "vec3")
    child_pivot: Vec3 | None = key("child pivot", "vec3")
    parent_axis: Vec3 | None = key("parent axis", "vec3")
    child_axis: Vec3 | None = key("child axis", "vec3")
    joint_limits: JointLimits | None = key("joint limits", JointLimits)
    offset: float | None = key("offset", "float")
    child_offset: float | None = key("child offset", "float")
    joint_offset: float | None = key("joint offset", "float")
    damping: float | AxesGains | None = key("damping", FloatOr(AxesGains))
    stiffness: float | AxesGains | None = key("stiffness", FloatOr(AxesGains))
    equilibrium_point: float | AxesGains | None = key("equilibrium point", FloatOr(AxesGains))
    max_motor_impulse: float | None = key("max motor impulse", "float")
    controller: PID | None = key("controller", PID)
    controller_output_type: str | None = key("controller output type", "str")
    enable_feedback: bool | None = key("enable feedback", "bool")
    enable_motor: bool | None = key("enable motor", "bool")
    ignore_inter_collision: bool | None = key("ignore inter-collision", "bool")
    joint_erp: float | None = key("joint erp", "float")
    joint_cfm: float | None = key("joint cfm", "float")


# --- sensors and actuators ----------------------------------------------------------------


@dataclass(kw_only=True)
class Ray(Node):
    offset: Vec3 | None = key("offset", "vec3")
    direction: Vec3 | None = key("direction", "vec3")


@dataclass(kw_only=True)
class Parametric(Node):
    resolution: int | None = key("resolution", "uint")
    horizontal_angle: float | None = key("horizontal angle", "float")
    vertical_angle: float | None = key("vertical angle", "float")
    start_offset: float | None = key("start offset", "float")


@dataclass(kw_only=True)
class ResistanceFriction(Node):
    static: float | None = key("static", "float")
    damping: float | None = key("damping", "float")
    dynamic: float | None = key("dynamic", "float")
    variable: bool | None = key("variable", "bool")


@dataclass(kw_only=True)
class Sensor(_Comm, _Ident):
    """Proximity or resistance ray sensor (§11.1); rays in the sensor frame."""

    type: str | None = key("type", "str")
    parent: str | None = key("parent", "str")
    location: Pose | None = key("location", "pose")
    range: float | None = key("range", "float")
    visible: bool | None = key("visible", "bool")
    visible_size: float | None = key("visible size", "float")
    array: list[Ray] | None = key("array", ListOf(Ray))
    mesh: str | None = key("mesh", "str")
    parametric: Parametric | None = key("parametric", Parametric)
    friction: ResistanceFriction | None = key("friction", ResistanceFriction)
    contact_area: float | None = key("contact area", "float")
    contact_stiffness: float | None = key("contact stiffness", "float")
    contact_damping: float | None = key("contact damping", "float")


@dataclass(kw_only=True)
class Actuator(_Comm, _Ident):
    """Constraint actuator (§11.2): fixes a sensed body to its parent on command."""

    type: str | None = key("type", "str")
    parent: str | None = key("parent", "str")
    location: Pose | None = key("location", "pose")
    visible: bool | None = key("visible", "bool")
    visible_size: float | None = key("visible size", "float")
    max_impulse: float | None = key("max impulse", "float")
    tau: float | None = key("tau", "float")


# --- cameras and lights -------------------------------------------------------------------


@dataclass(kw_only=True)
class ClippingPlane(Node):
    near: float | None = key("near", "float")
    far: float | None = key("far", "float")


@dataclass(kw_only=True)
class Stereo(Node):
    mode: str | None = key("mode", "str")
    eye_separation: float | None = key("eye separation", "float")
    focal_length: float | None = key("focal length", "float")


@dataclass(kw_only=True)
class Resolution(Node):
    width: float | None = key("width", "float")
    height: float | None = key("height", "float")


@dataclass(kw_only=True)
class DepthNoise(Node):
    mean: float | None = key("mean", "float")
    std_dev: float | None = key("std_dev", "float")
    std_dev_spaced: float | None = key("std dev", "float")
    bias: float | None = key("bias", "float")


@dataclass(kw_only=True)
class MouseMultipliers(Node):
    pan: float | None = key("pan", "float")
    rotate: float | None = key("rotate", "float")
    scroll: float | None = key("scroll", "float")
    arcball: float | None = key("arcball", "float")


@dataclass(kw_only=True)
class Camera(_Comm, _Ident):
    """A camera (§9). Vectors are in the parent body frame when ``parent`` is set."""

    parent: str | None = key("parent", "str")
    location: Vec3 | None = key("location", "vec3")
    look_at: Vec3 | None = key("look at", "vec3")
    up: Vec3 | None = key("up", "vec3")
    clipping_plane: ClippingPlane | None = key("clipping plane", ClippingPlane)
    field_view_angle: float | None = key("field view angle", "float")
    orthographic_view_width: float | None = key("orthographic view width", "float")
    stereo: Stereo | None = key("stereo", Stereo)
    monitor: int | None = key("monitor", "uint")
    visible: bool | None = key("visible", "bool")
    controlling_devices: list[str] | None = key("controlling devices", ListOf("str"))
    publish_image: bool | None = key("publish image", "bool")
    publish_depth: bool | None = key("publish depth", "bool")
    publish_image_interval: int | None = key("publish image interval", "uint")
    publish_depth_interval: int | None = key("publish depth interval", "uint")
    publish_image_resolution: Resolution | None = key("publish image resolution", Resolution)
    publish_depth_resolution: Resolution | None = key("publish depth resolution", Resolution)
    publish_depth_noise: DepthNoise | None = key("publish depth noise", DepthNoise)
    preprocessing_shaders: Shaders | None = key("preprocessing shaders", Shaders)
    depth_compute_shaders: Shaders | None = key("depth compute shaders", Shaders)
    multipass: bool | None = key("multipass", "bool")
    mouse_control_multipliers: MouseMultipliers | None = key("mouse control multipliers", MouseMultipliers)


@dataclass(kw_only=True)
class Attenuation(Node):
    constant: float | None = key("constant", "float")
    linear: float | None = key("linear", "float")
    quadratic: float | None = key("quadratic", "float")


@dataclass(kw_only=True)
class Light(_Comm, _Ident):
    """A spot light (§10); ``direction`` becomes the light's +X axis."""

    parent: str | None = key("parent", "str")
    location: Vec3 | None = key("location", "vec3")
    direction: Vec3 | None = key("direction", "vec3")
    spot_exponent: float | None = key("spot exponent", "float")
    cutoff_angle: float | None = key("cutoff angle", "float")
    shadow_quality: int | None = key("shadow quality", "uint")
    attenuation: Attenuation | None = key("attenuation", Attenuation)


# --- vehicles and volumes -----------------------------------------------------------------


@dataclass(kw_only=True)
class Suspension(Node):
    stiffness: float | None = key("stiffness", "float")
    damping: float | None = key("damping", "float")
    compression: float | None = key("compression", "float")
    rest_length: float | None = key("rest length", "float")


@dataclass(kw_only=True)
class SteeringLimits(Node):
    low: float | None = key("low", "float")
    high: float | None = key("high", "float")


@dataclass(kw_only=True)
class Wheel(Node):
    body: str | None = key("body", "str")
    mesh: str | None = key("mesh", "str")
    width: float | None = key("width", "float")
    radius: float | None = key("radius", "float")
    friction: float | None = key("friction", "float")
    suspension: Suspension | None = key("suspension", Suspension)
    roll_influence: float | None = key("roll influence", "float")
    down_direction: Vec3 | None = key("down direction", "vec3")
    axel_direction: Vec3 | None = key("axel direction", "vec3")
    offset: Vec3 | None = key("offset", "vec3")
    front: bool | None = key("front", "bool")
    steering_limits: SteeringLimits | None = key("steering limits", SteeringLimits)
    max_engine_power: float | None = key("max engine power", "float")
    max_brake_power: float | None = key("max brake power", "float")


@dataclass(kw_only=True)
class Vehicle(_Comm, _Ident):
    chassis: str | None = key("chassis", "str")
    high_resolution_path: str | None = key("high resolution path", "str")
    wheels: list[Wheel] | None = key("wheels", ListOf(Wheel))


@dataclass(kw_only=True)
class VolumeImages(Node):
    path: str | None = key("path", "str")
    prefix: str | None = key("prefix", "str")
    format: str | None = key("format", "str")
    count: int | None = key("count", "uint")


@dataclass(kw_only=True)
class Volume(_Comm, _Ident):
    parent: str | None = key("parent", "str")
    location: Pose | None = key("location", "pose")
    scale: float | None = key("scale", "float")
    dimensions: Vec3 | None = key("dimensions", "vec3")
    iso_surface_value: float | None = key("iso-surface value", "float")
    optical_density: float | None = key("optical density", "float")
    quality: float | None = key("quality", "float")
    shaders: Shaders | None = key("shaders", Shaders)
    color_rgba: RGBA | None = key("color rgba", RGBA)
    color_components: ColorComponents | None = key("color components", ColorComponents)
    use_material: bool | None = key("use material", "bool")
    images: VolumeImages | None = key("images", VolumeImages)
