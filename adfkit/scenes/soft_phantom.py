"""A soft tissue phantom: a skin membrane (an ADF soft body, a square grid mesh) held at its
border over a rigid tray, and a rigid tool on a free vertical slide (no motor:
`max motor impulse: 0`) above its centre: the suturing needle lying flat (the default), or
a spherical probe (``tool="sphere"``). Under gravity the tool sinks into the skin;
tests/test_soft_bodies.py measures the indentation. The world has a floor, a camera looking
along the skin and a light.

The skin's settings are Bullet soft-body keys (config: kLST, piterations, kDP, kDF, fixed
nodes) as AMBF reads them; the PyBullet runner maps them as docs/soft-bodies.md
says. The mesh is written beside the model file as skin.obj.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ..adf.writer import atomic_write_text, write_file
from ..model import (
    RGBA,
    Body,
    Camera,
    ClippingPlane,
    Colors,
    Friction,
    Geometry,
    Inertia,
    InputDevices,
    Joint,
    JointLimits,
    Launch,
    Light,
    ModelFile,
    Pose,
    Quat,
    Resolution,
    ShapeEntry,
    Vec3,
    World,
)
from ..model.objects import SoftBody, SoftBodyConfig
from .suturing_pad import FLOOR, STEEL, TISSUE, build_floor

TRAY = RGBA(r=0.3, g=0.3, b=0.35, a=1.0)


@dataclass
class SoftPhantomParams:
    size: float = 0.1  # skin side, m
    cells: int = 20  # grid cells per side (nodes: (cells + 1)²)
    height: float = 0.04  # skin above the floor, m
    skin_mass: float = 0.05  # kg
    kLST: float = 0.2  # Bullet link stiffness
    piterations: int = 4
    kDP: float = 0.5
    kDF: float = 0.5
    margin: float = 0.001  # collision margin, m
    probe_mass: float = 0.05  # kg
    probe_radius: float = 0.008  # spherical tip, m
    tool: str = "needle"  # the suturing needle lying flat, or "sphere": a probe
    needle_radius: float = 0.012  # arc radius, m (the suturing pad's)
    needle_wire: float = 0.0005  # wire radius, m
    probe_gap: float = 0.002  # tip above the skin at the start, m
    with_probe: bool = True


def grid_obj(size: float, cells: int) -> str:
    """A flat square of size × size in the z = 0 plane, centred on the origin, as OBJ text:
    (cells + 1)² vertices row by row (index = j·(cells + 1) + i), two triangles per cell."""
    n = cells + 1
    step = size / cells
    lines = ["# soft phantom skin, written by adfkit.scenes.soft_phantom"]
    for j in range(n):
        for i in range(n):
            lines.append(f"v {-size / 2 + i * step:.6f} {-size / 2 + j * step:.6f} 0.000000")
    for j in range(cells):
        for i in range(cells):
            a = j * n + i + 1
            lines.append(f"f {a} {a + 1} {a + n + 1}")
            lines.append(f"f {a} {a + n + 1} {a + n}")
    return "\n".join(lines) + "\n"


def border_nodes(cells: int) -> list[int]:
    n = cells + 1
    return [j * n + i for j in range(n) for i in range(n) if i in (0, cells) or j in (0, cells)]


def build_soft_phantom(p: SoftPhantomParams | None = None) -> ModelFile:
    p = p or SoftPhantomParams()
    m = ModelFile(namespace="/ambf/env/phantom/")
    m.soft_bodies.append(
        SoftBody(
            identifier="SOFTBODY Skin",
            name="Skin",
            mesh="skin.obj",
            mass=p.skin_mass,
            location=Pose(Vec3(0.0, 0.0, p.height)),
            collision_margin=p.margin,
            color_rgba=TISSUE,
            config=SoftBodyConfig(
                kLST=p.kLST,
                piterations=p.piterations,
                kDP=p.kDP,
                kDF=p.kDF,
                bending_constraint=2,
                fixed_nodes=border_nodes(p.cells),
            ),
        )
    )
    tray = Geometry(x=p.size * 1.2, y=p.size * 1.2, z=0.01)
    m.bodies.append(
        Body(
            identifier="BODY Tray",
            name="Tray",
            mass=0.0,
            location=Pose(Vec3(0, 0, 0.005)),
            shape="Box",
            geometry=tray,
            collision_shape="Box",
            collision_geometry=tray,
            collision_offset=Pose(),
            color_rgba=TRAY,
            friction=Friction(static=0.8, rolling=0.01),
            restitution=0.0,
        )
    )
    if not p.with_probe:
        return m
    tool, tool_z = _needle(p) if p.tool == "needle" else _sphere_probe(p)
    holder_z = tool_z + 0.04
    holder = Geometry(x=0.02, y=0.02, z=0.01)
    m.bodies.append(
        Body(
            identifier="BODY Holder",
            name="Holder",
            mass=0.0,
            location=Pose(Vec3(0, 0, holder_z)),
            shape="Box",
            geometry=holder,
            # a static body with no collision shape holds no joint in AMBF (runner/plan.py
            # holds_nothing): its needle fell through the skin to the tray there, turned 5°
            collision_shape="Box",
            collision_geometry=holder,
            color_rgba=STEEL,
        )
    )
    m.bodies.append(tool)
    m.joints.append(
        Joint(
            identifier=f"JOINT Holder-{tool.name}",
            name=f"Holder-{tool.name}",
            parent="BODY Holder",
            child=tool.identifier,
            type="prismatic",
            parent_pivot=Vec3(0, 0, tool_z - holder_z),
            child_pivot=Vec3(),
            parent_axis=Vec3(0, 0, 1),
            child_axis=Vec3(0, 0, 1),
            joint_limits=JointLimits(low=-0.04, high=0.0),
            max_motor_impulse=0.0,
        )
    )
    return m


def _sphere_probe(p: SoftPhantomParams) -> tuple[Body, float]:
    # a sphere: PyBullet's soft contact lets an upright capsule's end through a membrane that holds a sphere
    z = p.height + p.probe_gap + p.probe_radius
    tip = Geometry(radius=p.probe_radius)
    i = 0.4 * p.probe_mass * p.probe_radius**2
    return Body(
        identifier="BODY Probe",
        name="Probe",
        mass=p.probe_mass,
        location=Pose(Vec3(0, 0, z)),
        shape="Sphere",
        geometry=tip,
        collision_shape="Sphere",
        collision_geometry=tip,
        collision_offset=Pose(),
        inertia=Inertia(ix=i, iy=i, iz=i),
        inertial_offset=Pose(),
        color_rgba=STEEL,
        friction=Friction(static=0.3, rolling=0.01),
        restitution=0.0,
    ), z


def _needle(p: SoftPhantomParams) -> tuple[Body, float]:
    """The suturing pad's needle (a 3/8 circle of 12 mm radius, 0.5 mm wire, as capsules along
    the arc) lying flat on the skin, pressed by `probe_mass` (its weight and a driver's push)."""
    n = 6
    r, wire, arc = p.needle_radius, p.needle_wire, 3 * math.pi / 4
    step = arc / n
    chord = 2 * r * math.sin(step / 2)
    parts = []
    for k in range(n):
        mid = -arc / 2 + (k + 0.5) * step
        # the arc's mid-point at the body origin, so the needle presses on the skin's centre
        pos = Vec3(r * math.cos(mid) - r, r * math.sin(mid), 0.0)
        parts.append(
            ShapeEntry(
                shape="Capsule",
                offset=Pose(pos, Quat.from_axis_angle((0, 0, 1), mid + math.pi / 2)),
                geometry=Geometry(radius=wire, height=chord + 2 * wire, axis="x"),
            )
        )
    z = p.height + p.probe_gap + wire
    mass = p.probe_mass
    return Body(
        identifier="BODY Needle",
        name="Needle",
        mass=mass,
        location=Pose(Vec3(0, 0, z)),
        compound_shape=[ShapeEntry(shape=e.shape, geometry=e.geometry, offset=e.offset) for e in parts],
        compound_collision_shape=parts,
        color_rgba=STEEL,
        inertia=Inertia(ix=mass * r * r / 2, iy=mass * r * r / 2, iz=mass * r * r),
        inertial_offset=Pose(),
        friction=Friction(static=0.3, rolling=0.01),
        restitution=0.0,
    ), z


def build_world(p: SoftPhantomParams) -> World:
    w = World(namespace="/ambf/env/", gravity=Vec3(0, 0, -9.81), max_iterations=50, environment="floor.yaml")
    w.cameras.append(
        Camera(
            identifier="camera",
            name="camera",
            namespace="cameras/",
            location=Vec3(0.0, -0.16, p.height + 0.03),
            look_at=Vec3(0.0, 0.0, p.height - 0.01),
            up=Vec3(0, 0, 1),
            clipping_plane=ClippingPlane(near=0.01, far=2.0),
            field_view_angle=0.6,
            publish_image_resolution=Resolution(width=640, height=480),
        )
    )
    w.lights.append(
        Light(
            identifier="light1",
            name="light1",
            namespace="lights/",
            location=Vec3(0, 0, 1.0),
            direction=Vec3(0, 0, -1),
            spot_exponent=0.3,
            cutoff_angle=1.2,
            shadow_quality=0,
        )
    )
    return w


def write_soft_phantom(out_dir: str | Path, p: SoftPhantomParams | None = None) -> Path:
    """Write launch.yaml, world.yaml, floor.yaml, phantom.yaml, skin.obj, input_devices.yaml
    and colors.yaml into ``out_dir``; returns the launch file path."""
    p = p or SoftPhantomParams()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / "skin.obj", grid_obj(p.size, p.cells))
    write_file(build_floor(), out / "floor.yaml")
    write_file(build_soft_phantom(p), out / "phantom.yaml")
    write_file(build_world(p), out / "world.yaml")
    write_file(InputDevices(present_lists={"input devices"}), out / "input_devices.yaml")
    write_file(Colors(colors={"tissue": TISSUE, "steel": STEEL, "floor": FLOOR}), out / "colors.yaml")
    launch = Launch(
        world_config="world.yaml",
        color_config="colors.yaml",
        input_devices_config="input_devices.yaml",
        multibody_configs=["phantom.yaml"],
    )
    return write_file(launch, out / "launch.yaml")


__all__ = ["SoftPhantomParams", "build_soft_phantom", "write_soft_phantom", "grid_obj", "border_nodes"]
