"""Values the add-on computed in float64, kept beside Blender's single-precision properties.

*Estimate inertia* and the fitted primitives compute in float64 (:mod:`.precision`), but a
Blender property holds a float32 and an object's placement a float32 matrix: an inertial
offset's angle of pi would come back as 3.1415927 and a fitted capsule turned by pi as
-3.1415926072. The exact values are kept on the object (the ``adf_exact`` ID property, JSON),
and export writes each one while the property still holds its float32 image, as it writes an
imported file's snapshot value; a value the modeller has changed since is written as it stands.
"""

from __future__ import annotations

import json

from adfkit.model.pose import Pose, Quat, Vec3

from .fields import same32

KEY = "adf_exact"


def record(obj) -> dict:
    try:
        rec = json.loads(obj.get(KEY, "") or "{}")
    except ValueError:
        return {}
    return rec if isinstance(rec, dict) else {}


def keep(obj, **values) -> None:
    """Remember exact values of the object's ADF properties (by property name)."""
    rec = record(obj)
    rec.update({k: list(v) if isinstance(v, tuple) else v for k, v in values.items()})
    obj[KEY] = json.dumps(rec)


def _value(v):
    return tuple(v) if isinstance(v, list) else v


def applied(obj, values: dict) -> dict:
    """``values`` ({property: Blender value}, as ``properties.read_group`` gives them) with each
    value the modeller has not changed since it was computed replaced by its exact value."""
    out = dict(values)
    for k, v in record(obj).items():
        if out.get(k) is not None and same32(_value(v), out[k]):
            out[k] = _value(v)
    return out


def _basis(obj) -> list[float]:
    return [float(v) for row in obj.matrix_basis for v in row]


def keep_offset(child, pose: Pose) -> None:
    """Remember the exact pose a child was placed at in its parent's frame (its matrix_basis)."""
    keep(child, offset=[*pose.position, *pose.orientation], basis=_basis(child))


def offset(child) -> Pose | None:
    """The exact pose the child was placed at, while it has not been moved since."""
    rec = record(child)
    o = rec.get("offset")
    if not (isinstance(o, list) and len(o) == 7 and rec.get("basis") == _basis(child)):
        return None
    return Pose(Vec3(*o[:3]), Quat(*o[3:]))
