"""Compare two models field by field, floats to a tolerance; quaternions q and -q are equal."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from .pose import Quat


def _close(a: float, b: float, tol: float) -> bool:
    if math.isnan(a) and math.isnan(b):
        return True
    return a == b or abs(a - b) <= tol * max(1.0, abs(a), abs(b))


def differences(a: Any, b: Any, tol: float = 1e-12, path: str = "", quat_tol: float | None = None) -> list[str]:
    """Human-readable paths where ``a`` and ``b`` differ (empty when equal).

    ``quat_tol`` (radians, default ``tol``) bounds the angle between two orientations: an
    orientation that went through roll/pitch/yaw near gimbal lock keeps only ~1e-11 rad.
    """
    out: list[str] = []
    _diff(a, b, tol, path or "<root>", out, tol if quat_tol is None else quat_tol)
    return out


def equal(a: Any, b: Any, tol: float = 1e-12, quat_tol: float | None = None) -> bool:
    return not differences(a, b, tol, quat_tol=quat_tol)


def _diff(a, b, tol, path, out, qtol) -> None:
    if len(out) > 50:
        return
    if isinstance(a, Quat) and isinstance(b, Quat):
        if a.angle_to(b) > qtol:
            out.append(f"{path}: {tuple(a)} != {tuple(b)} ({a.angle_to(b):.3g} rad apart)")
        return
    if isinstance(a, bool) or isinstance(b, bool):
        if a is not b:
            out.append(f"{path}: {a!r} != {b!r}")
        return
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        if not _close(float(a), float(b), tol):
            out.append(f"{path}: {a!r} != {b!r}")
        return
    if dataclasses.is_dataclass(a) and dataclasses.is_dataclass(b):
        if type(a) is not type(b):
            out.append(f"{path}: {type(a).__name__} != {type(b).__name__}")
            return
        for f in dataclasses.fields(a):
            if f.compare:
                _diff(getattr(a, f.name), getattr(b, f.name), tol, f"{path}.{f.name}", out, qtol)
        return
    if isinstance(a, dict) and isinstance(b, dict):
        for k in a.keys() | b.keys():
            if k not in a or k not in b:
                out.append(f"{path}[{k!r}]: only in {'first' if k in a else 'second'}")
            else:
                _diff(a[k], b[k], tol, f"{path}[{k!r}]", out, qtol)
        return
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        if len(a) != len(b):
            out.append(f"{path}: length {len(a)} != {len(b)}")
            return
        for i, (x, y) in enumerate(zip(a, b)):
            label = getattr(x, "identifier", None) or i
            _diff(x, y, tol, f"{path}[{label}]", out, qtol)
        return
    if a != b:
        out.append(f"{path}: {a!r} != {b!r}")
