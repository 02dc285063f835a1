"""The four ADF file kinds (launch, world, input devices, model) and the colors file,
plus :class:`Scene`, a launch with the world and the model files it selects."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from .common import RGBA, CartesianController, Plugin, Shaders
from .objects import (
    Actuator,
    Body,
    Camera,
    Ghost,
    Joint,
    Light,
    Sensor,
    SoftBody,
    Vehicle,
    Volume,
)
from .pose import Pose, Quat, Vec3
from .spec import ListOf, Node, Obj, key

if TYPE_CHECKING:  # the model does no I/O: the input policy's Tree is only named here
    from ..inputs import Tree


@dataclass(frozen=True)
class ObjectList:
    """Marks a top-level key that lists object identifiers (`bodies: [BODY a, ...]`)."""

    kind: type


def object_list(adf_key: str, cls: type):
    return key(adf_key, ObjectList(cls), default_factory=list)


@dataclass(kw_only=True)
class AdfFile(Node):
    """Common to every file: where it lives (for path resolution) and its version marker."""

    path: Path | None = field(default=None, compare=False, repr=False)
    # The folder the files this one names must lie in (adfkit.inputs.Tree); None: no limit.
    tree: Tree | None = field(default=None, compare=False, repr=False)
    adf_version: str | None = key("adf version", "str")

    @property
    def directory(self) -> Path:
        return self.path.parent if self.path else Path(".")


@dataclass(kw_only=True)
class ModelFile(AdfFile):
    """A model (multibody) ADF file (§6)."""

    bodies: list[Body] = object_list("bodies", Body)
    joints: list[Joint] = object_list("joints", Joint)
    soft_bodies: list[SoftBody] = object_list("soft bodies", SoftBody)
    ghost_objects: list[Ghost] = object_list("ghost objects", Ghost)
    sensors: list[Sensor] = object_list("sensors", Sensor)
    actuators: list[Actuator] = object_list("actuators", Actuator)
    cameras: list[Camera] = object_list("cameras", Camera)
    lights: list[Light] = object_list("lights", Light)
    vehicles: list[Vehicle] = object_list("vehicles", Vehicle)
    volumes: list[Volume] = object_list("volumes", Volume)
    high_resolution_path: str | None = key("high resolution path", "str")
    low_resolution_path: str | None = key("low resolution path", "str")
    ignore_inter_collision: bool | None = key("ignore inter-collision", "bool")
    gravity: Vec3 | None = key("gravity", "vec3")
    namespace: str | None = key("namespace", "str")
    shaders: Shaders | None = key("shaders", Shaders)
    plugins: list[Plugin] | None = key("plugins", ListOf(Plugin))
    joint_erp: float | None = key("joint erp", "float")
    joint_cfm: float | None = key("joint cfm", "float")
    # Which top-level list keys the file wrote (an absent list and an empty one differ on disk).
    present_lists: set[str] = field(default_factory=set, compare=False, repr=False)

    @property
    def name(self) -> str:
        """AMBF names a model after its file."""
        return self.path.stem if self.path else "model"

    def body(self, identifier: str) -> Body | None:
        for b in self.bodies:
            if b.identifier == identifier:
                return b
        return None

    def all_objects(self) -> list[Obj]:
        return [
            *self.bodies,
            *self.soft_bodies,
            *self.ghost_objects,
            *self.sensors,
            *self.actuators,
            *self.joints,
            *self.vehicles,
            *self.cameras,
            *self.lights,
            *self.volumes,
        ]


@dataclass(kw_only=True)
class Enclosure(Node):
    length: float | None = key("length", "float")
    width: float | None = key("width", "float")
    height: float | None = key("height", "float")


@dataclass(kw_only=True)
class Skybox(Node):
    path: str | None = key("path", "str")
    right: str | None = key("right", "str")
    left: str | None = key("left", "str")
    top: str | None = key("top", "str")
    bottom: str | None = key("bottom", "str")
    front: str | None = key("front", "str")
    back: str | None = key("back", "str")
    shaders: Shaders | None = key("shaders", Shaders)


@dataclass(kw_only=True)
class World(AdfFile):
    """A world file (§4): gravity, environment model, lights, cameras."""

    lights: list[Light] = object_list("lights", Light)
    cameras: list[Camera] = object_list("cameras", Camera)
    namespace: str | None = key("namespace", "str")
    gravity: Vec3 | None = key("gravity", "vec3")
    max_iterations: int | None = key("max iterations", "uint")
    environment: str | None = key("environment", "str")
    enclosure: Enclosure | None = key("enclosure", Enclosure)
    skybox: Skybox | None = key("skybox", Skybox)
    shaders: Shaders | None = key("shaders", Shaders)
    plugins: list[Plugin] | None = key("plugins", ListOf(Plugin))
    name: str | None = key("name", "str")
    present_lists: set[str] = field(default_factory=set, compare=False, repr=False)


@dataclass(kw_only=True)
class Launch(AdfFile):
    """A launch file (§3); paths are relative to the launch file's directory."""

    world_config: str | None = key("world config", "str")
    color_config: str | None = key("color config", "str")
    input_devices_config: str | None = key("input devices config", "str")
    multibody_configs: list[str] | None = key("multibody configs", ListOf("str"))
    plugins: list[Plugin] | None = key("plugins", ListOf(Plugin))


