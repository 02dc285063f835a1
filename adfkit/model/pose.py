"""Positions, unit quaternions and poses, with the one conversion to and from ADF roll/pitch/yaw.

Quaternions are stored as (x, y, z, w), the order PyBullet uses. ADF's RPY is fixed-axis
X-Y-Z: R = Rz(yaw) * Ry(pitch) * Rx(roll), the same as URDF ``rpy``.
Pure ``math`` on purpose: the core must import fast, without numpy.
"""

from __future__ import annotations

import math
from typing import NamedTuple


class Vec3(NamedTuple):
    x: float = 0.0
    y: float = 0.0
    z: float = 0.0

    def __add__(self, o):
        return Vec3(self.x + o[0], self.y + o[1], self.z + o[2])

    def __sub__(self, o):
        return Vec3(self.x - o[0], self.y - o[1], self.z - o[2])

    def scaled(self, s: float) -> Vec3:
        return Vec3(self.x * s, self.y * s, self.z * s)

    def dot(self, o) -> float:
        return self.x * o[0] + self.y * o[1] + self.z * o[2]

    def cross(self, o) -> Vec3:
        return Vec3(self.y * o[2] - self.z * o[1], self.z * o[0] - self.x * o[2], self.x * o[1] - self.y * o[0])

    def norm(self) -> float:
        return math.hypot(self.x, self.y, self.z)  # no overflow for components near 1e308

    def normalized(self) -> Vec3:
        n = self.norm()
        if n == 0.0:
            raise ValueError("cannot normalise a zero vector")
        return self.scaled(1.0 / n)


