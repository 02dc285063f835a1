"""Small helpers shared by the suturing scene's builders: 4x4 transforms to ADF poses, with
values rounded so that a build is byte-identical on every machine."""

from __future__ import annotations

import math

import numpy as np

from ...model import Pose, Quat, Vec3

DECIMALS = 10  # 0.1 nm and 1e-10 rad: far below anything the scene resolves


def r(v: float) -> float:
    return round(float(v), DECIMALS) + 0.0


def vec(v) -> Vec3:
    return Vec3(r(v[0]), r(v[1]), r(v[2]))


def pose(m: np.ndarray) -> Pose:
    """ADF pose of a 4x4 transform."""
    q = Quat.from_matrix(m[:3, :3]).normalized()
    if q.w < 0:
        q = Quat(-q.x, -q.y, -q.z, -q.w)
    return Pose(vec(m[:3, 3]), q)


def translation(x=0.0, y=0.0, z=0.0) -> np.ndarray:
    t = np.eye(4)
    t[:3, 3] = (x, y, z)
    return t


def rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    t = np.eye(4)
    t[1:3, 1:3] = [[c, -s], [s, c]]
    return t


def rot_y(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    t = np.eye(4)
    t[0, 0], t[0, 2], t[2, 0], t[2, 2] = c, s, -s, c
    return t


def rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    t = np.eye(4)
    t[:2, :2] = [[c, -s], [s, c]]
    return t


def look_frame(origin, z_axis, x_hint) -> np.ndarray:
    """A frame at ``origin`` whose z is ``z_axis`` and whose x is as close to ``x_hint`` as it can be."""
    z = np.asarray(z_axis, float)
    z = z / np.linalg.norm(z)
    x = np.asarray(x_hint, float) - np.dot(x_hint, z) * z
    x = x / np.linalg.norm(x)
    t = np.eye(4)
    t[:3, 0], t[:3, 1], t[:3, 2], t[:3, 3] = x, np.cross(z, x), z, origin
    return t


def for_ambf(m):
    """The model ``m`` (in place) with the `joint offset` and `offset` of every joint on a body
    whose inertial frame is turned set to those with which AMBF, building joint frames in the
    bodies' inertial frames, builds the ones the body frames give
    (semantics.offsets_for_body_frames): the file means in AMBF what it means in its body frames."""
    from ...model.semantics import inertial_rotation, offsets_for_body_frames

    for j in m.joints:
        parent, child = m.body(j.parent), m.body(j.child)
        if all(inertial_rotation(b).angle_to(inertial_rotation(None)) < 1e-12 for b in (parent, child)):
            continue
        jo, off = offsets_for_body_frames(j, parent, child)
        j.joint_offset, j.offset = (r(jo) if abs(jo) > 1e-12 else None), r(off)
    return m