@dataclass(kw_only=True)
class HapticGain(Node):
    linear: float | None = key("linear", "float")
    angular: float | None = key("angular", "float")


@dataclass(kw_only=True)
class ButtonMapping(Node):
    a1: int | None = key("a1", "int")
    a2: int | None = key("a2", "int")
    g1: int | None = key("g1", "int")
    next_mode: int | None = key("next mode", "int")
    prev_mode: int | None = key("prev mode", "int")


@dataclass(kw_only=True)
class InputDevice(Obj):
    """One physical device and its simulated counterpart (§5)."""

    hardware_name: str | None = key("hardware name", "str")
    haptic_gain: HapticGain | None = key("haptic gain", HapticGain)
    workspace_scaling: float | None = key("workspace scaling", "float")
    deadband: float | None = key("deadband", "float")
    max_force: float | None = key("max force", "float")
    max_jerk: float | None = key("max jerk", "float")
    orientation_offset: Quat | None = key("orientation offset", "rpy")
    button_mapping: ButtonMapping | None = key("button mapping", ButtonMapping)
    visible: bool | None = key("visible", "bool")
    visible_size: float | None = key("visible size", "float")
    simulated_multibody: str | None = key("simulated multibody", "str")
    root_link: str | None = key("root link", "str")
    location: Pose | None = key("location", "pose")
    controller_gain: CartesianController | None = key("controller gain", CartesianController)
    enable_joint_control: bool | None = key("enable joint control", "bool")
    pair_cameras: list[str] | None = key("pair cameras", ListOf("str"))


@dataclass(kw_only=True)
class InputDevices(AdfFile):
    input_devices: list[InputDevice] = object_list("input devices", InputDevice)
    present_lists: set[str] = field(default_factory=set, compare=False, repr=False)


@dataclass(kw_only=True)
class Colors(AdfFile):
    """The colors file: named {r, g, b, a} colours (read by AMBF 1.x only)."""

    colors: dict[str, RGBA] = field(default_factory=dict)


@dataclass(kw_only=True)
class Scene:
    """What AMBF builds: a world plus the model files chosen from a launch, in load order."""

    launch: Launch | None = None
    world: World | None = None
    environment: ModelFile | None = None
    models: list[ModelFile] = field(default_factory=list)
    input_devices: InputDevices | None = None

    def all_models(self) -> list[ModelFile]:
        return ([self.environment] if self.environment else []) + list(self.models)


FILE_KINDS = {"launch": Launch, "world": World, "input_devices": InputDevices, "model": ModelFile, "colors": Colors}
