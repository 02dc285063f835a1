"""From a loaded scene to a drilling task: the volume, the burr (a sphere body of the scene),
the tissue labels and the tool path."""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ...adf.paths import relative_to_file
from ...diagnostics import AdfError, error
from ...geometry.voxels_edit import EditableVolume
from .inputs import default_labels, label_array, read_labels


@dataclass
class DrillScene:
    model: object  # the ModelFile holding the volume
    volume: object  # its Volume
    data: object  # VolumeData
    pose: np.ndarray  # 4x4 volume frame in the world
    burr_name: str
    burr_start: np.ndarray  # (3,) world
    burr_radius: float
    label_names: list[str]  # index = label id; 0 is "unlabelled"
    label_ranges: list[tuple[float, float]]
    protected: set[str]
    labels_file: str | None


def _pose(p) -> np.ndarray:
    from ...model.semantics import pose_or_identity
    from ...runner.rotations import pose_to_matrix

    return pose_to_matrix(pose_or_identity(p))


def find_volume(scene, name: str | None):
    found = [(m, v) for m in scene.models for v in m.volumes if v.defined]
    if name:
        found = [(m, v) for m, v in found if name in (v.identifier, v.name, v.identifier.removeprefix("VOLUME "))]
    if len(found) != 1:
        names = [v.identifier for m in scene.models for v in m.volumes]
        raise AdfError(
            error(
                "drill-volume",
                f"the scene has {len(found)} volume(s) matching {name!r}: {names}"
                if name
                else f"drilling needs one volume; the scene has {len(found)}: {names}",
                None,
                "name one with --volume NAME" if found else "drill a scene with a `volumes` section",
            )
        )
    return found[0]


def find_burr(scene, name: str | None):
    """The sphere body the burr is: the one named ``name``, else the sphere body whose name
    holds 'burr', else the only sphere body."""
    spheres = []
    for m in scene.models:
        for b in m.bodies:
            shape = (b.collision_shape or b.shape or "").lower()
            geo = b.collision_geometry if b.collision_shape else b.geometry
            if shape == "sphere" and geo is not None and geo.radius:
                spheres.append((b, float(geo.radius) * (b.scale if b.scale is not None else 1.0)))
    if name:
        pick = [s for s in spheres if name in (s[0].identifier, s[0].name, s[0].identifier.removeprefix("BODY "))]
    else:
        pick = [s for s in spheres if "burr" in (s[0].name or s[0].identifier).lower()] or spheres
    if len(pick) != 1:
        raise AdfError(
            error(
                "drill-burr",
                f"no single burr: {len(pick)} sphere bodies match ({[s[0].identifier for s in spheres]})",
                None,
                "name the burr's body with --burr NAME (a body with a sphere shape)",
            )
        )
    return pick[0]


def prepare(scene, volume_name: str | None = None, burr_name: str | None = None, protect=()) -> DrillScene:
    from ...geometry.volume import DEFAULT_ISO, load_volume

    model, vol = find_volume(scene, volume_name)
    body, radius = find_burr(scene, burr_name)
    data = load_volume(model, vol)
    iso = vol.iso_surface_value if vol.iso_surface_value is not None else DEFAULT_ISO
    labels_path = relative_to_file(model.path, str(vol.images.path)) / "labels.yaml"
    labels_file = None
    if os.path.lexists(labels_path):
        names, ranges, protected = read_labels(labels_path, data.full_scale, getattr(model, "tree", None))
        labels_file = str(labels_path)
    else:
        names, ranges, protected = default_labels(iso)
    unknown = [p for p in protect if p not in names]
    if unknown:
        raise AdfError(
            error(
                "bad-option",
                f"--protect {unknown[0]!r} is not a tissue of this volume ({', '.join(names)})",
                None,
                "name a tissue of the volume's labels.yaml, or add it there",
            )
        )
    pos = body.location.position if body.location else None
    start = np.array([pos.x, pos.y, pos.z] if pos else [0.0, 0.0, 0.0])
    return DrillScene(
        model,
        vol,
        data,
        _pose(vol.location),
        body.identifier,
        start,
        radius,
        ["unlabelled", *names],
        ranges,
        set(protected) | set(protect),
        labels_file,
    )


def editable(ds: DrillScene) -> EditableVolume:
    from ...geometry.volume import DEFAULT_ISO

    iso = ds.volume.iso_surface_value if ds.volume.iso_surface_value is not None else DEFAULT_ISO
    vals = ds.data.voxels
    return EditableVolume(vals, ds.data.dimensions, iso, label_array(vals, ds.label_ranges), ds.label_names)


def default_path(ds: DrillScene, vol: EditableVolume, depth: float) -> np.ndarray:
    """The scripted path: straight from the burr towards the volume's centre, ending ``depth``
    past the first solid voxel on that line (at the centre when the line meets none)."""
    centre = ds.pose[:3, 3]
    d = centre - ds.burr_start
    n = np.linalg.norm(d)
    if n == 0:
        return centre[None, :]
    u = d / n
    rot, org = ds.pose[:3, :3], ds.pose[:3, 3]
    step = float(vol.step.min()) / 2
    shape = np.array(vol.values.shape[::-1])
    for s in np.arange(0.0, n + 2 * np.linalg.norm(vol.dimensions), step):
        q = ds.burr_start + s * u
        ijk = np.rint(vol.index_of(rot.T @ (q - org))).astype(int)
        if np.all(ijk >= 0) and np.all(ijk < shape) and vol.values[ijk[2], ijk[1], ijk[0]] >= vol.iso:
            return (q + depth * u)[None, :]
    return centre[None, :]


__all__ = ["DrillScene", "default_path", "editable", "find_burr", "find_volume", "prepare"]
