"""Where AMBF looks for the files an ADF names (adf-format.md §6.2, §1.1, §3, §4)."""

from __future__ import annotations

from pathlib import Path

from ..model import ModelFile
from ..model.objects import Body, Ghost, SoftBody


def _join(base: str | None, name: str) -> str:
    if not base:
        return name
    return str(Path(base) / name)


def _anchor(model: ModelFile, model_dir_path: str | None, p: str) -> Path:
    if not Path(p).is_absolute():
        p = _join(model_dir_path, p)
    path = Path(p)
    if not path.is_absolute():
        path = model.directory / path
    return path


def visual_mesh_path(model: ModelFile, obj: Body | SoftBody | Ghost) -> Path | None:
    """The visual mesh file, or None when the object names none (`mesh: ''` or no key)."""
    if not obj.mesh:
        return None
    return _anchor(model, model.high_resolution_path, _join(obj.high_resolution_path, obj.mesh))


def collision_mesh_path(model: ModelFile, obj: Body | SoftBody | Ghost) -> Path | None:
    """The collision mesh file: `collision mesh` (or the visual file name) in the low-res dirs."""
    name = obj.collision_mesh if obj.collision_mesh is not None else obj.mesh
    if not name:
        return None
    base = obj.low_resolution_path or obj.high_resolution_path
    return _anchor(model, model.low_resolution_path, _join(base, name))


def relative_to_file(doc_path: Path | None, p: str) -> Path:
    """A path written in a file, resolved against that file's directory (absolute kept)."""
    path = Path(p)
    if path.is_absolute() or doc_path is None:
        return path
    return doc_path.parent / path


def shader_paths(doc_path: Path | None, shaders) -> list[Path]:
    if shaders is None or shaders.path is None:
        return []
    base = relative_to_file(doc_path, shaders.path)
    return [base / f for f in (shaders.vertex, shaders.fragment) if f]


def uses_collision_mesh(obj) -> bool:
    """True when collision comes from a mesh file (no primitive or compound takes precedence)."""
    return not obj.collision_shape and not obj.compound_collision_shape
