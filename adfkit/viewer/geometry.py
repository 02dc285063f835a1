"""What the viewer draws of an ADF object, as triangle meshes in the object's own frame (the ADF
body frame: the mesh origin): its visual (a primitive, else its visual mesh, scaled, in its
colour) and its collision shape (primitives, compound entries or the collision mesh). The same
ADF rules as the runner (a primitive beats a mesh; §7.3 and §7.4), read from the model, so the
picture does not depend on the engine that plays the scene."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

from ..adf.paths import collision_mesh_path, visual_mesh_path
from ..model.semantics import ShapeKind, collision_primitives, shape_kind
from ..runner.plan import rgba
from ..runner.rotations import pose_to_matrix

DEFAULT_COLOUR = (0.8, 0.8, 0.8, 1.0)


@dataclass
class Part:
    vertices: np.ndarray  # (n, 3) float32, object frame, metres
    faces: np.ndarray  # (m, 3) uint32
    colour: tuple  # (r, g, b, a) in 0..1
    textured: trimesh.Trimesh | None = None  # the same mesh with its texture, when its file has one


def primitive(kind: ShapeKind, g, scale: float = 1.0) -> trimesh.Trimesh | None:
    """A primitive's mesh centred on its frame (cylinders, capsules and cones along ``axis``,
    z by default)."""
    if kind is ShapeKind.BOX:
        return trimesh.creation.box([(g.x or 0) * scale, (g.y or 0) * scale, (g.z or 0) * scale])
    if kind is ShapeKind.SPHERE:
        return trimesh.creation.icosphere(subdivisions=2, radius=(g.radius or 0) * scale)
    r, h = (g.radius or 0) * scale, (g.height or 0) * scale
    if kind is ShapeKind.CYLINDER:
        mesh = trimesh.creation.cylinder(radius=r, height=h, sections=24)
    elif kind is ShapeKind.CAPSULE:
        mesh = trimesh.creation.capsule(height=max(h - 2 * r, 0.0), radius=r, count=[12, 12])
    elif kind is ShapeKind.CONE:
        mesh = trimesh.creation.cone(radius=r, height=h, sections=24)
        mesh.apply_translation([0, 0, -h / 2])
    else:
        return None
    axis = (getattr(g, "axis", None) or "z").lower()
    if axis == "x":
        mesh.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    elif axis == "y":
        mesh.apply_transform(trimesh.transformations.rotation_matrix(-np.pi / 2, [1, 0, 0]))
    return mesh


def _part(mesh: trimesh.Trimesh, colour) -> Part | None:
    if mesh is None or len(mesh.faces) == 0:
        return None
    return Part(
        np.asarray(mesh.vertices, dtype=np.float32),
        np.asarray(mesh.faces, dtype=np.uint32),
        tuple(float(c) for c in colour),
    )


def _mesh_file(model, path, scale: float) -> trimesh.Trimesh | None:
    """A mesh file through the project's one reader (input policy, unit scale); None when it
    cannot be read (the validator and the runner say why)."""
    from ..diagnostics import AdfError
    from ..geometry.meshio import load_mesh

    try:
        return load_mesh(path, scale=scale, tree=getattr(model, "tree", None))
    except (AdfError, ValueError):
        return None


def _textured(model, path, scale: float, tint=None) -> trimesh.Trimesh | None:
    """An OBJ visual mesh with its material's texture (the MTL and the image beside it), scaled,
    the texture multiplied by ``tint`` (an ADF colour: AMBF's material modulates its texture);
    None when it has none. The OBJ goes through the input policy; trimesh reads its MTL and
    image from the OBJ's own folder."""
    from .. import inputs
    from ..diagnostics import AdfError

    try:
        p = inputs.check_mesh(path, tree=getattr(model, "tree", None))
    except AdfError:
        return None
    if p.suffix.lower() != ".obj":
        return None
    try:
        mesh = trimesh.load(str(p), force="mesh", process=False)
    except Exception:  # noqa: BLE001 - drawn untextured (load_mesh says why if it cannot read it at all)
        return None
    visual = getattr(mesh, "visual", None)
    if getattr(visual, "kind", None) != "texture" or getattr(getattr(visual, "material", None), "image", None) is None:
        return None
    mesh.apply_scale(scale)
    if tint is not None:
        visual.material.diffuse = np.clip(np.asarray(tint, float) * 255, 0, 255).astype(np.uint8)
    return mesh


def _mesh_colour(mesh: trimesh.Trimesh):
    try:
        c = np.asarray(mesh.visual.main_color, dtype=float) / 255.0
        return tuple(c)
    except Exception:  # noqa: BLE001 - a mesh without a material: the default grey
        return DEFAULT_COLOUR


def visual_parts(model, obj) -> list[Part]:
    """The visual of a body or ghost: its `shape` (or compound entries), else its visual mesh."""
    scale = obj.scale if obj.scale is not None else 1.0
    colour = rgba(obj)
    entries = []
    if obj.shape and obj.geometry is not None:
        entries = [(obj.shape, obj.geometry, None)]
    elif getattr(obj, "compound_shape", None):
        entries = [(e.shape, e.geometry, e.offset) for e in obj.compound_shape if e.geometry is not None]
    parts = []
    for shape, g, offset in entries:
        kind = shape_kind(shape)
        mesh = primitive(kind, g, scale) if kind is not None else None
        if mesh is not None and offset is not None:
            mesh.apply_transform(pose_to_matrix(offset))
        part = _part(mesh, colour or DEFAULT_COLOUR)
        if part is not None:
            parts.append(part)
    if entries:
        return parts
    path = visual_mesh_path(model, obj)
    mesh = _mesh_file(model, path, scale) if path is not None else None
    part = _part(mesh, colour or (_mesh_colour(mesh) if mesh is not None else DEFAULT_COLOUR))
    if part is not None:  # its file's texture, tinted by the ADF colour (AMBF's material modulates it)
        part.textured = _textured(model, path, scale, colour)
    return [part] if part is not None else []


def missing_textures(model, obj) -> tuple[str, ...]:
    """The textures an object's OBJ visual mesh names that are not there (drawn without them)."""
    from ..geometry.meshcheck import obj_material_problems

    if obj.shape or getattr(obj, "compound_shape", None):
        return ()
    path = visual_mesh_path(model, obj)
    if path is None or path.suffix.lower() != ".obj":
        return ()
    return tuple(w for w in obj_material_problems(str(path)) if w.startswith("texture "))


def collision_parts(model, obj, colour=(0.1, 0.9, 0.3, 0.35)) -> list[Part]:
    """The collision shape of a body or ghost, translucent: its primitives, else its collision mesh."""
    scale = obj.scale if obj.scale is not None else 1.0
    prims = collision_primitives(obj)
    parts = []
    if prims:
        for p in prims:
            mesh = primitive(p.kind, p.geometry, scale)
            if mesh is None:
                continue
            mesh.apply_transform(pose_to_matrix(p.pose))
            part = _part(mesh, colour)
            if part is not None:
                parts.append(part)
        return parts
    path = collision_mesh_path(model, obj)
    mesh = _mesh_file(model, path, scale) if path is not None else None
    part = _part(mesh, colour)
    return [part] if part is not None else []
