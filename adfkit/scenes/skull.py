"""A skull-base drilling scene laid out as the public AMBF drilling projects lay theirs out, with
a temporal-bone-shaped volume of adfkit's own making:

    launch.yaml                          drills.yaml, skull.yaml, stereo_cameras.yaml
    ADF/world.yaml                       main_camera, and light1 hanging from it
    ADF/drills.yaml                      BODY 2mm: a drill drawn as a mesh, its tip a 1 mm ball
    ADF/skull.yaml                       VOLUME skull: images {path, prefix: plane00, format: png, count: 512}
    ADF/stereo_cameras.yaml              stereoL, stereoR hanging from main_camera
    ADF/meshes/high_res/2mm.OBJ
    resources/volumes/skull/plane00<i>.png   RGBA slices, fewer than count (AMBF reads count as a maximum)
    resources/volumes/skull/labels.yaml      the colours' tissues for `adfkit drill`, sinus and nerve protected

The volume is segmented as the projects' are, by colour, with alpha 255 in tissue and 0 in
air: a rounded block of bone whose cortex covers mastoid air cells, a sigmoid sinus, the facial
nerve and the ear canal (air). Slices are made one at a time, so a 512³ volume is written in
the memory of one slice.
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
    InputDevices,
    Launch,
    Light,
    ModelFile,
    Pose,
    Resolution,
    Vec3,
    World,
)
from ..model.objects import Volume, VolumeImages
from .suturing_pad import build_floor

BONE = (255, 249, 219)  # the drilling projects' bone colour
SINUS = (110, 184, 209)
NERVE = (244, 214, 49)
TIP = 0.001  # m: the drill's round tip (a 2 mm burr)


@dataclass
class SkullParams:
    voxels: int = 128  # pixels per slice side; slices: 15/16 of it (a folder fuller than none, emptier than count)
    size: float = 0.0492027  # m, the volume's side (the drilling projects' dimensions)
    count: int = 512  # `images: count`, the most AMBF searches for
    seed: int = 11

    @property
    def slices(self) -> int:
        return max(2, self.voxels * 15 // 16)


def _cells(p: SkullParams) -> np.ndarray:
    """(n, 4) mastoid air cells: centre x, y, z and radius, in the unit box."""
    rng = np.random.default_rng(p.seed)
    n = 70
    centre = np.column_stack([rng.uniform(-0.45, 0.65, n), rng.uniform(-0.45, 0.5, n), rng.uniform(0.0, 0.5, n)])
    return np.column_stack([centre, rng.uniform(0.04, 0.11, n)])


def _tube(x, y, z, a, b, r) -> np.ndarray:
    """Points within ``r`` of the segment a-b (unit box)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    ab = b - a
    t = np.clip(((x - a[0]) * ab[0] + (y - a[1]) * ab[1] + (z - a[2]) * ab[2]) / (ab @ ab), 0, 1)
    return (x - a[0] - t * ab[0]) ** 2 + (y - a[1] - t * ab[1]) ** 2 + (z - a[2] - t * ab[2]) ** 2 <= r * r


def _ellipsoid(x, y, z, centre, radii) -> np.ndarray:
    """The ellipsoid's implicit value: 1 on its surface, below 1 inside."""
    return sum(((v - c) / r) ** 2 for v, c, r in zip((x, y, z), centre, radii))


