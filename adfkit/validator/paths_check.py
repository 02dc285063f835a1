"""Rules about files an ADF names: meshes (§6.2), their OBJ material libraries and textures,
shaders, skyboxes, sensor meshes, and the files launch, world and input-devices files chain to."""

from __future__ import annotations

import os
from functools import lru_cache
from pathlib import Path

import numpy as np

from .. import inputs
from ..adf.paths import collision_mesh_path, relative_to_file, shader_paths, uses_collision_mesh, visual_mesh_path
from ..diagnostics import AdfError, Diagnostic, SourceLocation
from ..geometry.meshcheck import mesh_problem, obj_faces_crash_ambf, obj_material_problems
from ..model import InputDevices, Launch, ModelFile, World
from ..model.objects import Body, Ghost, SoftBody
from ..model.semantics import SENSOR_TYPES, collision_primitives
from . import softbody_rules, volume_rules
from .rules import RULES

AMBF_MESH_SUFFIXES = (".obj", ".stl", ".3ds")  # what CHAI3D's cMultiMesh::loadFromFile reads for AMBF


def _d(rule: str, message: str, loc: SourceLocation | None, hint: str | None = None) -> Diagnostic:
    return Diagnostic(RULES[rule].severity, rule, message, loc, hint)


# a regular file is there (never raises: odd paths are simply not there); asked once per path
_exists = lru_cache(maxsize=4096)(inputs.is_regular)


def _present(path) -> bool:
    """Something is there (a device or a folder counts: the input policy then says what)."""
    try:
        return os.path.lexists(path)
    except (OSError, ValueError):
        return False


@lru_cache(maxsize=4096)
def _refusal(path: str, root: str | None, kind: str) -> tuple[str, str, str | None] | None:
    """(rule, message, hint) when the input policy refuses a file that is there, else None."""
    try:
        inputs.check_file(path, kind, tree=inputs.Tree(Path(root)) if root else None)
    except AdfError as exc:
        d = exc.diagnostics[0]
        return d.rule, d.message, d.hint
    return None


def _policy(path, doc, kind: str, loc, owner: str) -> Diagnostic | None:
    """The input policy's finding for a file ``doc`` names, located at the naming key."""
    tree = getattr(doc, "tree", None)
    found = _refusal(str(path), str(tree.root) if tree is not None else None, kind)
    if found is None:
        return None
    rule, message, hint = found
    return _d(rule, f"{owner}: {message}", loc, hint)


def _shaders(doc_path, shaders, owner: str, loc) -> list[Diagnostic]:
    return [
        _d(
            "missing-shader",
            f"shader {path} of {owner} not found",
            loc,
            "shader paths are relative to the file that declares them",
        )
        for path in shader_paths(doc_path, shaders)
        if not _exists(str(path))
    ]


#: m, the estimated centre of mass off the body frame below which AMBF's estimate is not worth a word
COM_ESTIMATE_NOTED = 1e-4


def _com_estimated(m: ModelFile, body: Body) -> list[Diagnostic]:
    """`inertial-offset-estimated`: AMBF puts the centre of mass of a mesh body without
    `inertial offset` (or without `mass`) at its estimate from the collision mesh, and builds
    the collision shape there, that far off the visual (geometry/chai3d_com.py)."""
    from ..geometry.chai3d_com import body_com

    est = body_com(m, body)
    if est is None or float(np.linalg.norm(est)) < COM_ESTIMATE_NOTED:
        return []
    path = collision_mesh_path(m, body)
    name = path.name if path is not None else "its collision mesh"
    mm = ", ".join(f"{1e3 * float(x):.1f}" for x in est)
    why = "no `mass`" if body.mass is None else "no `inertial offset`"
    return [
        _d(
            "inertial-offset-estimated",
            f"'{body.identifier}' has {why}: AMBF puts its centre of mass at ({mm}) mm in the body frame, "
            f"its estimate from {name}'s vertices, and builds its collision shape there, "
            f"{1e3 * float(np.linalg.norm(est)):.1f} mm off its visual mesh",
            body.where("mass") or body.source,
            "give the body `inertial offset` (and `mass`); `adfkit inertia MESH --mass M` computes one",
        )
    ]


def _empty_submeshes(m: ModelFile, body: Body) -> list[Diagnostic]:
    """`obj-empty-submesh`: AMBF 2.0 segfaults building a concave collision shape of an OBJ one
    of whose CHAI3D sub-meshes has no face (measured: static or moving; a hull or a convex mesh
    of it loads)."""
    from ..geometry.chai3d_com import empty_submeshes
    from ..model.semantics import CollisionMeshType, collision_mesh_type

    if collision_primitives(body) is not None or collision_mesh_type(body.collision_mesh_type)[0] is not (
        CollisionMeshType.CONCAVE_MESH
    ):
        return []
    path = collision_mesh_path(m, body)
    if path is None or not _present(path):
        return []
    found = empty_submeshes(path)
    if not found or not found[1]:
        return []
    meshes, empty = found
    key = "collision mesh" if body.collision_mesh is not None else "mesh"
    return [
        _d(
            "obj-empty-submesh",
            f"'{body.identifier}': AMBF 2.0 crashes building the concave collision shape of {path.name}: "
            f"its materials and objects make {meshes} sub-meshes, {empty} of them without a face",
            body.where(key) or body.source,
            "remove the materials no face uses from its .mtl (and objects without faces), or set "
            "`collision mesh type: CONVEX_HULL`",
        )
    ]


