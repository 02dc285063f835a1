"""Load what a launch file selects: the world, its environment and the chosen model files,
like AMBF's ``--launch_file ... -l 6,7,8``."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import cast

from ..diagnostics import AdfError, Diagnostic, SourceLocation, error, warning
from ..model import Launch, ModelFile, Scene, World
from .paths import relative_to_file
from .yamlcompat import read_as_ambf


def read_file(path, kind: str | None = None, *, tree=None, referrer=None):
    """A file read as AMBF reads it (yaml-cpp's layouts too, adf.yamlcompat): (doc, diagnostics)."""
    doc, diags, _text, _moved = read_as_ambf(path, kind, tree=tree, referrer=referrer)
    return doc, diags


def parse_indices(text: str | None) -> list[int] | None:
    """`6,7,8` or `6-11` or `6-8,10` → [6, 7, 8, ...]."""
    if text is None or text == "":
        return None
    out: list[int] = []
    for part in text.split(","):
        part = part.strip()
        if not part:
            continue
        try:
            if "-" in part:
                lo, hi = part.split("-", 1)
                out.extend(range(int(lo), int(hi) + 1))
            else:
                out.append(int(part))
        except ValueError:
            raise AdfError(
                error("bad-index", f"'{part}' is not an index or a range", None, "write indices like 6,7,8 or 6-11")
            ) from None
    return out


def load_scene(
    path: str | Path, indices: Iterable[int] | None = None, diagnostics: list[Diagnostic] | None = None
) -> Scene:
    """Load a launch file (with `multibody configs` picked by 0-based ``indices``; all when
    None), a world file (with its environment) or a single model file as a scene."""
    diags = diagnostics if diagnostics is not None else []
    doc, found = read_file(path)
    diags.extend(found)
    scene = Scene()
    if isinstance(doc, ModelFile):
        scene.models.append(doc)
        return scene
    if isinstance(doc, World):
        _attach_world(scene, doc, diags)
        return scene
    if not isinstance(doc, Launch):
        raise AdfError(
            error(
                "wrong-kind",
                f"{path} is a {type(doc).__name__} file; a scene starts from a launch, world or model file",
                SourceLocation(str(path)),
            )
        )
    scene.launch = doc
    if doc.world_config:
        world, found = read_file(
            relative_to_file(doc.path, doc.world_config), "world", tree=doc.tree, referrer=doc.where("world config")
        )
        diags.extend(found)
        _attach_world(scene, cast(World, world), diags)
    configs = doc.multibody_configs or []
    chosen = range(len(configs)) if indices is None else list(indices)
    for i in chosen:
        if not 0 <= i < len(configs):
            raise AdfError(
                error(
                    "bad-index",
                    f"index {i} is out of range: the launch file lists "
                    f"{len(configs)} model files (0–{len(configs) - 1})",
                    doc.where("multibody configs"),
                    "pick indices from the multibody configs list",
                )
            )
        path = relative_to_file(doc.path, configs[i])
        try:
            model, found = read_file(path, "model", tree=doc.tree, referrer=doc.where("multibody configs"))
        except AdfError as exc:
            if exc.diagnostics[0].rule != "file-not-found":
                raise
            # AMBF says it failed to load the file and loads the others (measured)
            diags.append(
                warning(
                    "missing-model-file",
                    f"{exc.diagnostics[0].message}; the launch file's other models are loaded, as AMBF does",
                    doc.where("multibody configs"),
                    "paths in a launch file are relative to the launch file's directory",
                )
            )
            continue
        diags.extend(found)
        scene.models.append(cast(ModelFile, model))
    return scene


def _attach_world(scene: Scene, world: World, diags: list[Diagnostic]) -> None:
    scene.world = world
    if world.environment:
        env_path = relative_to_file(world.path, world.environment)
        env, found = read_file(env_path, "model", tree=world.tree, referrer=world.where("environment"))
        diags.extend(found)
        scene.environment = cast(ModelFile, env)
