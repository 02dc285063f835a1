"""ADF volumes for the MJCF and URDF writers (mjcf_volumes.py, urdf_volumes.py): neither format
has a voxel volume, so each volume is written as its iso-surface
(:func:`adfkit.geometry.volume.iso_surface`, marching cubes at its ``iso-surface value``) in
binary STL files beside the output, a static mesh at the volume's location, in its colour. A
surface of more than 200,000 triangles (MuJoCo's STL reader refuses more) is cut into pieces
within that (``<stem>_<volume>_<k>.stl``; geometry.surface_parts). For MJCF the convex parts
the MuJoCo engine collides by come too (``parts``: the hull's vertices per block). The voxel
data itself is a ``Loss``, and so is a volume whose slices cannot be read (nothing is written
for it)."""

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
    paths: list[Path]  # the STL files written: the surface, or its pieces
    pose: Pose  # the volume's location (its frame in the model's world)
    rgba: tuple[float, float, float, float] | None
    parts: list  # (n, 3) hull vertices of each convex part (with_parts), else empty


def _safe(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_") or "volume"


def volume_meshes(
    model, out_dir: Path, stem: str, fmt: str, losses: list[Loss], with_parts: bool = False
) -> list[VolumeMesh]:
    """Write each volume's iso-surface as ``<stem>_<volume>.stl`` in ``out_dir`` (atomically),
    or as pieces ``<stem>_<volume>_<k>.stl`` of at most 200,000 triangles each."""
    import trimesh

    from ..adf.writer import atomic_write_bytes
    from ..geometry.surface_parts import MUJOCO_STL_MAX_FACES, convex_parts, hull_vertices, split_surface
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
            data = load_volume(model, vol)
            verts, faces = iso_surface(data, level)
        except AdfError as exc:
            losses.append(Loss(who, "volume", f"not written: {exc.diagnostics[0].message}"))
            continue
        if len(faces) == 0:
            losses.append(Loss(who, "volume", f"not written: no voxel reaches the iso-surface value {level}"))
            continue
        name = _safe(vol.name or who.removeprefix("VOLUME "))
        pieces = split_surface(verts, faces, len(verts), MUJOCO_STL_MAX_FACES)
        paths = []
        for k, (v, f) in enumerate(pieces):
            path = Path(out_dir) / (
                f"{_safe(stem)}_{name}.stl" if len(pieces) == 1 else f"{_safe(stem)}_{name}_{k}.stl"
            )
            atomic_write_bytes(path, trimesh.Trimesh(v, f, process=False).export(file_type="stl"))
            paths.append(path)
        parts = []
        if with_parts:
            parts = [hull_vertices(p) for p in convex_parts(verts, faces, data.voxels >= level, data.dimensions)]
        del data
        files = paths[0].name if len(paths) == 1 else f"{len(paths)} pieces, {paths[0].name} ..."
        losses.append(
            Loss(
                who,
                "voxel data",
                f"{fmt} has no voxel volume: written as its iso-surface at {level} ({files}); "
                "the slices, optical density, quality and shaders are not carried",
            )
        )
        out.append(VolumeMesh(vol, name, paths, pose_or_identity(vol.location), _material(vol), parts))
    return out


__all__ = ["VolumeMesh", "volume_meshes"]
