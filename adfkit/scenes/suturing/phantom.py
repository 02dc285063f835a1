"""The tissue phantom: a textured slab with a slot the needle lies across, a ridge of tissue
blocks with a gap at each of the four entry/exit pairs, the holes' capsule boundary bodies
(Entry1..4, Exit1..4: a square of four capsules around each hole, tilted along the needle's
path), their ghost objects (thin boxes), the camera frame body, and the needle and thread.
Names follow the challenge's ``Phantoms/Simple`` files."""

from __future__ import annotations

import numpy as np

from ...model import (
    RGBA,
    Body,
    Friction,
    Geometry,
    Ghost,
    ModelFile,
    Pose,
    ShapeEntry,
    Vec3,
)
from . import layout as L
from .frames import for_ambf, look_frame, pose, r, vec
from .meshes import boxes_mesh, obj_text
from .needle import needle_body
from .thread import thread_bodies_and_joints

HOLE = RGBA(r=0.12, g=0.05, b=0.05, a=1.0)
GHOST = RGBA(r=0.8, g=0.04, b=0.02, a=0.4)
FRAME_HALF = 0.003  # the hole's capsule square: centre lines 6 mm apart
CAPSULE_RADIUS = 0.0006
GHOST_SIZE = (0.005, 0.005, 0.00045)
TEXTURE_SCALE = 0.04  # metres per texture repeat
#: where the stereo camera frame is and the point it looks at
CAMERA_FRAME = (0.0, -0.085, 0.15)
CAMERA_TARGET = (0.0, 0.012, 0.03)


def phantom_boxes() -> list[tuple[tuple, tuple]]:
    """The phantom as axis-aligned boxes ((min), (max)) in the world (its body frame is the world's)."""
    sx, sy, sz = L.SLAB
    lower = sz - L.SLOT_DEPTH
    x0, x1 = L.SLOT_X
    gy = L.NEEDLE_GRASP_XY[1]
    y0, y1 = gy - L.SLOT_HALF_Y, gy + L.SLOT_HALF_Y
    boxes = [
        ((-sx / 2, -sy / 2, 0.0), (sx / 2, sy / 2, lower)),  # the slab's lower half
        ((-sx / 2, -sy / 2, lower), (sx / 2, y0, sz)),  # upper half around the slot
        ((-sx / 2, y1, lower), (sx / 2, sy / 2, sz)),
        ((-sx / 2, y0, lower), (x0, y1, sz)),
        ((x1, y0, lower), (sx / 2, y1, sz)),
    ]
    # the ridge: blocks between the gaps of the hole pairs
    edges = [L.RIDGE_Y[0]]
    for y in sorted(L.HOLE_YS):
        edges += [y - L.RIDGE_GAP / 2, y + L.RIDGE_GAP / 2]
    edges.append(L.RIDGE_Y[1])
    for a, b in zip(edges[0::2], edges[1::2]):
        boxes.append(((-L.RIDGE_HALF_X, a, sz), (L.RIDGE_HALF_X, b, L.RIDGE_TOP)))
    return [(tuple(r(v) for v in lo), tuple(r(v) for v in hi)) for lo, hi in boxes]


def phantom_obj_text() -> str:
    v, uv, f = boxes_mesh(phantom_boxes(), TEXTURE_SCALE)
    return obj_text(
        v,
        f,
        uvs=uv,
        mtllib="Phantom.mtl",
        material="tissue",
        comment="tissue phantom: slab, needle slot and ridge, written by adfkit",
    )


def phantom_mtl_text() -> str:
    return (
        "newmtl tissue\nKa 0.3 0.3 0.3\nKd 1.0 1.0 1.0\nKs 0.25 0.2 0.2\nNs 30\nd 1\n"
        "map_Kd tissue.png\nmap_Bump tissue_normal.png\nnorm tissue_normal.png\n"
    )


