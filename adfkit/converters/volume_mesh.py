"""ADF volumes for the MJCF and URDF writers (mjcf_volumes.py, urdf_volumes.py): neither format has a voxel volume, so each volume
is written as its iso-surface (:func:`adfkit.geometry.volume.iso_surface`, marching cubes at
its ``iso-surface value``) in a binary STL file beside the output, drawn and colliding as a
static mesh at the volume's location, in its colour. The voxel data itself is a ``Loss``, and
so is a volume whose slices cannot be read (nothing is written for it)."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from ..diagnostics import AdfError
from ..model.pose import Pose
from .losses import Loss


@dataclass
class VolumeMesh:
    volume: object  # the ADF Volume
    name: str  # a file- and XML-safe name
    path: Path  # the STL written
    pose: Pose  # the volume's location (its frame in the model's world)
    rgba: tuple[float, float, float, float] | None


def _safe(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_") or "volume"


def volume_meshes(model, out_dir: Path, stem: str, fmt: str, losses: list[Loss]) -> list[VolumeMesh]:
    """Write each volume's iso-surface as ``<stem>_<volume>.stl`` in ``out_dir`` (atomically)."""
    import trimesh

    from ..adf.writer import atomic_write_bytes
    from ..geometry.volume import DEFAULT_ISO, iso_surface, load_volume
    from ..model.semantics import pose_or_identity
    from .urdf_xml import _material

    out = []
    for vol in model.volumes:
        if not vol.defined:
            continue
        who = vol.identifier
        level = vol.iso_surface_value if vol.iso_surface_value is not None else DEFAULT_ISO
        try:
            verts, faces = iso_surface(load_volume(model, vol), level)
        except AdfError as exc:
            losses.append(Loss(who, "volume", f"not written: {exc.diagnostics[0].message}"))
            continue
        if len(faces) == 0:
            losses.append(Loss(who, "volume", f"not written: no voxel reaches the iso-surface value {level}"))
            continue
        name = _safe(vol.name or who.removeprefix("VOLUME "))
        path = Path(out_dir) / f"{_safe(stem)}_{name}.stl"
        atomic_write_bytes(path, trimesh.Trimesh(verts, faces, process=False).export(file_type="stl"))
        losses.append(
            Loss(
                who,
                "voxel data",
                f"{fmt} has no voxel volume: written as its iso-surface at {level} ({path.name}); "
                "the slices, optical density, quality and shaders are not carried",
            )
        )
        out.append(VolumeMesh(vol, name, path, pose_or_identity(vol.location), _material(vol)))
    return out


__all__ = ["VolumeMesh", "volume_meshes"]
