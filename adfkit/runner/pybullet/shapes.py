"""Collision and visual shapes of bodies and ghosts (adf-format.md §7.3–§7.5, §12.3).

Every shape pose is given in the object's COM frame, the frame PyBullet uses as the base
frame. Primitive collision dimensions are not scaled; meshes are (§12.3).
"""

from __future__ import annotations

import math
import os
import tempfile
from dataclasses import dataclass, field

import numpy as np
import pybullet as pb

from ... import inputs, scratch
from ...adf.paths import collision_mesh_path, visual_mesh_path
from ...diagnostics import Diagnostic, warning
from ...geometry.concave import parts_obj
from ...geometry.meshcheck import mesh_problem, obj_material_problems
from ...model.pose import Pose, Quat, Vec3
from ...model.semantics import (
    CollisionMeshType,
    Primitive,
    ShapeKind,
    collision_mesh_pose,
    collision_mesh_type,
    collision_primitives,
    cone_vertices,
    shape_kind,
    shortest_arc,
)
from ..collisions import convex_stand_in
from ..plan import mesh_refusal, mesh_skipped, rgba, uncreated
from ..rotations import invert, matrix_to_pq, pose_to_matrix
from .margins import file_margin, give_margin
from .meshfiles import MESH_SUFFIXES, hull_pieces, is_convex, pybullet_mesh, reads_quietly


@dataclass
class ShapeParts:
    """Arguments for createCollisionShapeArray (one entry per child shape)."""

    types: list[int] = field(default_factory=list)
    kwargs: list[dict] = field(default_factory=list)
    plane: tuple[list[float], float] | None = None  # a lone PLANE (added directly, §7.4)
    margin: float | None = None  # the file's collision margin, where PyBullet's 1 mm is not it (margins.py)

    def add(self, shape_type: int, **kw) -> None:
        self.types.append(shape_type)
        self.kwargs.append(kw)


_CONE_CACHE: dict[tuple[float, float], str] = {}


def cone_obj(radius: float, height: float) -> str:
    """A cone along +z centred on half its height (Bullet's btConeShapeZ, model.semantics'
    cone_vertices, as the MJCF writer's), as an OBJ file in the scratch folder."""
    key = (round(radius, 9), round(height, 9))
    if key in _CONE_CACHE and os.path.exists(_CONE_CACHE[key]):
        return _CONE_CACHE[key]
    pts = cone_vertices(radius, height)
    n = len(pts) - 2
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in pts]
    for i in range(n):
        j = (i + 1) % n
        lines.append(f"f 1 {i + 3} {j + 3}")
        lines.append(f"f 2 {j + 3} {i + 3}")
    fd, path = tempfile.mkstemp(prefix="cone_", suffix=".obj", dir=scratch.scratch_dir())
    with os.fdopen(fd, "w") as f:
        f.write("\n".join(lines) + "\n")
    _CONE_CACHE[key] = path
    return path


def _axis_rotation(axis: Vec3) -> Quat:
    """Rotation taking PyBullet's z-aligned primitive onto the ADF `axis`."""
    return shortest_arc(Vec3(0, 0, 1), axis)


def _primitive(parts: ShapeParts, prim: Primitive, pose_in_com: np.ndarray) -> None:
    g = prim.geometry
    rot = pose_in_com @ pose_to_matrix(Pose(Vec3(), _axis_rotation(prim.axis)))
    pos, orn = matrix_to_pq(rot)
    if prim.kind is ShapeKind.BOX:
        parts.add(
            pb.GEOM_BOX,
            halfExtents=[g.x / 2, g.y / 2, g.z / 2],
            collisionFramePosition=matrix_to_pq(pose_in_com)[0],
            collisionFrameOrientation=matrix_to_pq(pose_in_com)[1],
        )
    elif prim.kind is ShapeKind.SPHERE:
        parts.add(pb.GEOM_SPHERE, radius=g.radius, collisionFramePosition=pos, collisionFrameOrientation=orn)
    elif prim.kind is ShapeKind.CYLINDER:
        parts.add(
            pb.GEOM_CYLINDER,
            radius=g.radius,
            height=g.height,
            collisionFramePosition=pos,
            collisionFrameOrientation=orn,
        )
    elif prim.kind is ShapeKind.CAPSULE:  # ADF height includes the caps
        parts.add(
            pb.GEOM_CAPSULE,
            radius=g.radius,
            height=max(g.height - 2 * g.radius, 0.0),
            collisionFramePosition=pos,
            collisionFrameOrientation=orn,
        )
    elif prim.kind is ShapeKind.CONE:
        parts.add(
            pb.GEOM_MESH,
            fileName=cone_obj(g.radius, g.height),
            meshScale=[1, 1, 1],
            collisionFramePosition=pos,
            collisionFrameOrientation=orn,
        )
    elif prim.kind is ShapeKind.PLANE:
        n = np.array(g.normal or (0, 0, 1), dtype=float)
        n = n / (np.linalg.norm(n) or 1.0)
        parts.plane = (list(map(float, n)), float(g.offset or 0.0))


