"""The drilling scene: a bone-like voxel volume (two labelled tissues: bone, and a canal of
softer tissue through it, as a nerve runs through the temporal bone) written as PNG slices, a
drill (a shaft and a spherical burr) on a prismatic mount above it, weightless as a held tool,
stereo cameras and a light.

Voxel values (8 bit): 0 air, CANAL inside the canal, BONE elsewhere in the bone, with a little
texture; the iso-surface at 0.5 of full scale (127.5) is the bone's surface, and the canal,
below it, is a tunnel through the bone.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..adf.writer import write_file
from ..model import (
    RGBA,
    Body,
    Camera,
    ClippingPlane,
    Colors,
    Geometry,
    InputDevices,
    Joint,
    JointLimits,
    Launch,
    Light,
    ModelFile,
    Pose,
    Resolution,
    Stereo,
    Vec3,
    World,
)
from ..model.objects import Volume, VolumeImages
from .suturing_pad import build_floor

BONE, CANAL = 230, 90  # voxel values of the two tissues (air is 0)
BONE_RGBA = RGBA(r=0.93, g=0.89, b=0.78, a=1.0)
STEEL = RGBA(r=0.7, g=0.7, b=0.75, a=1.0)


@dataclass
class DrillingParams:
    voxels: int = 48  # slices, and pixels per slice side
    size: float = 0.04  # m, the volume's cube side
    canal_radius: float = 0.004  # m
    burr_radius: float = 0.002  # m
    shaft_length: float = 0.05  # m
    seed: int = 7


def bone_voxels(p: DrillingParams) -> np.ndarray:
    """(slices, rows, columns) uint8: a rounded bone block with a canal along x through it."""
    n = p.voxels
    c = (np.arange(n) + 0.5) / n - 0.5  # voxel centres in units of the size
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    block = (np.abs(x) / 0.42) ** 4 + (np.abs(y) / 0.38) ** 4 + (np.abs(z) / 0.30) ** 4 <= 1.0
    canal = (y**2 + (z + 0.05) ** 2) <= (p.canal_radius / p.size) ** 2
    rng = np.random.default_rng(p.seed)
    vol = np.where(block, BONE - rng.integers(0, 20, size=block.shape), 0)
    vol = np.where(block & canal, CANAL, vol)
    return vol.astype(np.uint8)


LABELS_YAML = f"""\
# The tissue each range of slice values stands for (8-bit values), read by `adfkit drill`;
# the burr must not touch a protected tissue.
bone: [150, 255]   # {BONE - 19}..{BONE}
canal: [60, 120]   # {CANAL}
protected: [canal]
"""


def write_slices(vox: np.ndarray, folder: Path, prefix: str = "bone_") -> None:
    from PIL import Image

    from ..adf import atomic_write_text

    folder.mkdir(parents=True, exist_ok=True)
    for i, s in enumerate(vox):
        Image.fromarray(s).save(folder / f"{prefix}{i}.png", optimize=True)
    atomic_write_text(folder / "labels.yaml", LABELS_YAML)


def build_drill_model(p: DrillingParams) -> ModelFile:
    # The drill is held by whoever drills (as the PSM files make their arms weightless): AMBF
    # leaves the mount's prismatic joint free (its motor off until commanded), so under the
    # world's gravity the shaft slides down through the bone (AMBF's volumes do not collide) to
    # the floor, 68 mm in 1 s. The model's own gravity, which AMBF reads, holds it where it is.
    m = ModelFile(namespace="/ambf/env/drilling/", gravity=Vec3(0.0, 0.0, 0.0))
    m.volumes.append(
        Volume(
            identifier="VOLUME Bone",
            name="Bone",
            location=Pose(Vec3(0, 0, p.size / 2)),
            dimensions=Vec3(p.size, p.size, p.size),
            iso_surface_value=0.5,
            color_rgba=BONE_RGBA,
            images=VolumeImages(path="slices/", prefix="bone_", format="png", count=p.voxels),
        )
    )
    top = p.size + 0.03
    m.bodies.append(
        Body(
            identifier="BODY Mount",
            name="Mount",
            mass=0.0,
            shape="Box",
            geometry=Geometry(x=0.01, y=0.01, z=0.01),
            collision_shape="Box",  # without one AMBF's slider holds nothing (runner/plan.py holds_nothing)
            collision_geometry=Geometry(x=0.01, y=0.01, z=0.01),
            location=Pose(Vec3(0, 0, top + p.shaft_length)),
            color_rgba=STEEL,
        )
    )
    shaft_r = 0.6 * p.burr_radius
    m.bodies.append(
        Body(
            identifier="BODY Shaft",
            name="Shaft",
            mass=0.05,
            shape="Cylinder",
            geometry=Geometry(radius=shaft_r, height=p.shaft_length, axis="z"),
            collision_shape="Cylinder",
            collision_geometry=Geometry(radius=shaft_r, height=p.shaft_length, axis="z"),
            location=Pose(Vec3(0, 0, top + p.shaft_length / 2)),
            color_rgba=STEEL,
        )
    )
    m.bodies.append(
        Body(
            identifier="BODY Burr",
            name="Burr",
            mass=0.01,
            shape="Sphere",
            geometry=Geometry(radius=p.burr_radius),
            collision_shape="Sphere",
            collision_geometry=Geometry(radius=p.burr_radius),
            location=Pose(Vec3(0, 0, top)),
            color_rgba=RGBA(r=0.85, g=0.7, b=0.2, a=1.0),
        )
    )
    m.joints.append(
        Joint(
            identifier="JOINT Mount-Shaft",
            name="Mount-Shaft",
            parent="BODY Mount",
            child="BODY Shaft",
            type="prismatic",
            parent_pivot=Vec3(0, 0, -p.shaft_length / 2),
            child_pivot=Vec3(0, 0, 0),
            parent_axis=Vec3(0, 0, 1),
            child_axis=Vec3(0, 0, 1),
            joint_limits=JointLimits(low=-0.08, high=0.0),
        )
    )
    m.joints.append(
        Joint(
            identifier="JOINT Shaft-Burr",
            name="Shaft-Burr",
            parent="BODY Shaft",
            child="BODY Burr",
            type="fixed",
            parent_pivot=Vec3(0, 0, -p.shaft_length / 2),
            child_pivot=Vec3(0, 0, 0),
            parent_axis=Vec3(0, 0, 1),
            child_axis=Vec3(0, 0, 1),
        )
    )
    return m


def build_world(p: DrillingParams) -> World:
    w = World(namespace="/ambf/env/", gravity=Vec3(0, 0, -9.81), max_iterations=50, environment="floor.yaml")
    w.cameras.append(
        Camera(
            identifier="cameraL",
            name="cameraL",
            namespace="cameras/",
            location=Vec3(0.09, -0.10, 0.12),
            look_at=Vec3(0.0, 0.0, p.size / 2),
            up=Vec3(0, 0, 1),
            clipping_plane=ClippingPlane(near=0.01, far=1.0),
            field_view_angle=0.7,
            publish_image_resolution=Resolution(width=640, height=480),
            stereo=Stereo(mode="", eye_separation=0.005, focal_length=0.15),
        )
    )
    w.lights.append(
        Light(
            identifier="light1",
            name="light1",
            namespace="lights/",
            location=Vec3(0.1, -0.1, 0.5),
            direction=Vec3(-0.2, 0.2, -1),
            spot_exponent=0.3,
            cutoff_angle=1.2,
            shadow_quality=0,
        )
    )
    return w


def write_drilling(out_dir: str | Path, p: DrillingParams | None = None) -> Path:
    """Write launch.yaml, world.yaml, floor.yaml, drill.yaml (the volume and the drill), slices/bone_*.png
    with slices/labels.yaml (bone, and the canal as a protected tissue),
    input_devices.yaml and colors.yaml into ``out_dir``; returns the launch file path."""
    p = p or DrillingParams()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_slices(bone_voxels(p), out / "slices")
    write_file(build_drill_model(p), out / "drill.yaml")
    write_file(build_floor(), out / "floor.yaml")
    write_file(build_world(p), out / "world.yaml")
    write_file(InputDevices(present_lists={"input devices"}), out / "input_devices.yaml")
    write_file(Colors(colors={"bone": BONE_RGBA, "steel": STEEL}), out / "colors.yaml")
    launch = Launch(
        world_config="world.yaml",
        color_config="colors.yaml",
        input_devices_config="input_devices.yaml",
        multibody_configs=["drill.yaml"],
    )
    return write_file(launch, out / "launch.yaml")


__all__ = ["DrillingParams", "bone_voxels", "build_drill_model", "write_drilling", "BONE", "CANAL"]