def _sensor_mesh(s) -> list[Diagnostic]:
    """`sensor-mesh`: AMBF 2.0 reads a found sensor mesh's rays (triangle centroids along their
    normals) but never sets the sensor's ray count (afRayTracerSensor::createFromAttribs sets it for
    an `array` or a `parametric` fan only): measured, a proximity sensor segfaults (exit -11) at its
    first update and a resistance sensor throws std::bad_alloc (exit -6) sizing its contacts. An
    `array` beside it wins in AMBF's loader; a type AMBF does not know is `sensor-type`'s."""
    if s.array is not None or SENSOR_TYPES.get(s.type or "") not in ("proximity", "resistance"):
        return []
    if Path(s.mesh).suffix.lower() not in AMBF_MESH_SUFFIXES:
        return []  # CHAI3D cannot read it: AMBF says so and skips the sensor
    return [
        _d(
            "sensor-mesh",
            f"'{s.identifier}': AMBF 2.0 crashes on a {SENSOR_TYPES[s.type]} sensor whose rays come from "
            f"mesh {s.mesh} (it never sets the sensor's ray count)",
            s.where("mesh"),
            "give the rays as an `array` (an offset and a direction each, in the sensor frame)",
        )
    ]


def model_paths(m: ModelFile) -> list[Diagnostic]:
    out: list[Diagnostic] = []
    objs: list[Body | SoftBody | Ghost] = [*m.bodies, *m.soft_bodies, *m.ghost_objects]
    for obj in objs:
        if not obj.defined:
            continue
        start = len(out)
        seen = set()
        checks = []
        if not obj.shape and not obj.compound_shape:
            checks.append(("mesh", visual_mesh_path(m, obj)))
        if uses_collision_mesh(obj):
            checks.append(("collision mesh" if obj.collision_mesh is not None else "mesh", collision_mesh_path(m, obj)))
        for key, path in checks:
            if path is None or str(path) in seen:
                continue
            seen.add(str(path))
            if path.suffix.lower() not in AMBF_MESH_SUFFIXES:
                out.append(
                    _d(
                        "mesh-format",
                        f"mesh {inputs.shown(path.name)} of '{obj.identifier}': AMBF loads OBJ, 3DS and STL "
                        f"meshes, not {path.suffix or 'files without a suffix'}",
                        obj.where(key),
                        "export the mesh as OBJ, STL or 3DS",
                    )
                )
            if not _present(path):
                out.append(
                    _d(
                        "missing-mesh",
                        f"mesh file {inputs.shown(path)} of '{obj.identifier}' not found",
                        obj.where(key),
                        "paths resolve against the body's and model's high/low resolution "
                        "paths, then the model file's directory",
                    )
                )
            elif (refused := _policy(path, m, "mesh", obj.where(key), f"mesh of '{obj.identifier}'")) is not None:
                out.append(refused)
            elif (problem := mesh_problem(path)) is not None:
                out.append(
                    _d(
                        "mesh-unreadable",
                        f"mesh {inputs.shown(path.name)} of '{obj.identifier}': {problem}",
                        obj.where(key),
                        "re-export the mesh as a triangle mesh (STL or OBJ)",
                    )
                )
            elif path.suffix.lower() == ".obj":
                if obj_faces_crash_ambf(str(path)):
                    out.append(
                        _d(
                            "obj-faces-crash-ambf",
                            f"mesh {path.name} of '{obj.identifier}' has faces written `f v/vt` (texture "
                            "coordinates without normals): AMBF 2.0's OBJ reader crashes on them",
                            obj.where(key),
                            "export the normals too (`f v/vt/vn`), or no texture coordinates",
                        )
                    )
                for what in obj_material_problems(str(path)):
                    out.append(
                        _d(
                            "missing-texture",
                            f"{what} of mesh {path.name} ('{obj.identifier}') not found",
                            obj.where(key),
                            "textures come from the mesh's own material (MTL) file",
                        )
                    )
        # a mesh found missing, refused or unreadable above is not read again (a missing texture is fine)
        if isinstance(obj, Body) and all(d.rule == "missing-texture" for d in out[start:]):
            out += _com_estimated(m, obj) + _empty_submeshes(m, obj)
        out += _shaders(m.path, getattr(obj, "shaders", None), f"'{obj.identifier}'", obj.where("shaders"))
    for s in m.sensors:
        if s.mesh and not _exists(str(m.directory / s.mesh)):
            out.append(
                _d(
                    "missing-mesh",
                    f"sensor mesh {m.directory / s.mesh} of '{s.identifier}' not found",
                    s.where("mesh"),
                    "sensor meshes resolve against the model directory only",
                )
            )
        elif s.mesh:
            out += _sensor_mesh(s)
    for v in m.volumes:
        out += _shaders(m.path, v.shaders, f"'{v.identifier}'", v.where("shaders"))
    for c in m.cameras:
        out += _camera_shaders(m.path, c)
    out += _shaders(m.path, m.shaders, "the model", m.where("shaders"))
    return out


