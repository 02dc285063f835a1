"""ADF volumes as either engine plays them, decided once here: each volume's iso-surface
(:mod:`adfkit.geometry.volume`, marching cubes) as a static body at the volume's location, in
its colour, with a label of its own in the segmentation. A volume with a ``parent`` (a body,
or a camera: runner.frames, as AMBF follows it) is placed in the frame of the body at the root
of its parents. The back ends only turn a :class:`VolumeSurface` into their engine's mesh body.

What of a volume is not played is listed in ``world.not_played``, never dropped: its
``shaders`` (the runner draws the iso-surface, not AMBF's ray-marched volume), a volume whose
slices cannot be read or whose iso-surface is empty (the reason, located)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..diagnostics import AdfError, Severity
from ..model import Body
from ..model.semantics import pose_or_identity
from .names import merge_namespace
from .plan import rgba
from .rotations import pose_to_matrix

BONE = [0.93, 0.89, 0.78, 1.0]


@dataclass
class VolumeSurface:
    key: str  # namespace + identifier, as every engine keys it
    volume: object  # the ADF Volume
    model: object  # its ModelFile
    body: Body  # a static stand-in body (mass 0, the volume's location) for the world's tables
    parent: object  # the engine's body at the root of the volume's parents, or None (the world)
    location: np.ndarray  # 4x4 volume frame in the parent's ADF body frame (or the world)
    dimensions: np.ndarray  # (3,) metres: the voxel box
    vertices: np.ndarray  # (n, 3) float32, metres in the volume's frame
    faces: np.ndarray  # (m, 3) uint32
    rgba: tuple  # colour
    report: dict  # the report.json entry
    solid: np.ndarray | None = None  # (slices, rows, columns) bool: voxels at or above the level

    def convex_parts(self) -> list[np.ndarray]:
        """Point sets whose convex hulls cover the surface and the solid behind it, one per block
        the surface crosses (geometry.surface_parts): what MuJoCo collides by."""
        from ..geometry.surface_parts import convex_parts

        assert self.solid is not None
        parts = convex_parts(self.vertices, self.faces, self.solid, self.dimensions)
        self.solid = None  # read once
        return parts

    @property
    def surface(self) -> tuple:
        """What a viewer draws of it (its own frame)."""
        return (self.vertices, self.faces, self.rgba)


def not_played_parts(vol) -> list[dict]:
    out = []
    if vol.shaders is not None:
        out.append(
            {
                "object": vol.identifier,
                "what": "shaders",
                "why": "the runner draws the iso-surface as a mesh, not AMBF's ray-marched volume",
            }
        )
    return out


def volume_surfaces(world, models, body_type=None) -> list[VolumeSurface]:
    """Every defined volume of ``models`` that can be played, as its iso-surface, its parent
    resolved among the engine's bodies of ``body_type``; the others are warned about
    (``runner-volume``) and listed in ``world.not_played``."""
    from ..geometry.volume import DEFAULT_ISO, iso_surface, load_volume
    from .frames import resolve_frame

    out = []
    for m in models:
        ns = m.namespace or ""
        for vol in m.volumes:
            if not vol.defined:
                continue
            level = vol.iso_surface_value if vol.iso_surface_value is not None else DEFAULT_ISO
            try:
                data = load_volume(m, vol)
                verts, faces = iso_surface(data, level)
            except AdfError as exc:
                for d in exc.diagnostics:
                    world._warn(
                        "runner-volume", f"{d.message}; the volume is not played", vol, d.hint or "fix the slices"
                    )
                world.not_played.append({"object": vol.identifier, "what": "volume", "why": exc.diagnostics[0].message})
                continue
            for d in data.findings:
                if d.severity >= Severity.WARNING:
                    world._warn("runner-volume", d.message, vol, d.hint or "fix the slices")
            world.not_played.extend(not_played_parts(vol))
            if len(faces) == 0:
                world._warn(
                    "runner-volume",
                    f"{vol.identifier}: no voxel reaches the iso-surface value {level}; nothing to draw",
                    vol,
                    "lower `iso-surface value` (a fraction of full scale)",
                )
                world.not_played.append({"object": vol.identifier, "what": "volume", "why": "empty iso-surface"})
                continue
            body = Body(
                identifier=vol.identifier,
                name=vol.name or vol.identifier.removeprefix("VOLUME "),
                mass=0.0,
                location=pose_or_identity(vol.location),
                source=vol.source,
            )
            key = merge_namespace(ns, vol.namespace) + vol.identifier
            parent, frame = resolve_frame(world, vol.parent, ns, vol, body_type)
            report = {
                "object": vol.identifier,
                "key": key,
                "voxels": list(data.voxels.shape[::-1]),
                "slices_found": len(data.files),
                "dimensions_m": data.dimensions.tolist(),
                "triangles": int(len(faces)),
                "iso_surface_value": level,
            }
            out.append(
                VolumeSurface(
                    key,
                    vol,
                    m,
                    body,
                    parent,
                    frame @ pose_to_matrix(pose_or_identity(vol.location)),
                    data.dimensions,
                    np.asarray(verts, dtype=np.float32),
                    np.asarray(faces, dtype=np.uint32),
                    tuple(rgba(vol) or BONE),
                    report,
                    data.voxels >= level,
                )
            )
    return out


__all__ = ["BONE", "VolumeSurface", "not_played_parts", "volume_surfaces"]
