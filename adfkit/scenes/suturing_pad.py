"""The suturing pad: a tissue pad with four entry/exit hole pairs (each with a ghost
object), a curved needle made of four capsules along its arc, and a thread of N capsule
elements joined by six-dof springs, in a world with a stereo camera pair.

Everything is a primitive, so the scene needs no mesh files. Dimensions are SI and close
to a real 3/8-circle suture needle; the thread's spring settings follow the published
suturing scene (angular limits ±π/6, angular stiffness 0.02 N·m/rad, damping 0.01).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ..adf.writer import write_file
from ..model import (
    RGBA,
    AxesGains,
    Body,
    Camera,
    ClippingPlane,
    Colors,
    Friction,
    Geometry,
    Ghost,
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
    Vec3Range,
    VelocityDamping,
    World,
)

TISSUE = RGBA(r=0.85, g=0.55, b=0.5, a=1.0)
STEEL = RGBA(r=0.7, g=0.7, b=0.75, a=1.0)
THREAD = RGBA(r=0.2, g=0.3, b=0.9, a=1.0)
HOLE = RGBA(r=0.1, g=0.1, b=0.1, a=1.0)
FLOOR = RGBA(r=0.5, g=0.5, b=0.5, a=1.0)


@dataclass
class SuturingPadParams:
    pad_size: tuple[float, float, float] = (0.12, 0.08, 0.02)  # m, full lengths
    hole_pairs: int = 4
    hole_gap: float = 0.012  # entry-to-exit distance, m
    needle_radius: float = 0.012  # arc radius, m
    needle_arc: float = 3 * math.pi / 4  # 3/8 circle
    needle_wire: float = 0.0005  # wire radius, m
    needle_mass: float = 0.002  # kg
    thread_elements: int = 40
    thread_length: float = 0.2  # m
    thread_radius: float = 0.0004
    thread_mass: float = 0.0005  # kg per element
    #: kg·m² of each element about every axis, not its capsule's (1e-9): AMBF damps the joints
    #: explicitly, and the chain settles only where an element's inertia passes 4·c·dt (c the
    #: joints' 0.01 N·m·s/rad, dt AMBF's 1 ms step); at the capsule's the thread turns its needle
    #: over (scenes/suturing/thread.py, docs/parity.md)
    thread_inertia: float = 5e-5
    camera_height: float = 0.25  # m above the pad
    eye_separation: float = 0.005  # stereo baseline, m


def _capsule_inertia(mass: float, r: float, length: float) -> Inertia:
    """Solid cylinder approximation of a thin capsule along x (principal moments)."""
    ix = 0.5 * mass * r * r
    iyz = mass * (3 * r * r + length * length) / 12.0
    return Inertia(ix=ix, iy=iyz, iz=iyz)


def _static_box(ident: str, name: str, size, pose: Pose, color: RGBA) -> Body:
    g = Geometry(x=size[0], y=size[1], z=size[2])
    return Body(
        identifier=ident,
        name=name,
        mass=0.0,
        location=pose,
        shape="Box",
        geometry=g,
        collision_shape="Box",
        collision_geometry=g,
        collision_offset=Pose(),
        color_rgba=color,
        friction=Friction(static=0.8, rolling=0.01),
        restitution=0.0,
    )


def build_suturing_pad(p: SuturingPadParams | None = None) -> ModelFile:
    p = p or SuturingPadParams()
    m = ModelFile(namespace="/ambf/env/pad/", ignore_inter_collision=False)
    sx, sy, sz = p.pad_size
    top = sz
    m.bodies.append(_static_box("BODY Pad", "Pad", p.pad_size, Pose(Vec3(0, 0, sz / 2)), TISSUE))

    # Entry/exit holes: small static markers on the top face, each with a ghost box.
    for i in range(p.hole_pairs):
        y = -sy / 2 + sy * (i + 1) / (p.hole_pairs + 1)
        for kind, x in (("Entry", -p.hole_gap / 2), ("Exit", p.hole_gap / 2)):
            ident = f"BODY {kind}{i + 1}"
            g = Geometry(radius=0.0015)
            m.bodies.append(
                Body(
                    identifier=ident,
                    name=f"{kind}{i + 1}",
                    mass=0.0,
                    location=Pose(Vec3(x, y, top)),
                    shape="Sphere",
                    geometry=g,
                    color_rgba=HOLE,
                    collision_groups=[999],
                )
            )
            m.joints.append(
                Joint(
                    identifier=f"JOINT Pad-{kind}{i + 1}",
                    name=f"Pad-{kind}{i + 1}",
                    parent="BODY Pad",
                    child=ident,
                    type="fixed",
                    parent_pivot=Vec3(x, y, top - sz / 2),
                    child_pivot=Vec3(),
                    parent_axis=Vec3(0, 0, 1),
                    child_axis=Vec3(0, 0, 1),
                )
            )
            gg = Geometry(x=0.004, y=0.004, z=0.01)
            m.ghost_objects.append(
                Ghost(
                    identifier=f"GHOST {kind}{i + 1}",
                    name=f"ghost{kind}{i + 1}",
                    parent=ident,
                    location=Pose(Vec3(0, 0, -0.003)),
                    shape="Box",
                    geometry=gg,
                    collision_shape="Box",
                    collision_geometry=gg,
                    collision_offset=Pose(),
                )
            )

    # Needle: a 3/8 arc lying in a vertical plane above the pad, made of four capsules.
    needle_z = top + p.needle_radius + 0.01
    centre = Vec3(-sx / 4, 0.0, needle_z)
    parts = []
    n_parts = 4
    dtheta = p.needle_arc / n_parts
    theta0 = -math.pi / 2 - p.needle_arc / 2
    chord = 2 * p.needle_radius * math.sin(dtheta / 2)
    for k in range(n_parts):
        mid = theta0 + (k + 0.5) * dtheta
        pos = Vec3(p.needle_radius * math.cos(mid), 0.0, p.needle_radius * math.sin(mid))
        # capsule along x, rotated about -y so it follows the arc's tangent
        rot = Quat.from_axis_angle((0, -1, 0), mid + math.pi / 2)
        parts.append(
            ShapeEntry(
                shape="Capsule",
                offset=Pose(pos, rot),
                geometry=Geometry(radius=p.needle_wire, height=chord + 2 * p.needle_wire, axis="x"),
            )
        )
    tail_angle = theta0 + p.needle_arc
    tail = Vec3(p.needle_radius * math.cos(tail_angle), 0.0, p.needle_radius * math.sin(tail_angle))
    m.bodies.append(
        Body(
            identifier="BODY Needle",
            name="Needle",
            mass=p.needle_mass,
            location=Pose(centre),
            compound_shape=[ShapeEntry(shape=e.shape, geometry=e.geometry, offset=e.offset) for e in parts],
            compound_collision_shape=parts,
            color_rgba=STEEL,
            inertia=_capsule_inertia(p.needle_mass, p.needle_radius, p.needle_radius),
            inertial_offset=Pose(),
            friction=Friction(static=0.5, rolling=0.01),
            restitution=0.0,
            damping=VelocityDamping(linear=0.1, angular=0.1),
        )
    )

    # Thread: N capsules along +x from the needle's tail, joined by six-dof springs.
    n = p.thread_elements
    seg = p.thread_length / n
    start = centre + tail
    limits = JointLimits(
        linear=Vec3Range(low=Vec3(0, 0, 0), high=Vec3(0, 0, 0)),
        angular=Vec3Range(low=Vec3(*(3 * (-math.pi / 6,))), high=Vec3(*(3 * (math.pi / 6,)))),
    )
    for i in range(n):
        ident = "BODY Thread" if i == 0 else f"BODY Thread_{i:03d}"
        g = Geometry(radius=p.thread_radius, height=seg, axis="x")
        m.bodies.append(
            Body(
                identifier=ident,
                name=ident[5:],
                mass=p.thread_mass,
                location=Pose(start + Vec3(seg * (i + 0.5), 0, 0)),
                shape="Capsule",
                geometry=g,
                collision_shape="Capsule",
                collision_geometry=g,
                collision_offset=Pose(),
                color_rgba=THREAD,
                inertia=Inertia(ix=p.thread_inertia, iy=p.thread_inertia, iz=p.thread_inertia),
                inertial_offset=Pose(),
                friction=Friction(static=0.5, rolling=0.01),
                restitution=0.0,
                damping=VelocityDamping(linear=0.5, angular=0.5),
            )
        )
        if i == 0:
            m.joints.append(
                Joint(
                    identifier="JOINT Needle-Thread",
                    name="Needle-Thread",
                    parent="BODY Needle",
                    child=ident,
                    type="fixed",
                    parent_pivot=tail,
                    child_pivot=Vec3(-seg / 2, 0, 0),
                    parent_axis=Vec3(1, 0, 0),
                    child_axis=Vec3(1, 0, 0),
                )
            )
        else:
            prev = m.bodies[-2].identifier
            m.joints.append(
                Joint(
                    identifier=f"JOINT {prev[5:]}-{ident[5:]}",
                    name=f"{prev[5:]}-{ident[5:]}",
                    parent=prev,
                    child=ident,
                    type="six dof spring",
                    parent_pivot=Vec3(seg / 2, 0, 0),
                    child_pivot=Vec3(-seg / 2, 0, 0),
                    parent_axis=Vec3(1, 0, 0),
                    child_axis=Vec3(1, 0, 0),
                    joint_limits=limits,
                    stiffness=AxesGains(linear=Vec3(0, 0, 0), angular=Vec3(0.02, 0.02, 0.02)),
                    damping=AxesGains(linear=Vec3(0, 0, 0), angular=Vec3(0.01, 0.01, 0.01)),
                    equilibrium_point=AxesGains(linear=Vec3(0, 0, 0), angular=Vec3(0, 0, 0)),
                )
            )
    return m


def build_floor(top: float = 0.0) -> ModelFile:
    """A static 2 m square floor whose top face is at z = ``top``."""
    m = ModelFile(namespace="/ambf/env/")
    m.bodies.append(_static_box("BODY Floor", "Floor", (2.0, 2.0, 0.02), Pose(Vec3(0, 0, top - 0.01)), FLOOR))
    return m


def build_world(p: SuturingPadParams) -> World:
    w = World(namespace="/ambf/env/", gravity=Vec3(0, 0, -9.81), max_iterations=50, environment="floor.yaml")
    h = p.camera_height
    for ident, dx in (("cameraL", -p.eye_separation / 2), ("cameraR", p.eye_separation / 2)):
        w.cameras.append(
            Camera(
                identifier=ident,
                name=ident,
                namespace="cameras/",
                location=Vec3(dx, -0.1, h),
                look_at=Vec3(dx, 0.0, 0.0),
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


def write_suturing_pad(out_dir: str | Path, p: SuturingPadParams | None = None) -> Path:
    """Write launch.yaml, world.yaml, floor.yaml, pad.yaml, input_devices.yaml and
    colors.yaml into ``out_dir``; returns the launch file path."""
    p = p or SuturingPadParams()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_file(build_floor(), out / "floor.yaml")
    write_file(build_suturing_pad(p), out / "pad.yaml")
    write_file(build_world(p), out / "world.yaml")
    write_file(InputDevices(present_lists={"input devices"}), out / "input_devices.yaml")
    write_file(Colors(colors={"tissue": TISSUE, "steel": STEEL, "thread": THREAD}), out / "colors.yaml")
    launch = Launch(
        world_config="world.yaml",
        color_config="colors.yaml",
        input_devices_config="input_devices.yaml",
        multibody_configs=["pad.yaml"],
    )
    return write_file(launch, out / "launch.yaml")


__all__ = ["SuturingPadParams", "build_suturing_pad", "write_suturing_pad"]