def skull_slice(p: SkullParams, k: int, cells: np.ndarray | None = None) -> np.ndarray:
    """Slice ``k`` (of ``p.slices``, from the volume's -z side) as an RGBA picture (rows from the
    top, the volume's +y side, as a slice file holds it): alpha 255 in tissue, 0 in air."""
    cells = _cells(p) if cells is None else cells
    n = p.voxels
    c = (np.arange(n) + 0.5) / n * 2 - 1
    x = c[None, :]
    y = c[::-1, None]  # the picture's top row is +y
    z = (k + 0.5) / p.slices * 2 - 1
    # the temporal bone's outline: a rounded block, the mastoid process below its back, the
    # petrous ridge along its front, a gentle waviness
    wave = 0.04 * np.sin(3.1 * x + 1.3) * np.cos(2.7 * y - 0.4) + 0.03 * np.sin(2.3 * z + 2.1 * x)
    block = (np.abs(x) / 0.85) ** 3 + (np.abs(y) / 0.72) ** 3 + (np.abs(z - 0.05) / 0.62) ** 3 + wave
    mastoid = _ellipsoid(x, y, z, (0.4, -0.3, -0.5), (0.33, 0.3, 0.42))
    u, v = (x + y) / np.sqrt(2), (y - x) / np.sqrt(2)  # the ridge runs diagonally
    ridge = _ellipsoid(u, v, z, (0.0, 0.45, 0.35), (0.85, 0.2, 0.3))
    shape = np.minimum(np.minimum(block, mastoid), ridge)
    alpha = (shape <= 1.0).astype(float)  # 0 or 1, as a segmentation gives it
    inner = shape <= 0.55  # the cortex is what lies outside it
    hollow = np.zeros_like(shape, dtype=bool)
    for cx, cy, cz, r in cells:
        if abs(z - cz) < r:
            hollow |= inner & ((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2 <= r * r)
    hollow |= _tube(x, y, z, (-1.2, 0.3, -0.25), (-0.25, 0.3, -0.25), 0.14)  # the ear canal
    alpha[hollow] = 0.0
    bone = alpha > 0
    sinus = bone & (
        _tube(x, y, z, (0.7, -0.3, 0.45), (0.55, -0.35, -0.1), 0.13)
        | _tube(x, y, z, (0.55, -0.35, -0.1), (0.1, -0.3, -0.55), 0.13)
    )
    nerve = bone & (
        _tube(x, y, z, (-0.45, 0.1, -0.05), (0.05, 0.05, -0.15), 0.045)
        | _tube(x, y, z, (0.05, 0.05, -0.15), (0.15, -0.2, -0.6), 0.045)
    )
    out = np.zeros((n, n, 4), np.uint8)
    out[bone, :3] = BONE
    out[sinus, :3] = SINUS
    out[nerve, :3] = NERVE
    out[..., 3] = np.rint(alpha * 255)
    out[sinus | nerve, 3] = 255
    return out


LABELS_YAML = """\
# The tissue each colour of the slices stands for, read by `adfkit drill`; the burr must not
# touch a protected tissue.
bone: "#{:02x}{:02x}{:02x}"
sigmoid sinus: "#{:02x}{:02x}{:02x}"
facial nerve: "#{:02x}{:02x}{:02x}"
protected: [sigmoid sinus, facial nerve]
""".format(*BONE, *SINUS, *NERVE)


def write_skull_slices(folder: Path, p: SkullParams) -> None:
    """The slices, and labels.yaml naming their colours' tissues."""
    from PIL import Image

    from ..adf import atomic_write_text

    folder.mkdir(parents=True, exist_ok=True)
    cells = _cells(p)
    for k in range(p.slices):
        Image.fromarray(skull_slice(p, k, cells), "RGBA").save(folder / f"plane00{k}.png")
    atomic_write_text(folder / "labels.yaml", LABELS_YAML)


def write_drill_mesh(path: Path) -> None:
    """A drill along +x from its origin: the 1 mm tip ball at the origin, a shaft, a handle."""
    import trimesh

    ball = trimesh.creation.icosphere(subdivisions=3, radius=TIP)
    shaft = trimesh.creation.cylinder(radius=0.0006, height=0.04, sections=24)
    handle = trimesh.creation.cylinder(radius=0.005, height=0.08, sections=32)
    turn = trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0])
    for part, at in ((shaft, 0.02), (handle, 0.08)):
        part.apply_transform(turn)
        part.apply_translation([at, 0, 0])
    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.util.concatenate([ball, shaft, handle]).export(path)


