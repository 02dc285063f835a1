"""Numbers the add-on computes from Blender's single-precision data, without float32 error.

Blender stores vertex coordinates in float32: a 4 cm cube's corner 0.02 is 0.0199999996, and
its volume times 1000 kg/m³ is 0.0639999957 kg instead of 0.064. The geometry work (volume,
mass properties, fitted primitives) therefore takes the coordinates as the decimals they
stand for (:func:`typed`, float32's 7 significant digits, in float64) and computes in float64;
what it returns carries the digits its float32 input holds: :func:`rounded` to at most
:data:`FLOAT32_DIGITS` significant digits (and the scene's *Float digits*), a position to digits
of the mesh's size (:func:`snapped`), so a centre of mass that is zero by symmetry is 0, not
2.2e-10, and a symmetric body's principal axes are its own (:func:`principal`). Pure NumPy: no bpy.
"""

from __future__ import annotations

import math

import numpy as np

#: Significant decimal digits a float32 holds for certain (FLT_DIG is 6; 7 are needed to tell
#: neighbouring float32 values apart, and a value typed with 7 digits reads back the same).
FLOAT32_DIGITS = 7


def typed(values) -> np.ndarray:
    """float32 coordinates as the decimals they stand for, in float64: rounded to
    :data:`FLOAT32_DIGITS` digits of the largest of them (0.0199999996 -> 0.02 in a 4 cm cube;
    a rotation's -1.7e-09 -> 0). That is float32's own precision at that size: nothing a
    modeller made is moved by more than a float32 step of the mesh's extent."""
    a = np.asarray(values, dtype=np.float64)
    finite = np.abs(a[np.isfinite(a)])
    big = float(finite.max()) if finite.size else 0.0
    if big == 0.0:
        return a
    return np.round(a, FLOAT32_DIGITS - 1 - math.floor(math.log10(big))) + 0.0


def rounded(x: float, digits: int) -> float:
    """``x`` to ``digits`` significant digits (0.06400000000000002 -> 0.064)."""
    x = float(x)
    return float(f"{x:.{digits}g}") + 0.0 if math.isfinite(x) else x


def snapped(values, size: float, digits: int) -> tuple[float, ...]:
    """Coordinates of a point measured on a body of extent ``size``: rounded to ``digits``
    digits of that size, so what is zero by symmetry (1e-19, or 2.2e-10 from float32 input)
    is 0."""
    if not size > 0 or not math.isfinite(size):
        return tuple(float(v) for v in values)
    decimals = digits - 1 - math.floor(math.log10(size))
    return tuple(round(float(v), decimals) + 0.0 for v in values)


def principal(m, digits: int) -> tuple[np.ndarray, np.ndarray]:
    """(moments, axes as columns) of an inertia tensor whose entries are rounded to ``digits``
    digits of its largest one. The products of inertia that vanish by symmetry are then 0, and
    a diagonal tensor keeps the body's own axes (moments in x, y, z order, no rotation) instead
    of axes sorted by moment or drawn from rounding noise in a degenerate pair."""
    m = np.asarray(m, dtype=np.float64)
    big = float(np.abs(m).max()) if m.size else 0.0
    if big > 0 and math.isfinite(big):
        m = np.round(0.5 * (m + m.T), digits - 1 - math.floor(math.log10(big))) + 0.0
    if not np.any(m - np.diag(np.diag(m))):
        return np.diag(m).copy(), np.eye(3)
    moments, axes = np.linalg.eigh(m)
    if np.linalg.det(axes) < 0:
        axes[:, 2] *= -1.0
    return moments, axes