_DIMENSIONS = {
    ShapeKind.BOX: ("x", "y", "z"),
    ShapeKind.SPHERE: ("radius",),
    ShapeKind.CYLINDER: ("radius", "height"),
    ShapeKind.CAPSULE: ("radius", "height"),
    ShapeKind.CONE: ("radius", "height"),
}


def _missing_dimension(prim: Primitive) -> str | None:
    """The first dimension a primitive needs that is absent, not a number, negative or not finite."""
    for name in _DIMENSIONS.get(prim.kind, ()):
        v = getattr(prim.geometry, name, None)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
            return name
    return None


def collision_parts(
    model, obj, frame_in_body, scale: float, static: bool, diags: list[Diagnostic], deformable: bool = False
) -> ShapeParts | None:
    """The collision shape of a body or ghost, or None when AMBF would skip the object.
    ``deformable``: the world has soft bodies, which cannot collide with a triangle mesh
    (Bullet's sparse SDF gives every point a distance 0 to a non-convex shape, so the nodes
    near one are pushed away): a static concave mesh is played as convex hulls, one per OBJ
    object, with a warning unless the mesh is convex anyway."""
    if (why := uncreated(model, obj)) is not None:  # a mesh missing, refused or without triangles (plan.py)
        diags.append(why)
        return None
    parts = ShapeParts(margin=file_margin(obj))
    body_to_com = invert(frame_in_body)
    prims = collision_primitives(obj)
    if prims is not None:
        if not prims:
            diags.append(
                warning(
                    "runner-no-collision",
                    f"{obj.identifier}: no usable collision primitive",
                    obj.source,
                    "check `collision shape` and `collision geometry`",
                )
            )
        for prim in prims:
            missing = _missing_dimension(prim)
            if missing:
                diags.append(
                    warning(
                        "runner-no-collision",
                        f"{obj.identifier}: collision {prim.kind.value} has no "
                        f"usable {missing}; that shape is left out",
                        obj.where("collision geometry") or obj.source,
                        "give every dimension as a finite number ≥ 0",
                    )
                )
                continue
            _primitive(parts, prim, body_to_com @ pose_to_matrix(prim.pose))
        return parts
    path = collision_mesh_path(model, obj)
    if path is None:
        return parts  # no collision geometry: an empty shape (AMBF prints an error)
    path, refused = pybullet_mesh(model, path)
    if refused is not None:  # an STL neither PyBullet nor trimesh can read
        diags.append(mesh_skipped(obj, refused))
        return None
    if path.suffix.lower() not in MESH_SUFFIXES:
        diags.append(
            warning(
                "runner-mesh-format",
                f"{obj.identifier}: collision mesh {inputs.shown(path.name)}: PyBullet reads OBJ and STL meshes, "
                f"not {path.suffix or 'files without a suffix'}; no collision shape",
                obj.where("collision mesh" if obj.collision_mesh is not None else "mesh") or obj.source,
                "export the mesh as OBJ or STL",
            )
        )
        return parts
    kind, _ = collision_mesh_type(obj.collision_mesh_type)
    pos, orn = matrix_to_pq(body_to_com @ pose_to_matrix(collision_mesh_pose(obj)))
    kw = dict(fileName=str(path), meshScale=[scale] * 3, collisionFramePosition=pos, collisionFrameOrientation=orn)
    if kind is CollisionMeshType.CONCAVE_MESH and static and deformable:
        if not is_convex(path):
            diags.append(
                warning(
                    "runner-soft-concave",
                    f"{obj.identifier}: concave collision mesh {inputs.shown(path.name)} played as convex hulls "
                    "(one per OBJ object): PyBullet's soft bodies cannot collide with a triangle mesh and are "
                    "torn apart near one",
                    obj.where("collision mesh" if obj.collision_mesh is not None else "mesh") or obj.source,
                    "decompose the mesh (the add-on's Generate convex collision) to keep its hollows",
                )
            )
    elif kind is CollisionMeshType.CONCAVE_MESH and static:
        kw["flags"] = pb.GEOM_FORCE_CONCAVE_TRIMESH  # exact triangles: only static bodies in PyBullet
    if "flags" not in kw:  # hulls, one per sub-mesh as AMBF makes them, or a moving concave mesh's convex parts
        stand_in = None if static else convex_stand_in(model, obj, diags)
        kw["fileName"] = str(parts_obj(stand_in) if stand_in else hull_pieces(path, getattr(model, "tree", None)))
    parts.add(pb.GEOM_MESH, **kw)
    return parts


