"""Counts that describe a launch, world or model file (what `adfkit info` prints)."""

from __future__ import annotations

import os
from collections import Counter
from pathlib import Path
from typing import Any

from . import inputs
from .adf.paths import collision_mesh_path, relative_to_file, uses_collision_mesh, visual_mesh_path
from .model import InputDevices, Launch, ModelFile, Scene, World
from .model.semantics import effective_mass, joint_kind


def model_summary(model: ModelFile) -> dict[str, Any]:
    joints = Counter()
    for j in model.joints:
        k = joint_kind(j.type)
        joints[k.value if k else f"unknown:{j.type}"] += 1
    meshes: set[Path] = set()
    for obj in [*model.bodies, *model.soft_bodies, *model.ghost_objects]:
        v = visual_mesh_path(model, obj)
        if v is not None and not obj.shape:
            meshes.add(v)
        if uses_collision_mesh(obj):
            c = collision_mesh_path(model, obj)
            if c is not None:
                meshes.add(c)
    missing = sorted(str(p) for p in meshes if not os.path.lexists(p))  # lexists: never raises on odd names
    dynamic = [b for b in model.bodies if effective_mass(b) > 0]
    return {
        "kind": "model",
        "file": str(model.path) if model.path else None,
        "bodies": len(model.bodies),
        "static bodies": len(model.bodies) - len(dynamic),
        "soft bodies": len(model.soft_bodies),
        "ghost objects": len(model.ghost_objects),
        "joints": len(model.joints),
        "joints by type": dict(sorted(joints.items())),
        "sensors": len(model.sensors),
        "actuators": len(model.actuators),
        "cameras": len(model.cameras),
        "lights": len(model.lights),
        "vehicles": len(model.vehicles),
        "volumes": _volumes(model),
        "meshes": len(meshes),
        "missing meshes": missing,
        # soft bodies weigh too (AMBF reads their mass with the same 1 kg default)
        "total mass": round(sum(effective_mass(b) for b in [*model.bodies, *model.soft_bodies]), 9),
    }


def _volumes(model: ModelFile) -> list[dict[str, Any]]:
    """Each volume's name, voxels, slices found, count and size (geometry.volume.volume_facts)."""
    defined = [v for v in model.volumes if v.defined]
    if not defined:
        return []
    try:
        from .geometry.volume import volume_facts  # numpy and Pillow: only for a file with volumes
    except ImportError:
        return [{"name": v.name or v.identifier} for v in defined]
    return [volume_facts(model, v) for v in defined]


def world_summary(world: World, environment: ModelFile | None = None) -> dict[str, Any]:
    g = world.gravity
    return {
        "kind": "world",
        "file": str(world.path) if world.path else None,
        "gravity": list(g) if g else None,
        "environment": str(relative_to_file(world.path, world.environment)) if world.environment else None,
        "lights": len(world.lights),
        "cameras": len(world.cameras),
        "environment summary": model_summary(environment) if environment else None,
    }


def _config_exists(launch: Launch, named: str) -> bool:
    """Whether a multibody config exists; a name the file system cannot look up (over-long, a
    NUL byte) is a located ``bad-path`` error, as everywhere else."""
    path = relative_to_file(launch.path, named)
    inputs.check_path_text(path, launch.where("multibody configs") or launch.source)
    return os.path.exists(path)


def launch_summary(launch: Launch) -> dict[str, Any]:
    configs = launch.multibody_configs or []
    return {
        "kind": "launch",
        "file": str(launch.path) if launch.path else None,
        "world config": launch.world_config,
        "input devices config": launch.input_devices_config,
        "multibody configs": [
            {"index": i, "path": p, "exists": _config_exists(launch, p)} for i, p in enumerate(configs)
        ],
    }


def input_devices_summary(devs: InputDevices) -> dict[str, Any]:
    return {
        "kind": "input_devices",
        "file": str(devs.path) if devs.path else None,
        "devices": [
            {"name": d.identifier, "hardware": d.hardware_name, "root link": d.root_link} for d in devs.input_devices
        ],
    }


def scene_summary(scene: Scene) -> dict[str, Any]:
    models = [model_summary(m) for m in scene.models]
    totals = Counter()
    for m in models:
        for k in ("bodies", "joints", "ghost objects", "sensors", "actuators", "cameras", "lights", "soft bodies"):
            totals[k] += m[k]
    return {
        "kind": "scene",
        "launch": launch_summary(scene.launch) if scene.launch else None,
        "world": world_summary(scene.world, scene.environment) if scene.world else None,
        "models": models,
        "totals": dict(totals),
        "total mass": round(sum(m["total mass"] for m in models), 9),
    }


def summarize(doc) -> dict[str, Any]:
    if isinstance(doc, ModelFile):
        return model_summary(doc)
    if isinstance(doc, World):
        return world_summary(doc)
    if isinstance(doc, Launch):
        return launch_summary(doc)
    if isinstance(doc, InputDevices):
        return input_devices_summary(doc)
    if isinstance(doc, Scene):
        return scene_summary(doc)
    return {"kind": type(doc).__name__.lower(), "file": str(doc.path) if doc.path else None}


def format_summary(s: dict[str, Any], indent: str = "") -> str:
    lines = []
    for k, v in s.items():
        if v is None or v == [] or v == {}:
            continue
        if isinstance(v, dict):
            lines.append(f"{indent}{k}:")
            lines.append(format_summary(v, indent + "  "))
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            lines.append(f"{indent}{k}:")
            for item in v:
                lines.append(
                    f"{indent}  - " + ", ".join(f"{a}: {b}" for a, b in item.items() if not isinstance(b, (dict, list)))
                )
        elif isinstance(v, list):
            lines.append(f"{indent}{k}: " + ", ".join(map(str, v)))
        else:
            lines.append(f"{indent}{k}: {v}")
    return "\n".join(line for line in lines if line)
