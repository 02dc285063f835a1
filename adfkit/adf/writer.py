"""Write the scene model back as ADF: deterministic, readable, atomic.

Key order follows the field declarations (the order the Blender add-on writes), then any
keys the reader did not recognise, so a file read and written back keeps everything.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import yaml

from ..model import Colors, Pose, Quat, Vec3, quat_to_rpy
from ..model.files import AdfFile, ObjectList
from ..model.pose import written_rpy
from ..model.spec import FloatOr, ListOf, Node, adf_fields
from ..scratch import temp_beside


class _Flow(dict):
    """A small mapping written on one line: {x: 0.0, y: 0.0, z: 0.0}."""


_BaseDumper: Any = getattr(yaml, "CSafeDumper", yaml.SafeDumper)  # libyaml's emitter when built in: ~5x faster


class _Dumper(_BaseDumper):
    def ignore_aliases(self, data):  # readable output: never emit anchors
        return True


def _represent_flow(dumper, data):
    return dumper.represent_mapping("tag:yaml.org,2002:map", data.items(), flow_style=True)


def _represent_dict(dumper, data):
    return dumper.represent_mapping("tag:yaml.org,2002:map", data.items(), flow_style=False)


_Dumper.add_representer(_Flow, _represent_flow)
_Dumper.add_representer(dict, _represent_dict)


def _vec(v) -> _Flow:
    return _Flow(x=float(v[0]), y=float(v[1]), z=float(v[2]))


RPY_DECIMALS = 10


def _angle(a: float) -> float:
    # Rounding to 1e-10 rad makes write → read → write byte-identical (the quaternion
    # round trip alone wobbles in the last bit) and turns 1e-17 noise into 0.0. Near gimbal lock roll and yaw lose ~1e-12.
    a = round(a, RPY_DECIMALS) + 0.0
    if a <= round(-math.pi, RPY_DECIMALS):  # -pi and +pi are the same angle: write +pi
        a = round(math.pi, RPY_DECIMALS)
    return a


def _rpy(q: Quat) -> _Flow:
    kept = written_rpy(q)
    if kept is not None:  # read from a file and unchanged: the angles as they were written
        return _Flow(r=float(kept[0]), p=float(kept[1]), y=float(kept[2]))
    r, p, y = quat_to_rpy(q)
    return _Flow(r=_angle(r), p=_angle(p), y=_angle(y))


def value_to_plain(kind, value) -> Any:
    if kind in ("float",):
        return float(value)
    if kind in ("bool", "str", "any"):
        return value
    if kind in ("int", "uint"):
        return int(value)
    if kind == "vec3":
        return _vec(value)
    if kind == "rpy":
        return _rpy(value)
    if kind == "pose":
        return {"position": _vec(value.position), "orientation": _rpy(value.orientation)}
    if isinstance(kind, ListOf):
        return [value_to_plain(kind.item, v) for v in value]
    if isinstance(kind, FloatOr):
        return node_to_plain(value) if isinstance(value, Node) else float(value)
    if isinstance(kind, type) and issubclass(kind, Node):
        return node_to_plain(value)
    raise TypeError(f"unknown field kind {kind!r}")  # pragma: no cover


_FLOW_KEYS = [
    {"r", "g", "b", "a"},
    {"r", "g", "b"},
    {"low", "high"},
    {"near", "far"},
    {"width", "height"},
    {"static", "rolling"},
    {"linear", "angular"},
    {"P", "I", "D"},
    {"P", "D"},
    {"ix", "iy", "iz"},
    {"x", "y", "z"},
]


def node_to_plain(obj: Node) -> dict:
    out: dict[str, Any] = {}
    for f in adf_fields(obj):
        kind = f.metadata["kind"]
        if isinstance(kind, ObjectList):
            continue
        value = getattr(obj, f.name)
        if value is None:
            continue
        out[f.metadata["adf_key"]] = value_to_plain(kind, value)
    for k, v in obj.extras.items():
        out.setdefault(k, v)
    if set(out) in _FLOW_KEYS and all(isinstance(v, (int, float)) for v in out.values()):
        return _Flow(out)
    return out


def file_to_plain(doc: AdfFile) -> dict:
    """The whole file as plain data: object lists, file-level keys, extras, then objects."""
    out: dict[str, Any]
    if isinstance(doc, Colors):
        out = {name: node_to_plain(c) for name, c in doc.colors.items()}
        out.update((k, v) for k, v in doc.extras.items() if k not in out)
        return out
    out = {}
    objects: dict[str, dict] = {}
    present: set[str] = getattr(doc, "present_lists", set())
    for f in adf_fields(doc):
        kind = f.metadata["kind"]
        if not isinstance(kind, ObjectList):
            continue
        items = getattr(doc, f.name)
        if not items and f.metadata["adf_key"] not in present:
            continue
        out[f.metadata["adf_key"]] = [o.identifier for o in items]
        for o in items:
            if o.defined and o.identifier not in objects:
                objects[o.identifier] = node_to_plain(o)
    for k, v in node_to_plain(doc).items():
        out.setdefault(k, v)
    for ident, body in objects.items():
        out.setdefault(ident, body)
    return out


HEADER = "# ADF 1.0, written by adfkit\n"


def dumps(doc: AdfFile, header: bool = True) -> str:
    text = yaml.dump(
        file_to_plain(doc), Dumper=_Dumper, sort_keys=False, allow_unicode=True, default_flow_style=False, width=100
    )
    return (HEADER if header else "") + text


def _mode_for(path: Path) -> int:
    try:
        return path.stat().st_mode & 0o7777
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def atomic_write_text(path: str | Path, text: str) -> None:
    """Write beside the target, then rename: a failure leaves the old file as it was."""
    atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write bytes beside the target, then rename: a failure leaves the old file as it was.
    Returns the path written."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = temp_beside(path)  # .<name>.<pid>.*.tmp: a later write removes it if this one is killed
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        # mkstemp makes the file private (0600); give it the mode a plain open() would, or keep
        # the mode of the file it replaces
        os.chmod(tmp, _mode_for(path))
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return path


def write_file(doc: AdfFile, path: str | Path) -> Path:
    path = Path(path)
    atomic_write_text(path, dumps(doc))
    return path


__all__ = [
    "dumps",
    "write_file",
    "atomic_write_text",
    "atomic_write_bytes",
    "file_to_plain",
    "node_to_plain",
    "Pose",
    "Vec3",
]