def _camera_shaders(path, c) -> list[Diagnostic]:
    return _shaders(
        path, c.preprocessing_shaders, f"camera '{c.identifier}'", c.where("preprocessing shaders")
    ) + _shaders(path, c.depth_compute_shaders, f"camera '{c.identifier}'", c.where("depth compute shaders"))


def world_paths(w: World) -> list[Diagnostic]:
    out: list[Diagnostic] = []
    if w.environment and not _present(relative_to_file(w.path, w.environment)):
        out.append(
            _d(
                "missing-file",
                f"environment {relative_to_file(w.path, w.environment)} not found",
                w.where("environment"),
                "the environment path is relative to the world file",
            )
        )
    out += _shaders(w.path, w.shaders, "the world", w.where("shaders"))
    if w.skybox is not None and w.skybox.path:
        base = relative_to_file(w.path, w.skybox.path)
        for face in ("right", "left", "top", "bottom", "front", "back"):
            name = getattr(w.skybox, face)
            if name and not _exists(str(base / name)):
                out.append(_d("missing-shader", f"skybox {face} image {base / name} not found", w.skybox.where(face)))
        out += _shaders(w.path, w.skybox.shaders, "the skybox", w.skybox.where("shaders"))
    for c in w.cameras:
        out += _camera_shaders(w.path, c)
    return out


def launch_targets(launch: Launch) -> dict[str, list[Path]]:
    """Files a launch file chains to, by slot (only slots that are set)."""
    out: dict[str, list[Path]] = {}
    for key, attr in (
        ("world config", "world_config"),
        ("color config", "color_config"),
        ("input devices config", "input_devices_config"),
    ):
        value = getattr(launch, attr)
        if value:
            out[key] = [relative_to_file(launch.path, value)]
    out["multibody configs"] = [relative_to_file(launch.path, p) for p in launch.multibody_configs or []]
    return out


def launch_paths(launch: Launch) -> list[Diagnostic]:
    """Files a launch file names that are not there. A path that is there but refused by the
    input policy (a device, a file outside the scene's tree) is reported by the validator
    when it follows the launch file (adfkit.validator.engine)."""
    out = []
    for key, paths in launch_targets(launch).items():
        for p in paths:
            if _present(p):
                continue
            rule = {"multibody configs": "missing-model-file", "color config": "missing-color-file"}.get(
                key, "missing-file"
            )
            out.append(
                _d(
                    rule,
                    f"'{key}' names {inputs.shown(p)}, which does not exist",
                    launch.where(key),
                    "AMBF 2.0 stores this path and never opens it"
                    if key == "color config"
                    else "paths in a launch file are relative to the launch file's directory",
                )
            )
    return out


def input_device_paths(d: InputDevices) -> list[Diagnostic]:
    out = []
    for dev in d.input_devices:
        if dev.simulated_multibody and not _exists(str(relative_to_file(d.path, dev.simulated_multibody))):
            out.append(
                _d(
                    "input-device",
                    f"simulated multibody {relative_to_file(d.path, dev.simulated_multibody)} "
                    f"of '{dev.identifier}' not found; the device loads without it",
                    dev.where("simulated multibody"),
                    "the path is relative to the input-devices file",
                )
            )
    return out


def plugin_paths(doc) -> list[Diagnostic]:
    """Plugins with a `path`: AMBF tries path/filename first, then its plugin path list and
    the bare name, so only a `path` that lacks the library is reported."""
    out = []
    owners = [doc] + (doc.all_objects() if isinstance(doc, ModelFile) else [])
    for owner in owners:
        for plugin in getattr(owner, "plugins", None) or []:
            if plugin.path and plugin.filename:
                lib = relative_to_file(doc.path, plugin.path) / plugin.filename
                if not _exists(str(lib)):
                    out.append(
                        _d(
                            "missing-plugin",
                            f"plugin library {lib} not found",
                            owner.where("plugins"),
                            "plugin paths are relative to the declaring file; AMBF then tries its plugin "
                            "path list and the bare file name",
                        )
                    )
    return out


def check(doc) -> list[Diagnostic]:
    out = plugin_paths(doc) if hasattr(doc, "plugins") else []
    if isinstance(doc, ModelFile):
        return out + model_paths(doc) + softbody_rules.mesh_rules(doc) + volume_rules.check(doc)
    if isinstance(doc, World):
        return out + world_paths(doc)
    if isinstance(doc, Launch):
        return out + launch_paths(doc)
    if isinstance(doc, InputDevices):
        return out + input_device_paths(doc)
    return out
