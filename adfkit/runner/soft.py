"""Soft bodies, the same way for every engine: which models have one, which joints join one to
a rigid body and which of its nodes such a joint holds, and what the report says of each
(pybullet/softbodies.py and mujoco/soft.py build them in their engine; docs/soft-bodies.md)."""

from __future__ import annotations

import numpy as np

from ..model.semantics import pose_or_identity
from .names import merge_namespace
from .rotations import pose_to_matrix

EXPLODED_STRETCH = 3.0  # a soft body wider than this many times its rest size has exploded
DEFAULT_MARGIN = 0.001  # adf-format.md §7.4


def in_scene(scene) -> bool:
    """True when some model defines a soft body."""
    return any(sb.defined for m in scene.all_models() for sb in m.soft_bodies)


def _refers(ref: str | None, ns: str, sb) -> bool:
    if not ref:
        return False
    # exact only: AMBF's substring lookup (§12) searches rigid bodies, and a rigid body whose
    # name is part of a soft body's key must stay the rigid body
    return ref in (sb.identifier, merge_namespace(ns, sb.namespace) + sb.identifier)


def soft_end(m, j) -> tuple[object | None, str | None]:
    """(soft body, 'parent' | 'child') when joint ``j`` of model ``m`` names one of its soft bodies."""
    ns = m.namespace or ""
    for sb in m.soft_bodies:
        if _refers(j.child, ns, sb):
            return sb, "child"
        if _refers(j.parent, ns, sb):
            return sb, "parent"
    return None, None


def held_nodes(soft, joint, end: str, nodes: np.ndarray) -> np.ndarray:
    """The nodes a joint between ``soft`` (its ``end``) and a rigid body holds: those within the
    collision margin (at least 1 mm) of the joint's pivot on the soft body, else the nearest
    (adfkit's extension: AMBF finds no soft body by name in a joint)."""
    pivot = joint.child_pivot if end == "child" else joint.parent_pivot
    local = np.array([*pivot]) * (soft.scale or 1.0) if pivot is not None else np.zeros(3)
    pose = pose_to_matrix(pose_or_identity(soft.location))
    at = pose[:3, :3] @ local + pose[:3, 3]
    d = np.linalg.norm(nodes - at, axis=1)
    margin = soft.collision_margin if soft.collision_margin is not None else DEFAULT_MARGIN
    chosen = np.flatnonzero(d <= max(margin, 1e-3))
    return chosen if len(chosen) else np.array([int(np.argmin(d))])


def soft_report(items, floor_z: float, extra=lambda s: {}) -> tuple[list[dict], list[str], list[str], list[str]]:
    """(per-soft-body entries, nan keys, exploded keys, fell-through-floor keys) of the engine's
    soft bodies (each with ``key``, ``node_count``, ``triangles``, ``fixed``, ``attached``,
    ``rest_size``, ``unmapped`` and ``nodes()``); ``extra(item)`` adds the engine's own fields."""
    rows, nan, exploded, fell = [], [], [], []
    for s in items:
        p = s.nodes()
        finite = bool(np.all(np.isfinite(p)))
        size = float(np.linalg.norm(p.max(axis=0) - p.min(axis=0))) if finite else None
        rows.append(
            {
                "name": s.key,
                "nodes": s.node_count,
                "triangles": s.triangles,
                "fixed_nodes": len(s.fixed),
                "attached_nodes": {k: len(v) for k, v in s.attached.items()},
                "lowest_z": float(p[:, 2].min()) if finite else None,
                "size_m": size,
                "rest_size_m": s.rest_size,
                **extra(s),
                "not_played": s.unmapped,
            }
        )
        if not finite:
            nan.append(s.key)
        elif size > EXPLODED_STRETCH * max(s.rest_size, 1e-6):
            exploded.append(s.key)
        elif p[:, 2].min() < floor_z - 0.1:
            fell.append(s.key)
    return rows, nan, exploded, fell


def soft_health(soft, floor_z: float, rep: dict) -> dict:
    """The report's ``soft_bodies`` and its health lists with the soft bodies' added (``soft``:
    the world's soft bodies, or None)."""
    rows, nan, exploded, fell = soft.report(floor_z) if soft is not None else ([], [], [], [])
    return {
        "soft_bodies": rows,
        "nan": rep["nan"] + nan,
        "exploded": rep["exploded"] + exploded,
        "fell_through_floor": rep["fell_through_floor"] + fell,
    }


__all__ = ["EXPLODED_STRETCH", "held_nodes", "in_scene", "soft_end", "soft_health", "soft_report"]