def create_collision(
    parts: ShapeParts, cid: int, obj=None, diags: list[Diagnostic] | None = None, compound: bool = False
) -> int:
    """Create the PyBullet collision shape, its children given the file's margin; -1 for an
    empty one, or (with a warning located at ``obj``) for one PyBullet refuses. A collision
    mesh does not need its textures: PyBullet's words about missing ones are not printed.
    ``compound``: a single shape too is a compound of it, as AMBF makes every body's
    (``_create_collision``)."""
    try:
        with reads_quietly([kw["fileName"] for kw in parts.kwargs if "fileName" in kw]):
            col = _create_collision(parts, cid, compound)
            give_margin(col, parts.margin, cid)  # (a probe body: PyBullet reads the files there)
        return col
    except pb.error as exc:
        if diags is None:
            raise
        who = getattr(obj, "identifier", "an object")
        diags.append(
            warning(
                "runner-bad-shape",
                f"{who}: PyBullet refused its collision shape ({exc}); it has none",
                getattr(obj, "source", None),
                "check its meshes and shape sizes",
            )
        )
        return -1


#: m, the frame offset that has PyBullet wrap a single shape in a compound (it makes a bare
#: shape of one whose frame is the identity)
COMPOUND_NUDGE = 1e-12


def _create_collision(parts: ShapeParts, cid: int, compound: bool = False) -> int:
    if parts.plane is not None and not parts.types:
        n, off = parts.plane
        return pb.createCollisionShape(
            pb.GEOM_PLANE, planeNormal=n, collisionFramePosition=[c * off for c in n], physicsClientId=cid
        )
    if not parts.types:
        return -1
    if len(parts.types) == 1:
        kw = parts.kwargs[0]
        if compound:
            # AMBF puts every shape in a btCompoundShape, whose child a pair meets only where the
            # two bounding boxes overlap: a ball falling onto a floor makes its contact only once
            # it is in the floor, where PyBullet's bare sphere made it 3 µm above (its second
            # bounce 125 mm from AMBF's; 0.000 mm as a compound)
            x, y, z = kw.get("collisionFramePosition", (0.0, 0.0, 0.0))
            kw = {**kw, "collisionFramePosition": [x, y, z + COMPOUND_NUDGE]}
        return pb.createCollisionShape(parts.types[0], physicsClientId=cid, **kw)
    arrays: dict[str, list] = {
        k: []
        for k in (
            "radii",
            "halfExtents",
            "lengths",
            "fileNames",
            "meshScales",
            "collisionFramePositions",
            "collisionFrameOrientations",
            "flags",
        )
    }
    for _t, kw in zip(parts.types, parts.kwargs):
        arrays["radii"].append(kw.get("radius", 0.5))
        arrays["halfExtents"].append(kw.get("halfExtents", [0.5, 0.5, 0.5]))
        arrays["lengths"].append(kw.get("height", 1.0))
        arrays["fileNames"].append(kw.get("fileName", ""))
        arrays["meshScales"].append(kw.get("meshScale", [1, 1, 1]))
        arrays["collisionFramePositions"].append(kw.get("collisionFramePosition", [0, 0, 0]))
        arrays["collisionFrameOrientations"].append(kw.get("collisionFrameOrientation", [0, 0, 0, 1]))
        arrays["flags"].append(kw.get("flags", 0))
    return pb.createCollisionShapeArray(shapeTypes=parts.types, physicsClientId=cid, **arrays)


