"""The MjSpec compiled, with MuJoCo's errors turned into located diagnostics, and the meshes the
MJCF writer referenced resolved to files MuJoCo reads."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import mujoco
import numpy as np

from ...diagnostics import AdfError, SourceLocation, error, warning


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
    by a box around its vertices (at least 1 mm thick), and leaving out a mesh MuJoCo cannot
    read, each with a located warning; anything else MuJoCo refuses is a located error."""
    for _ in range(100):
        try:
            return _compile_noting_warnings(world, spec)
        except ValueError as e:
            text = str(e)
            hit = re.search(r"mesh '([^']+)' has coplanar vertices", text)
            if hit is not None:
                _flat_to_box(world, spec, spec.mesh(hit.group(1)))
                continue
            mesh = _named_mesh(spec, text)
            if mesh is None:
                raise AdfError(
                    error(
                        "mujoco-refused",
                        f"MuJoCo cannot build the scene: {_first_line(text)}",
                        _where(world, spec, text),
                        "play it with --engine pybullet",
                    )
                ) from None
            _drop_mesh(world, spec, mesh, text)
    return _compile_noting_warnings(world, spec)


def _compile_noting_warnings(world, spec):
    """spec.compile(), its warnings (a mesh's texture coordinates discarded, ...) kept for the
    report's ``engine_warnings`` instead of printed as Python warnings with a line of code."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = spec.compile()
    notes = getattr(world, "engine_warnings", None)
    for w in caught:
        if notes is not None:
            notes.append(f"compile: {w.message}")
    return model


def _first_line(text: str) -> str:
    return text.removeprefix("Error: ").splitlines()[0] if text else "no reason given"


def _named_mesh(spec, text: str):
    """The mesh asset MuJoCo's error names (its element, or its file), or None."""
    hit = re.search(r"Element name '([^']*)'", text)
    if hit is not None and (mesh := spec.mesh(hit.group(1))) is not None:
        return mesh
    hit = re.search(r"file '([^']+)'", text)
    if hit is not None:
        return next((m for m in spec.meshes if m.file and Path(m.file) == Path(hit.group(1))), None)
    return None


def _adf_bodies(world, spec, geoms) -> list:
    """The ADF bodies (the plan's) whose MJCF bodies hold ``geoms``."""
    plan = getattr(world, "_plan", None)
    names = {g.parent.name for g in geoms}
    return [bp.body for bp in (plan.bodies if plan is not None else []) if bp.mjname in names]


def _where(world, spec, text: str):
    """Where the element MuJoCo's error names comes from: its ADF body, else the scene's first model."""
    hit = re.search(r"Element name '([^']*)'", text)
    name = hit.group(1) if hit is not None else ""
    el = spec.body(name) if name else None
    geom = spec.geom(name) if name and el is None else None
    if geom is not None:  # a geom MuJoCo refuses (a primitive of size 0): its body's shape
        bodies = _adf_bodies(world, spec, [geom])
        if bodies:
            b = bodies[0]
            for key in ("collision geometry", "compound collision shape", "collision mesh", "mesh"):
                if getattr(b, key.replace(" ", "_"), None) is not None:
                    return b.where(key) or b.source
            return b.source
    bodies = _adf_bodies(world, spec, [g for g in spec.geoms if el is not None and g.parent.name == el.name])
    if bodies:
        return bodies[0].source
    models = list(world.scene.all_models())
    return models[0].source if models else None


def _drop_mesh(world, spec, mesh, text: str) -> None:
    """A mesh MuJoCo cannot read (an STL its decoder refuses, ...): its geoms are left out, each
    body's warned about at its mesh key and listed in ``not_played``."""
    geoms = [g for g in spec.geoms if g.meshname == mesh.name]
    why = f"MuJoCo cannot read {Path(mesh.file).name if mesh.file else mesh.name}: {_first_line(text)}"
    bodies = _adf_bodies(world, spec, geoms)
    for b in bodies:
        key = "collision mesh" if getattr(b, "collision_mesh", None) is not None else "mesh"
        world.diagnostics.append(
            warning("runner-mesh-refused", f"{b.identifier}: {why}; its shapes from it are left out", b.where(key))
        )
        world.not_played.append({"object": b.identifier, "what": "mesh", "why": why})
    if not bodies:
        world._warn("runner-mesh-refused", f"{why}; its shapes are left out", None)
    for g in geoms:
        spec.delete(g)
    spec.delete(mesh)


def _flat_to_box(world, spec, mesh) -> None:
    lo, hi = _obj_bounds(Path(mesh.file), np.array(mesh.scale, float))
    bodies = _adf_bodies(world, spec, [g for g in spec.geoms if g.meshname == mesh.name])
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
        bodies[0] if bodies else None,
    )
    spec.delete(mesh)


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
