"""The suturing challenge's needle-pose-estimation score: position error (m, the distance
between the estimated and true needle origins) and orientation error (rad, the angle of
R_gt^T R_est), as the challenge's evaluation defines them.

Pose JSON (ground truth and estimate alike), either a single pose or {"poses": [pose, ...]}
compared pairwise in order; a pose is

    {"position": [x, y, z], "orientation": [qx, qy, qz, qw]}   (unit quaternion, x y z w)
 or {"position": [x, y, z], "rpy": [roll, pitch, yaw]}           (ADF's fixed-axis x-y-z, rad)
 or {"matrix": [[...4 numbers...] x 4]}                          (homogeneous 4x4)
"""

from __future__ import annotations

import math

import numpy as np


class PoseFormatError(ValueError):
    """A pose that cannot be read; the message says which field."""


def _rpy(r, p, y) -> np.ndarray:
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def _quat(x, y, z, w) -> np.ndarray:
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if not n or abs(n - 1.0) > 1e-3:
        raise PoseFormatError(f"orientation quaternion has norm {n:.4g}, not 1")
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _numbers(v, n: int, what: str) -> list[float]:
    if (
        not isinstance(v, list)
        or len(v) != n
        or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v)
    ):
        raise PoseFormatError(f"{what} must be a list of {n} finite numbers")
    return [float(x) for x in v]


def read_pose(d) -> np.ndarray:
    """4x4 pose from one of the documented JSON shapes."""
    if not isinstance(d, dict):
        raise PoseFormatError("a pose must be an object")
    t = np.eye(4)
    if "matrix" in d:
        m = d["matrix"]
        if not isinstance(m, list) or len(m) != 4:
            raise PoseFormatError("matrix must be 4 rows of 4 numbers")
        t = np.array([_numbers(r, 4, "each matrix row") for r in m])
        r = t[:3, :3]
        if np.abs(r.T @ r - np.eye(3)).max() > 1e-3 or np.linalg.det(r) < 0:
            raise PoseFormatError("matrix rotation part is not a rotation")
        return t
    if "position" not in d:
        raise PoseFormatError('a pose needs "position" (or "matrix")')
    t[:3, 3] = _numbers(d["position"], 3, "position")
    if "orientation" in d:
        t[:3, :3] = _quat(*_numbers(d["orientation"], 4, "orientation (x, y, z, w)"))
    elif "rpy" in d:
        t[:3, :3] = _rpy(*_numbers(d["rpy"], 3, "rpy"))
    else:
        raise PoseFormatError('a pose needs "orientation" [qx, qy, qz, qw] or "rpy" [r, p, y]')
    return t


def read_poses(doc) -> list[np.ndarray]:
    if isinstance(doc, dict) and "poses" in doc:
        if not isinstance(doc["poses"], list) or not doc["poses"]:
            raise PoseFormatError('"poses" must be a non-empty list')
        return [read_pose(p) for p in doc["poses"]]
    return [read_pose(doc)]


def pose_errors(gt: np.ndarray, est: np.ndarray) -> tuple[float, float]:
    """(position error m, orientation error rad = angle of R_gt^T R_est)."""
    dp = float(np.linalg.norm(est[:3, 3] - gt[:3, 3]))
    c = (np.trace(gt[:3, :3].T @ est[:3, :3]) - 1.0) / 2.0
    return dp, float(math.acos(max(-1.0, min(1.0, c))))