def create_visual(model, obj, frame_in_body, scale: float, cid: int, diags: list[Diagnostic]) -> int:
    """Visual shape (primitive beats mesh; compound parts drawn at the body origin, §7.3)."""
    colour = rgba(obj) or [0.8, 0.8, 0.8, 1.0]
    pos, orn = matrix_to_pq(invert(frame_in_body))
    base = dict(visualFramePosition=pos, visualFrameOrientation=orn, rgbaColor=colour, physicsClientId=cid)
    entries = []
    if obj.shape and obj.geometry is not None:
        entries = [(obj.shape, obj.geometry)]
    elif obj.compound_shape:
        entries = [(e.shape, e.geometry) for e in obj.compound_shape if e.geometry is not None]
    if entries:
        shape, g = entries[0]  # PyBullet visual shapes are single; draw the first part
        k = shape_kind(shape)
        try:
            if k is ShapeKind.BOX:
                return pb.createVisualShape(
                    pb.GEOM_BOX, halfExtents=[g.x * scale / 2, g.y * scale / 2, g.z * scale / 2], **base
                )
            if k is ShapeKind.SPHERE:
                return pb.createVisualShape(pb.GEOM_SPHERE, radius=g.radius * scale, **base)
            if k in (ShapeKind.CYLINDER, ShapeKind.CAPSULE):  # always along Z (§7.3)
                return pb.createVisualShape(pb.GEOM_CYLINDER, radius=g.radius * scale, length=g.height * scale, **base)
            if k is ShapeKind.CONE:
                return pb.createVisualShape(pb.GEOM_MESH, fileName=cone_obj(g.radius * scale, g.height * scale), **base)
        except (TypeError, pb.error):
            pass
        return -1
    path = visual_mesh_path(model, obj)
    if path is None:
        return -1
    suffix = path.suffix.lower()
    if suffix in MESH_SUFFIXES and mesh_refusal(model, path) is None and (problem := mesh_problem(path)) is not None:
        diags.append(
            warning(
                "runner-bad-mesh",
                f"{obj.identifier}: visual mesh {inputs.shown(path.name)}: {problem}",
                obj.where("mesh") or obj.source,
                "the body is drawn without a visual mesh",
            )
        )
        return -1
    path, refused = pybullet_mesh(model, path) if suffix in MESH_SUFFIXES else (path, mesh_refusal(model, path))
    if refused is not None:
        diags.append(
            warning(
                "runner-missing-mesh",
                f"{obj.identifier}: visual mesh {refused}",
                obj.where("mesh") or obj.source,
                "the body is drawn without a visual mesh",
            )
        )
        return -1
    if suffix not in MESH_SUFFIXES:
        diags.append(
            warning(
                "runner-mesh-format",
                f"{obj.identifier}: visual mesh {inputs.shown(path.name)}: PyBullet reads OBJ and STL meshes, "
                f"not {path.suffix or 'files without a suffix'}; the body is drawn without it",
                obj.where("mesh") or obj.source,
                "export the mesh as OBJ or STL",
            )
        )
        return -1
    kw = dict(base)
    if rgba(obj) is None:
        kw.pop("rgbaColor")
    missing = obj_material_problems(str(path)) if suffix == ".obj" else ()
    for what in missing:
        diags.append(
            warning(
                "runner-missing-texture",
                f"{obj.identifier}: {what} of visual mesh {inputs.shown(path.name)} not found",
                obj.where("mesh") or obj.source,
                "the mesh is drawn without it; textures come from the mesh's own material (MTL) file",
            )
        )
    try:  # (PyBullet reads the file in createMultiBody: pybullet_reads_quietly)
        return pb.createVisualShape(pb.GEOM_MESH, fileName=str(path), meshScale=[scale] * 3, **kw)
    except pb.error:
        diags.append(
            warning(
                "runner-visual", f"{obj.identifier}: PyBullet could not read {path}", obj.source, "re-export the mesh"
            )
        )
        return -1
