"""Small scenes that each exercise one part of the physics, to be played side by side in AMBF
and adfkit (``adfkit parity``, docs/parity.md): a box dropped onto a slab, an arm on a revolute
joint driven by position, velocity and effort commands (a command file for each). They need
nothing but themselves: no corpus, no meshes. The launch file lists one model per scene on the
same world (a floor); ``-l`` picks one."""

from __future__ import annotations

from pathlib import Path

from ..adf import atomic_write_text
from ..adf.writer import write_file
from ..model import (
    RGBA,
    Body,
    Colors,
    Geometry,
    InputDevices,
    Joint,
    JointLimits,
    Launch,
    ModelFile,
    Pose,
    Vec3,
    World,
)
from ..model.objects import Inertia
from ..model.pose import rpy_to_quat
from .suturing_pad import build_floor

GREY = RGBA(r=0.6, g=0.6, b=0.65, a=1.0)
ORANGE = RGBA(r=0.9, g=0.5, b=0.1, a=1.0)

#: the launch file's models, in order (-l INDEX)
SCENES = ("drop", "arm")

#: command files beside the scenes: (file, scene, lines)
COMMANDS = {
    "arm_position.txt": ("arm", ["0.0, position, base-arm, 0.6", "0.5, position, base-arm, -0.3"]),
    "arm_velocity.txt": ("arm", ["0.0, velocity, base-arm, 1.0", "0.3, velocity, base-arm, -0.5"]),
    "arm_effort.txt": ("arm", ["0.0, effort, base-arm, 0.02", "0.4, effort, base-arm, -0.03"]),
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


def build_arm() -> ModelFile:
    """A 30 cm, 0.5 kg arm on a revolute joint about z (gravity across the axis) from a static
    post: what a joint command does is all that moves it. No `controller`: AMBF's position
    commands go through its default P 10, D 1 velocity controller."""
    m = ModelFile(namespace="/ambf/env/arm/")
    m.bodies.append(_box("base", (0.05, 0.05, 0.05), (0.0, 0.0, 0.5)))
    m.bodies.append(_box("arm", (0.3, 0.03, 0.03), (0.2, 0.0, 0.5), mass=0.5, color=ORANGE))
    m.joints.append(
        Joint(
            identifier="JOINT base-arm",
            name="base-arm",
            parent="BODY base",
            child="BODY arm",
            type="revolute",
            parent_pivot=Vec3(0.0, 0.0, 0.0),
            parent_axis=Vec3(0.0, 0.0, 1.0),
            child_pivot=Vec3(-0.2, 0.0, 0.0),
            child_axis=Vec3(0.0, 0.0, 1.0),
            joint_limits=JointLimits(low=-2.0, high=2.0),
            max_motor_impulse=0.05,
        )
    )
    return m


BUILD = {"drop": build_drop, "arm": build_arm}


def write_parity(out_dir: str | Path) -> Path:
    """Write launch.yaml (the scenes of SCENES in order), world.yaml, floor.yaml, one model file
    per scene, the command files of COMMANDS, input_devices.yaml and colors.yaml into
    ``out_dir``; returns the launch file path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for name in SCENES:
        write_file(BUILD[name](), out / f"{name}.yaml")
    for fname, (scene, lines) in COMMANDS.items():
        head = f"# {scene}.yaml (-l {SCENES.index(scene)}): TIME, KIND, JOINT, VALUE (adfkit parity --commands)\n"
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


__all__ = ["SCENES", "COMMANDS", "write_parity", "build_drop", "build_arm"]
