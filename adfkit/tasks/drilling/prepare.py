"""From a loaded scene to a drilling task: the volume (chosen by index, file or name), the burr
(burr.py: a sphere body, or a drill mesh's tip), the tissue labels and the tool path."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ... import inputs
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
    label_ranges: list[tuple]  # (low, high) in the values' units, or (r, g, b) of a colour tissue
    protected: set[str]
    labels_file: str | None
    burr_how: str = "its sphere shape"  # what the burr's sphere is (burr.Burr.how)


def _colour_slices(path) -> bool:
    from PIL import Image

    with Image.open(path) as img:
        return img.mode not in ("1", "L", "I", "F") and not img.mode.startswith("I;16")


def _volume_pose(scene, model, vol) -> np.ndarray:
    """The volume's frame in the world, its parents followed as AMBF does (a body's location, a
    camera's setView frame: runner.frames), from where the scene puts them."""
    from ...runner.frames import camera_frame, match, scene_cameras
    from ...runner.names import merge_namespace

    bodies = [
        (merge_namespace(m.namespace or "", b.namespace) + b.identifier, b) for m in scene.models for b in m.bodies
    ]
    cameras = scene_cameras(scene)
    t = _pose(vol.location)
    ref, ns = vol.parent, model.namespace or ""
    for _ in range(16):
        if not ref:
            break
        body = match(bodies, ref, ns)
        if body is not None:
            return _pose(body[-1].location) @ t
        cam = match(cameras, ref, ns)
        if cam is None:
            break  # not found: where its own location puts it, as AMBF leaves it
        key, ns, c = cam
        t = camera_frame(c) @ t
        ref = c.parent
    return t


def _pose(p) -> np.ndarray:
    from ...model.semantics import pose_or_identity
    from ...runner.rotations import pose_to_matrix

    return pose_to_matrix(pose_or_identity(p))


def volume_choices(scene) -> list[tuple[int, object, object]]:
    """(index, model, volume) of every defined volume of the scene, in the order they load."""
    found = [(m, v) for m in scene.models for v in m.volumes if v.defined]
    return [(i, m, v) for i, (m, v) in enumerate(found)]


def _listed(choices) -> str:
    return "; ".join(
        f"{i}: {v.name or v.identifier} ({inputs.shown(m.path) if m.path else 'no file'})" for i, m, v in choices
    )


def _same_file(model, text: str) -> bool:
    if model.path is None:
        return False
    try:
        return Path(text).resolve() == Path(model.path).resolve()
    except (OSError, ValueError):
        return False


def _names(v) -> set:
    return {v.identifier, v.name, v.identifier.removeprefix("VOLUME ")}


def find_volume(scene, choice: str | None):
    """(model, volume) that ``choice`` names: an index (0 is the first volume loaded), the model
    file holding it (``FILE``, or ``FILE:NAME`` when the file has several), or its name; none
    given, the scene's only volume. Anything else is a ``drill-volume`` error listing them."""
    choices = volume_choices(scene)
    hint = "choose one with --volume INDEX, --volume NAME or --volume FILE (the model file holding it)"
    if not choices:
        raise AdfError(error("drill-volume", "the scene has no volume", None, "drill a scene with a `volumes` section"))
    if not choice:
        if len(choices) == 1:
            return choices[0][1:]
        raise AdfError(error("drill-volume", f"the scene has {len(choices)} volumes: {_listed(choices)}", None, hint))
    if choice.isdigit():
        pick = [c for c in choices if c[0] == int(choice)]
    else:
        file, _, name = choice.rpartition(":")
        if file and any(_same_file(m, file) for _, m, _ in choices):
            pick = [c for c in choices if _same_file(c[1], file) and name in _names(c[2])]
        else:
            pick = [c for c in choices if _same_file(c[1], choice)] or [c for c in choices if choice in _names(c[2])]
    if len(pick) != 1:
        what = f"matches {len(pick)} volumes: {_listed(pick)}" if pick else f"matches none of {_listed(choices)}"
        raise AdfError(error("drill-volume", f"--volume {choice!r} {what}", None, hint))
    return pick[0][1:]


def prepare(
    scene, volume_name: str | None = None, burr_name: str | None = None, protect=(), burr_radius: float | None = None
) -> DrillScene:
    from ...geometry.volume import DEFAULT_ISO, load_volume
    from .burr import find_burr

    model, vol = find_volume(scene, volume_name)
    burr = find_burr(scene, burr_name, burr_radius)
    data = load_volume(model, vol, raw=True)  # the slices' own values: uint8 for 8-bit slices
    iso = (vol.iso_surface_value if vol.iso_surface_value is not None else DEFAULT_ISO) * data.unit
    labels_path = relative_to_file(model.path, str(vol.images.path)) / "labels.yaml"
    labels_file = None
    if os.path.lexists(labels_path):
        names, ranges, protected = read_labels(labels_path, data.full_scale / data.unit, getattr(model, "tree", None))
        if any(len(r) == 3 for r in ranges) and not _colour_slices(data.files[0]):
            raise AdfError(
                error(
                    "drill-labels",
                    f"{inputs.shown(labels_path)} names tissues by colour, and the volume's slices are grey",
                    None,
                    "give grey slices' tissues as ranges of values, e.g. bone: [150, 255]",
                )
            )
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
    start = (_pose(burr.body.location) @ np.append(burr.centre_in_body, 1.0))[:3]
    return DrillScene(
        model,
        vol,
        data,
        _volume_pose(scene, model, vol),
        burr.body.identifier,
        start,
        burr.radius,
        ["unlabelled", *names],
        ranges,
        set(protected) | set(protect),
        labels_file,
        burr.how,
    )


def editable(ds: DrillScene) -> EditableVolume:
    from ...geometry.volume import DEFAULT_ISO

    iso = (ds.volume.iso_surface_value if ds.volume.iso_surface_value is not None else DEFAULT_ISO) * ds.data.unit
    vals = ds.data.voxels
    labels = label_array(vals, ds.label_ranges, ds.data.unit, ds.data.files)
    return EditableVolume(vals, ds.data.dimensions, iso, labels, ds.label_names)


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


__all__ = ["DrillScene", "default_path", "editable", "find_volume", "prepare", "volume_choices"]
