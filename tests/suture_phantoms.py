"""Phantoms built from the bundled suturing scene for the suture's verdict tests: the issue's
negative controls (a channel narrowed below the wire, its floor raised into the needle's arc,
the phantom raised under its holes, the phantom in its own model file, filled or not).

Each builder copies ``sample_scenes/suturing`` into a folder, changes the phantom through the
scene model (read, edit, write back) and returns the launch file."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

from adfkit.adf import read_file, write_file
from adfkit.model import Geometry, Pose, ShapeEntry, Vec3
from adfkit.scenes.suturing import layout as L

ROOT = Path(__file__).resolve().parents[1]
BUNDLED = ROOT / "sample_scenes" / "suturing"
PHANTOM = Path("phantom") / "phantom.yaml"


def copy_scene(folder: Path) -> Path:
    dst = folder / "suturing"
    shutil.copytree(BUNDLED, dst)
    return dst


def _box(lo, hi) -> ShapeEntry:
    c = [(a + b) / 2 for a, b in zip(lo, hi)]
    return ShapeEntry(
        shape="Box",
        geometry=Geometry(x=hi[0] - lo[0], y=hi[1] - lo[1], z=hi[2] - lo[2]),
        offset=Pose(Vec3(*c)),
    )


def edit_phantom(scene: Path, fn) -> None:
    """``fn(model)`` on phantom/phantom.yaml, written back."""
    doc, _ = read_file(scene / PHANTOM, "model")
    fn(doc)
    write_file(doc, scene / PHANTOM)


def _body(doc, name):
    return next(b for b in doc.bodies if b.name == name)


def add_boxes(scene: Path, boxes) -> None:
    """Boxes ((lo), (hi), world = the phantom's frame) added to Phantom's collision only."""
    edit_phantom(scene, lambda doc: _body(doc, "Phantom").compound_collision_shape.extend(_box(*b) for b in boxes))


def gap(k: int) -> tuple[float, float]:
    """y from and to of the ridge's gap at pair k."""
    y = L.HOLE_YS[k - 1]
    return y - L.RIDGE_GAP / 2, y + L.RIDGE_GAP / 2


def narrow_channel(folder: Path, width: float, k: int = 1) -> Path:
    """Pair k's channel (the ridge's gap) narrowed to ``width`` m in the collision."""
    s = copy_scene(folder)
    y0, y1 = gap(k)
    y = L.HOLE_YS[k - 1]
    x, z0, z1 = L.RIDGE_HALF_X, L.SLAB[2], L.RIDGE_TOP
    add_boxes(s, [((-x, y0, z0), (x, y - width / 2, z1)), ((-x, y + width / 2, z0), (x, y1, z1))])
    return s / "launch.yaml"


def raise_floor(folder: Path, height: float, k: int = 1) -> Path:
    """Pair k's channel filled from the slab up to ``height`` m (world z)."""
    s = copy_scene(folder)
    y0, y1 = gap(k)
    add_boxes(s, [((-L.RIDGE_HALF_X, y0, L.SLAB[2]), (L.RIDGE_HALF_X, y1, height))])
    return s / "launch.yaml"


def fill_holes(folder: Path, pairs=(1, 2, 3, 4)) -> Path:
    s = copy_scene(folder)
    add_boxes(s, [((-L.RIDGE_HALF_X, gap(k)[0], L.SLAB[2]), (L.RIDGE_HALF_X, gap(k)[1], L.RIDGE_TOP)) for k in pairs])
    return s / "launch.yaml"


def _moved(p: Pose | None, dz: float) -> Pose:
    p = p or Pose()
    return Pose(Vec3(p.position.x, p.position.y, p.position.z + dz), p.orientation)


def raise_phantom(folder: Path, dz: float = 0.004) -> Path:
    """The phantom (with the needle and the thread lying on it) ``dz`` m higher, its holes
    where they were."""
    s = copy_scene(folder)

    def fn(doc):
        for b in doc.bodies:
            if b.name == "Phantom" or b.name == "Needle" or b.name.startswith("Thread"):
                b.location = _moved(b.location, dz)

    edit_phantom(s, fn)
    return s / "launch.yaml"


def phantom_in_own_file(folder: Path, filled: bool = False) -> Path:
    """BODY Phantom moved, unchanged (or with every hole filled), into a model file of its own
    (phantom/tissue.yaml), listed in the launch file."""
    s = fill_holes(folder).parent if filled else copy_scene(folder)
    doc, _ = read_file(s / PHANTOM, "model")
    phantom = _body(doc, "Phantom")
    doc.bodies.remove(phantom)
    write_file(doc, s / PHANTOM)
    own, _ = read_file(s / PHANTOM, "model")
    own.bodies, own.joints = [phantom], []
    write_file(own, s / "phantom" / "tissue.yaml")
    launch, _ = read_file(s / "launch.yaml")
    launch.multibody_configs.append("phantom/tissue.yaml")
    write_file(launch, s / "launch.yaml")
    return s / "launch.yaml"


def fill_slot(folder: Path) -> Path:
    """The slot the needle lies across filled: the needle lies on a flat slab."""
    s = copy_scene(folder)
    gy = L.NEEDLE_GRASP_XY[1]
    add_boxes(
        s, [((L.SLOT_X[0], gy - L.SLOT_HALF_Y, L.SLAB[2] - L.SLOT_DEPTH), (L.SLOT_X[1], gy + L.SLOT_HALF_Y, L.SLAB[2]))]
    )
    return s / "launch.yaml"


# ---- a modeller's phantom in its own file, as `adfkit suture --phantom` takes it -------------
def phantom_file(
    folder: Path,
    pairs: int = 4,
    spacing: float = 0.024,
    turn_deg: float = 0.0,
    line_deg: float = 0.0,
    thicker: float = 0.0,
    at=(0.0, 0.0),
    numbered_back: bool = False,
) -> Path:
    """One model file holding a phantom alone, as the add-on exports one: a slab and a ridge of
    tissue boxes with a gap at each pair (the channel the needle goes through), the hole bodies
    Entry k / Exit k (four capsules each) and their ghosts. ``pairs`` pairs ``spacing`` apart
    along the ridge, 14 mm from entry to exit; the whole phantom turned ``turn_deg`` about the
    vertical and moved to ``at``; the line of pairs slanted ``line_deg`` (each pair still across
    the ridge); slab and ridge ``thicker`` (the holes on its top); ``numbered_back``: pair 1 at
    the other end of the line (where the bundled scene has its last pair). Returns the model file."""
    from adfkit.model import ModelFile
    from adfkit.scenes.suturing.frames import pose, rot_y, rot_z, translation
    from adfkit.scenes.suturing.meshes import boxes_mesh, obj_text
    from adfkit.scenes.suturing.phantom import TEXTURE_SCALE, _hole_body, _phantom_body, hole_ghost

    ys = [((pairs + 1) / 2 - k) * spacing * (-1 if numbered_back else 1) for k in range(1, pairs + 1)]
    slant = math.tan(math.radians(line_deg))
    xs = [y * slant for y in ys]
    top = L.RIDGE_TOP + thicker
    slab = L.SLAB[2] + thicker
    half_x = L.RIDGE_HALF_X + max(abs(x) for x in xs)
    y_end = max(abs(y) for y in ys) + 0.014
    boxes = [((-L.SLAB[0] / 2, -L.SLAB[1] / 2, 0.0), (L.SLAB[0] / 2, L.SLAB[1] / 2, slab))]
    edges = [-y_end]
    for y in sorted(ys):
        edges += [y - L.RIDGE_GAP / 2, y + L.RIDGE_GAP / 2]
    edges.append(y_end)
    boxes += [((-half_x, a, slab), (half_x, b, top)) for a, b in zip(edges[0::2], edges[1::2])]
    place = translation(at[0], at[1], 0.0) @ rot_z(math.radians(turn_deg))
    m = ModelFile(namespace="/ambf/env/phantom/", high_resolution_path="./meshes/", low_resolution_path="./meshes/")
    m.bodies.append(_phantom_body(boxes, pose(place)))
    tilt = L.entry_angle()
    for kind, sign in (("Entry", -1.0), ("Exit", 1.0)):
        for k, (x, y) in enumerate(zip(xs, ys), start=1):
            hole = place @ translation(x + sign * L.HOLE_HALF_GAP, y, top) @ rot_y(sign * tilt)
            m.bodies.append(_hole_body(f"{kind}{k}", hole))
            m.ghost_objects.append(hole_ghost(kind, k))
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "meshes").mkdir(exist_ok=True)
    v, uv, f = boxes_mesh(boxes, TEXTURE_SCALE)
    (folder / "meshes" / "Phantom.OBJ").write_text(obj_text(v, f, uvs=uv, mtllib="Phantom.mtl", material="tissue"))
    (folder / "meshes" / "Phantom.mtl").write_text("newmtl tissue\nKd 0.85 0.55 0.5\nd 1\n")
    return write_file(m, folder / "phantom.yaml")


def tilt_phantom(path: Path, axis: str, deg: float) -> Path:
    """The phantom file at ``path`` turned ``deg`` about world ``axis`` ("x": the line of pairs
    runs uphill toward pair 1's end for deg > 0; "y": entry above exit for deg > 0) and raised
    until its slab's lowest corner stands on the floor (turned about the origin, a third of it
    went through the floor, and the needle's thread with it). Written back; returns ``path``."""
    import numpy as np

    from adfkit.runner.rotations import pose_to_matrix
    from adfkit.scenes.suturing.frames import pose, rot_x, rot_y, translation

    turn = (rot_x if axis == "x" else rot_y)(math.radians(deg))
    corners = np.array([(sx * L.SLAB[0] / 2, sy * L.SLAB[1] / 2, 0.0, 1.0) for sx in (-1, 1) for sy in (-1, 1)])
    up = max(0.0, -float((corners @ turn.T)[:, 2].min()))
    doc, _ = read_file(path, "model")
    for b in doc.bodies:
        b.location = pose(translation(0.0, 0.0, up) @ turn @ pose_to_matrix(b.location))
    write_file(doc, path)
    return path
