"""The MjSpec compiled, with MuJoCo's errors turned into located diagnostics, and the meshes the
MJCF writer referenced resolved to files MuJoCo reads."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from ...diagnostics import AdfError, SourceLocation, error


def _resolve_meshes(world, child, out_dir: Path, model) -> None:
    """Absolute mesh paths; a mesh file that is not there drops its geoms, with a warning."""
    missing, missing_paths = {}, {}
    for mesh in list(child.meshes):
        if not mesh.file:  # vertices written inline (a cone's hull)
            continue
        path = (out_dir / mesh.file).resolve()
        if path.is_file():
            mesh.file = str(path)
            # inertials are explicit; shell inertia lets flat meshes (a floor, a backdrop) compile
            mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
        else:
            missing[mesh.name] = mesh
            missing_paths[mesh.name] = path
    if not missing:
        return
    for g in list(child.geoms):
        if g.meshname in missing:
            child.delete(g)
    for name, mesh in missing.items():
        world._warn(
            "runner-mesh", f"{model.name}: mesh file {missing_paths[name]} not found; its shapes are left out", model
        )
        child.delete(mesh)


def compile_spec(world, spec):
    """spec.compile(), replacing a collision mesh MuJoCo cannot hull (flat: coplanar vertices)
    by a box around its vertices (at least 1 mm thick), with a warning."""
    import re

    for _ in range(100):
        try:
            return spec.compile()
        except ValueError as e:
            hit = re.search(r"mesh '([^']+)' has coplanar vertices", str(e))
            if hit is None:
                raise
            mesh = spec.mesh(hit.group(1))
            lo, hi = _obj_bounds(Path(mesh.file), np.array(mesh.scale, float))
            for g in list(spec.geoms):
                if g.meshname != mesh.name:
                    continue
                body = g.parent
                box = body.add_geom(
                    type=mujoco.mjtGeom.mjGEOM_BOX,
                    size=np.maximum((hi - lo) / 2, 5e-4),
                    contype=g.contype,
                    conaffinity=g.conaffinity,
                    group=g.group,
                    friction=g.friction,
                    rgba=g.rgba,
                    name=(g.name or "") + "#box",
                )
                r = _quat_matrix(np.array(g.quat, float))
                box.pos = np.array(g.pos, float) + r @ ((lo + hi) / 2)
                box.quat = g.quat
                spec.delete(g)
            world._warn(
                "runner-flat-mesh",
                f"{Path(mesh.file).name}: a flat mesh has no convex hull for MuJoCo; it collides as its bounding box",
                None,
            )
            spec.delete(mesh)
    return spec.compile()


def _obj_bounds(path: Path, scale: np.ndarray):
    vs = []
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            if line.startswith("v "):
                vs.append([float(x) for x in line.split()[1:4]])
    v = np.array(vs) * scale if vs else np.zeros((1, 3))
    return v.min(axis=0), v.max(axis=0)


def _quat_matrix(q: np.ndarray) -> np.ndarray:
    from ..rotations import quat_to_matrix

    return quat_to_matrix(np.array([q[1], q[2], q[3], q[0]]))


def _parse_spec(text: str, model) -> mujoco.MjSpec:
    """MuJoCo's spec of one model's MJCF. MuJoCo parses MJCF with tinyxml2, which stops at 500
    nested elements: a chain of about 500 bodies joined by revolute or prismatic joints (each
    a <body> inside its parent's) cannot be loaded; that is a located error, not a traceback."""
    try:
        return mujoco.MjSpec.from_string(text)
    except ValueError as exc:
        if "DEPTH" not in str(exc).upper():
            raise
        where = model.source or SourceLocation(str(model.path) if model.path else "<model>", 1, 1)
        raise AdfError(
            error(
                "mujoco-tree-too-deep",
                "MuJoCo cannot load this model: its kinematic tree nests bodies deeper than "
                "MuJoCo's MJCF parser allows (about 500 levels)",
                where,
                "play it with --engine pybullet, or split the chain with p2p joints",
            )
        ) from None