def _phantom_body(boxes=None, location: Pose | None = None) -> Body:
    """BODY Phantom: a mesh, colliding as ``boxes`` (its frame's; the bundled phantom's by
    default), at ``location`` (the world's origin by default)."""
    parts = []
    for lo, hi in boxes if boxes is not None else phantom_boxes():
        c = [(a + b) / 2 for a, b in zip(lo, hi)]
        parts.append(
            ShapeEntry(
                shape="Box",
                geometry=Geometry(x=r(hi[0] - lo[0]), y=r(hi[1] - lo[1]), z=r(hi[2] - lo[2])),
                offset=Pose(vec(c)),
            )
        )
    return Body(
        identifier="BODY Phantom",
        name="Phantom",
        mass=0.0,
        location=location or Pose(),
        mesh="Phantom.OBJ",
        compound_collision_shape=parts,
        collision_margin=0.0001,
        use_material=True,
        friction=Friction(static=0.8, rolling=0.01),
        restitution=0.0,
        passive=False,
    )


def _hole_body(name: str, world: np.ndarray) -> Body:
    caps = []
    for axis, at in (
        ("x", (0.0, -FRAME_HALF, 0.0)),
        ("x", (0.0, FRAME_HALF, 0.0)),
        ("y", (FRAME_HALF, 0.0, 0.0)),
        ("y", (-FRAME_HALF, 0.0, 0.0)),
    ):
        caps.append(
            ShapeEntry(
                shape="Capsule",
                geometry=Geometry(radius=CAPSULE_RADIUS, height=2 * FRAME_HALF + 0.001, axis=axis),
                offset=Pose(Vec3(*at)),
            )
        )
    return Body(
        identifier=f"BODY {name}",
        name=name,
        mass=0.0,
        location=pose(world),
        shape="Cylinder",
        geometry=Geometry(radius=0.0014, height=0.0003, axis="z"),
        compound_collision_shape=caps,
        collision_margin=0.0001,
        color_rgba=HOLE,
        friction=Friction(static=0.0, rolling=0.0),
        restitution=0.1,
        passive=False,
    )


def camera_frame() -> np.ndarray:
    """The stereo pair's frame: it looks along its -z at CAMERA_TARGET, image up (its +y)
    toward the far side of the phantom."""
    at = np.array(CAMERA_FRAME)
    z = at - np.array(CAMERA_TARGET)
    z /= np.linalg.norm(z)
    return look_frame(at, z, np.cross((0.0, 1.0, 0.0), z))


def build_phantom() -> ModelFile:
    m = ModelFile(
        namespace="/ambf/env/phantom/",
        ignore_inter_collision=False,
        high_resolution_path="./meshes/",
        low_resolution_path="./meshes/",
    )
    m.bodies.append(_phantom_body())
    for k in range(1, 5):
        entry, exit_ = L.hole_poses(k)
        m.bodies.append(_hole_body(f"Entry{k}", entry))
    for k in range(1, 5):
        m.bodies.append(_hole_body(f"Exit{k}", L.hole_poses(k)[1]))
    m.bodies.append(
        Body(identifier="BODY CameraFrame", name="CameraFrame", mass=0.0, location=pose(camera_frame()), passive=False)
    )
    needle = L.needle_start()
    m.bodies.append(needle_body(needle))
    bodies, joints = thread_bodies_and_joints(needle)
    m.bodies += bodies
    m.joints += joints
    return for_ambf(m)


def hole_ghost(kind: str, k: int) -> Ghost:
    """The ghost ghost<kind><k> on hole body <kind><k> (kind: Entry or Exit), at its centre."""
    g = Geometry(x=GHOST_SIZE[0], y=GHOST_SIZE[1], z=GHOST_SIZE[2])
    return Ghost(
        identifier=f"GHOST ghost{kind}{k}",
        name=f"ghost{kind}{k}",
        parent=f"BODY {kind}{k}",
        location=Pose(),
        shape="Box",
        geometry=g,
        collision_shape="Box",
        collision_geometry=g,
        collision_margin=0.0001,
        color_rgba=GHOST,
        passive=False,
    )


def build_hole_ghosts() -> ModelFile:
    m = ModelFile(namespace="/ambf/env/phantom/", ignore_inter_collision=True)
    m.ghost_objects = [hole_ghost(kind, k) for kind in ("Entry", "Exit") for k in range(1, 5)]
    return m


__all__ = ["build_phantom", "build_hole_ghosts", "phantom_obj_text", "phantom_mtl_text", "phantom_boxes"]