class Quat(NamedTuple):
    """Unit quaternion, (x, y, z, w)."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    w: float = 1.0

    def __mul__(self, o: Quat) -> Quat:  # type: ignore[override]
        ax, ay, az, aw = self
        bx, by, bz, bw = o
        return Quat(
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        )

    def conjugate(self) -> Quat:
        return Quat(-self.x, -self.y, -self.z, self.w)

    def inverse(self) -> Quat:
        """The inverse rotation (the conjugate of a unit quaternion)."""
        return Quat(-self.x, -self.y, -self.z, self.w)

    def normalized(self) -> Quat:
        n = math.sqrt(sum(c * c for c in self))
        if not 0.0 < n < math.inf:  # zero, infinite or NaN: no rotation can be read from it
            return NAN_QUAT
        return Quat(*(c / n for c in self))

    def rotate(self, v) -> Vec3:
        qv = Quat(v[0], v[1], v[2], 0.0)
        r = self * qv * self.conjugate()
        return Vec3(r.x, r.y, r.z)

    def matrix(self) -> tuple[tuple[float, float, float], ...]:
        x, y, z, w = self
        return (
            (1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
            (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
            (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)),
        )

    @classmethod
    def from_axis_angle(cls, axis, angle: float) -> Quat:
        a = Vec3(*axis).normalized()
        if not math.isfinite(angle) or not all(map(math.isfinite, a)):
            return NAN_QUAT
        s = math.sin(angle / 2.0)
        return cls(a.x * s, a.y * s, a.z * s, math.cos(angle / 2.0))

    @classmethod
    def from_matrix(cls, m) -> Quat:
        m00, m01, m02 = m[0]
        m10, m11, m12 = m[1]
        m20, m21, m22 = m[2]
        if not all(math.isfinite(v) for v in (m00, m01, m02, m10, m11, m12, m20, m21, m22)):
            return NAN_QUAT
        try:
            return cls._from_finite_matrix(m00, m01, m02, m10, m11, m12, m20, m21, m22)
        except (ValueError, ZeroDivisionError):  # not a rotation matrix
            return NAN_QUAT

    @classmethod
    def _from_finite_matrix(cls, m00, m01, m02, m10, m11, m12, m20, m21, m22) -> Quat:
        tr = m00 + m11 + m22
        if tr > 0:
            s = math.sqrt(tr + 1.0) * 2
            q = cls((m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25 * s)
        elif m00 > m11 and m00 > m22:
            s = math.sqrt(1.0 + m00 - m11 - m22) * 2
            q = cls(0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s)
        elif m11 > m22:
            s = math.sqrt(1.0 + m11 - m00 - m22) * 2
            q = cls((m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s)
        else:
            s = math.sqrt(1.0 + m22 - m00 - m11) * 2
            q = cls((m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s)
        return q.normalized()

    def angle_to(self, o: Quat) -> float:
        """Smallest rotation angle between two orientations, radians."""
        d = self.conjugate() * o
        return 2.0 * math.atan2(math.sqrt(d.x * d.x + d.y * d.y + d.z * d.z), abs(d.w))


IDENTITY = Quat()
#: What the rotation helpers return for non-finite input (they never raise on it): every
#: component NaN, so the validator's non-finite-number rule and the writers see it.
NAN_QUAT = Quat(math.nan, math.nan, math.nan, math.nan)


def rpy_to_quat(roll: float, pitch: float, yaw: float) -> Quat:
    """ADF/URDF roll-pitch-yaw (R = Rz(y)·Ry(p)·Rx(r)) to a unit quaternion (:data:`NAN_QUAT`
    for an infinite or NaN angle)."""
    if not (math.isfinite(roll) and math.isfinite(pitch) and math.isfinite(yaw)):
        return NAN_QUAT
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return Quat(
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


class WrittenQuat(Quat):
    """A rotation read from roll/pitch/yaw that remembers the three angles as written. Files
    often hold triples outside the ranges :func:`quat_to_rpy` returns (a pitch above pi/2 with
    roll and yaw turned by pi): a writer gives the same numbers back (:func:`written_rpy`) as
    long as the quaternion is exactly the one they make. Any arithmetic gives a plain Quat."""

    written: tuple[float, float, float]


def rpy_to_quat_kept(roll: float, pitch: float, yaw: float) -> Quat:
    """:func:`rpy_to_quat`, remembering the angles (a :class:`WrittenQuat`)."""
    q = rpy_to_quat(roll, pitch, yaw)
    if q is NAN_QUAT:
        return q
    kept = WrittenQuat(*q)
    kept.written = (roll, pitch, yaw)
    return kept


def written_rpy(q: Quat) -> tuple[float, float, float] | None:
    """The roll/pitch/yaw ``q`` was read from, while ``q`` is still exactly their rotation."""
    kept = getattr(q, "written", None)
    return kept if kept is not None and rpy_to_quat(*kept) == tuple(q) else None


def quat_to_rpy(q: Quat) -> tuple[float, float, float]:
    """Unit quaternion to ADF/URDF roll-pitch-yaw, each in (-pi, pi], pitch in [-pi/2, pi/2].

    Pitch comes from atan2 of matrix terms rather than asin, which keeps full precision
    near gimbal lock (pitch = ±pi/2), where robot files often sit.
    """
    (m00, _, _), (m10, _, _), (m20, m21, m22) = q.matrix()
    pitch = math.atan2(-m20, math.hypot(m00, m10))
    if math.hypot(m00, m10) > 1e-9:
        roll = math.atan2(m21, m22)
        yaw = math.atan2(m10, m00)
    else:  # gimbal lock: put the whole rotation about z into yaw
        (_, m01, _), (_, m11, _), _ = q.matrix()
        roll = 0.0
        yaw = math.atan2(-m01, m11)
    return roll, pitch, yaw


class Pose(NamedTuple):
    position: Vec3 = Vec3()
    orientation: Quat = IDENTITY

    def __mul__(self, o: Pose) -> Pose:  # type: ignore[override]
        """Compose: self (A in W) * o (B in A) = B in W."""
        return Pose(self.position + self.orientation.rotate(o.position), self.orientation * o.orientation)

    def inverse(self) -> Pose:
        qi = self.orientation.conjugate()
        return Pose(qi.rotate(self.position).scaled(-1.0), qi)

    def transform(self, v) -> Vec3:
        return self.position + self.orientation.rotate(v)

    @classmethod
    def from_rpy(cls, xyz=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0)) -> Pose:
        return cls(Vec3(*map(float, xyz)), rpy_to_quat(*rpy))

    def rpy(self) -> tuple[float, float, float]:
        return quat_to_rpy(self.orientation)