def _camera(name: str, location, look_at, parent: str | None = None) -> Camera:
    return Camera(
        identifier=name,
        name=name,
        namespace="cameras/",
        location=Vec3(*location),
        look_at=Vec3(*look_at),
        up=Vec3(0.0, 0.0, 1.0),
        clipping_plane=ClippingPlane(near=0.001, far=5.0),
        field_view_angle=0.6,
        publish_image_resolution=Resolution(width=640, height=480),
        parent=parent,
    )


def write_skull(out_dir: str | Path, p: SkullParams | None = None) -> Path:
    """Write the scene into ``out_dir``; returns its launch file."""
    p = p or SkullParams()
    out = Path(out_dir)
    adf = out / "ADF"
    adf.mkdir(parents=True, exist_ok=True)
    write_skull_slices(out / "resources" / "volumes" / "skull", p)
    write_drill_mesh(adf / "meshes" / "high_res" / "2mm.OBJ")
    half = p.size / 2
    skull = ModelFile(namespace="/ambf/env/")
    skull.volumes.append(
        Volume(
            identifier="VOLUME skull",
            name="skull",
            location=Pose(Vec3(0.0, 0.0, 0.0)),
            dimensions=Vec3(p.size, p.size, p.size * p.slices / p.voxels),
            color_rgba=RGBA(r=1.0, g=0.976, b=0.859, a=1.0),
            images=VolumeImages(path="../resources/volumes/skull/", prefix="plane00", format="png", count=p.count),
        )
    )
    write_file(skull, adf / "skull.yaml")
    drills = ModelFile(
        namespace="/ambf/env/", high_resolution_path="meshes/high_res/", low_resolution_path="meshes/high_res/"
    )
    drills.bodies.append(  # its tip over the mastoid, the shaft rising away from it
        Body(
            identifier="BODY 2mm",
            name="2mm",
            mesh="2mm.OBJ",
            mass=0.0,
            inertial_offset=Pose(),  # else AMBF moves its collision shape to its vertices' mean, 8.2 mm
            location=Pose.from_rpy((0.2 * half, 0.1 * half, half + 0.004), (0.0, -1.2, 0.0)),
        )
    )
    write_file(drills, adf / "drills.yaml")
    stereo = ModelFile(namespace="/ambf/env/")
    stereo.cameras += [
        _camera("stereoL", (0.0, 0.0, 0.0), (-0.3, 0.0, 0.0), "main_camera"),
        _camera("stereoR", (0.0, 0.005, 0.0), (-0.3, 0.005, 0.0), "main_camera"),
    ]
    write_file(stereo, adf / "stereo_cameras.yaml")
    world = World(namespace="/ambf/env/", gravity=Vec3(0.0, 0.0, 0.0), max_iterations=50, environment="floor.yaml")
    world.cameras.append(_camera("main_camera", (0.09, -0.06, 0.08), (0.0, 0.0, 0.0)))
    world.lights.append(
        Light(
            identifier="light1",
            name="light1",
            namespace="lights/",
            location=Vec3(0.0, 0.0, 0.02),
            direction=Vec3(-1.0, 0.0, 0.0),
            spot_exponent=0.3,
            cutoff_angle=0.8,
            shadow_quality=0,
            parent="main_camera",
        )
    )
    write_file(world, adf / "world.yaml")
    write_file(build_floor(-0.05), adf / "floor.yaml")
    write_file(InputDevices(present_lists={"input devices"}), adf / "input_devices.yaml")
    write_file(Colors(colors={}), adf / "colors.yaml")
    launch = Launch(
        world_config="ADF/world.yaml",
        color_config="ADF/colors.yaml",
        input_devices_config="ADF/input_devices.yaml",
        multibody_configs=["ADF/drills.yaml", "ADF/skull.yaml", "ADF/stereo_cameras.yaml"],
    )
    return write_file(launch, out / "launch.yaml")


__all__ = ["NERVE", "SINUS", "SkullParams", "skull_slice", "write_skull"]
