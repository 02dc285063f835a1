"""The suture thread: 40 capsule elements joined by six-dof springs with the published limits
(angular ±pi/6, linear axes locked) and neither stiffness nor damping, the first element fixed
to the needle's tail. Names and the element frame (z along the thread, the next element at -z)
follow the challenge's phantom file.

The published stiffness and damping (0.02 N·m/rad, 0.01 N·m·s/rad) are left out: on elements of
their capsules' inertia (1.5e-8 kg·m²) no engine plays them as springs. AMBF's springs are
explicit, and its damper, at Bullet's cap, takes an element's whole turning each 1 ms step from
both its joints: AMBF's thread writhes and its world blows up under the suture's replay. MuJoCo's
joints without the damper go unstable within 10 ms. adfkit's suture (implicit springs over the
4 ms step) divided their torques by about 3e5, a limp thread. With neither, every engine plays
the same limp chain, held by its limits and its bodies' own velocity damping (0.9)
(docs/parity.md, "The bundled scene at rest")."""

from __future__ import annotations

import math

import numpy as np

from ...model import (
    RGBA,
    AxesGains,
    Body,
    Friction,
    Geometry,
    Inertia,
    Joint,
    JointLimits,
    Pose,
    Vec3,
    Vec3Range,
    VelocityDamping,
)
from ...model.semantics import shortest_arc
from . import layout as L
from .frames import pose, r, rot_x, vec

COLOUR = RGBA(r=0.25, g=0.2, b=0.85, a=1.0)
#: the challenge's published angular stiffness (N·m/rad) and damping (N·m·s/rad) of the thread's
#: joints, which the parity scene's falling thread keeps (scenes/parity.py)
PUBLISHED_STIFFNESS, PUBLISHED_DAMPING = 0.02, 0.01
#: the bundled scene's: none (the module's docstring says why)
STIFFNESS, DAMPING = 0.0, 0.0
LIMIT = math.pi / 6


def element_name(i: int) -> str:
    return "Thread" if i == 0 else f"Thread_{i:03d}"


def fixed_axes(rel: np.ndarray, child_axis=(0.0, 0.0, 1.0)) -> tuple[Vec3, float]:
    """Parent axis and offset of a joint whose child frame sits at rotation ``rel`` (3x3, in
    the parent frame) at joint value 0, for the given child axis (adf-format.md §8.2: the child
    is turned by R(a, offset)·Rmin(b→a))."""
    b = np.asarray(child_axis, float)
    a = rel @ b
    arc = np.array(shortest_arc(Vec3(*b), Vec3(*a)).matrix())
    twist = rel @ arc.T  # a rotation about a
    off = math.atan2(
        float(np.dot(a, np.array([twist[2, 1] - twist[1, 2], twist[0, 2] - twist[2, 0], twist[1, 0] - twist[0, 1]]))),
        float(np.trace(twist) - 1.0),
    )
    return vec(a), r(off)


def thread_path(tail: np.ndarray, rest_z: float) -> list[np.ndarray]:
    """World pose of every element: from the needle's tail along world -y, the first element
    level with the tail, the next two sloping down to ``rest_z`` (the needle's collision hull
    holds the tail higher than a thread element lies; two joints of half the slope each stay
    well inside the ±pi/6 limits), then lying on at rest_z. Element z points back toward the
    needle, the next element is at -z."""
    p = L.THREAD_PITCH
    drop = max(0.0, tail[2] - rest_z)
    slope = math.asin(min(1.0, drop / (2 * p)))
    at = np.array(tail, float)
    poses = []
    for i in range(L.THREAD_ELEMENTS):
        a = slope if i in (1, 2) else 0.0
        d = np.array([0.0, -math.cos(a), -math.sin(a)])  # down the chain
        m = rot_x(-math.pi / 2 + a)  # z -> -d, x stays world x
        m[:3, 3] = at + d * p / 2
        poses.append(m)
        at = at + d * p
    return poses


def thread_bodies_and_joints(needle_world: np.ndarray, stiffness: float = STIFFNESS, damping: float = DAMPING):
    """Bodies and joints of the thread lying along world -y from the needle's tail, its joints'
    angular ``stiffness`` and ``damping`` about every axis."""
    p = L.THREAD_PITCH
    tail_local = np.array(
        [L.NEEDLE_RADIUS * math.cos(L.NEEDLE_TAIL_ANGLE), L.NEEDLE_RADIUS * math.sin(L.NEEDLE_TAIL_ANGLE), 0.0]
    )
    tail = (needle_world @ np.append(tail_local, 1.0))[:3]
    path = thread_path(tail, L.SLAB[2] + L.THREAD_RADIUS + 0.00001)
    g = Geometry(radius=L.THREAD_RADIUS, height=0.00238, axis="z")
    m = L.THREAD_MASS
    i_perp = m * (3 * L.THREAD_RADIUS**2 + p * p) / 12
    inertia = Inertia(ix=r(i_perp), iy=r(i_perp), iz=r(m * L.THREAD_RADIUS**2 / 2))
    bodies, joints = [], []
    limits = JointLimits(
        linear=Vec3Range(low=Vec3(0.0, 0.0, 0.0), high=Vec3(0.0, 0.0, 0.0)),
        angular=Vec3Range(low=Vec3(-LIMIT, -LIMIT, -LIMIT), high=Vec3(LIMIT, LIMIT, LIMIT)),
    )
    for i in range(L.THREAD_ELEMENTS):
        name = element_name(i)
        world = path[i]
        bodies.append(
            Body(
                identifier=f"BODY {name}",
                name=name,
                mass=m,
                location=pose(world),
                inertia=inertia,
                inertial_offset=Pose(),
                shape="Capsule",
                geometry=g,
                collision_shape="Capsule",
                collision_geometry=g,
                collision_offset=Pose(),
                collision_margin=0.0001,
                color_rgba=COLOUR,
                friction=Friction(static=0.5, rolling=0.0),
                restitution=0.0,
                damping=VelocityDamping(linear=0.9, angular=0.9),
                passive=False,
            )
        )
        if i == 0:
            rel = needle_world[:3, :3].T @ world[:3, :3]
            axis, off = fixed_axes(rel)
            joints.append(
                Joint(
                    identifier="JOINT Needle-Thread",
                    name="Needle-Thread",
                    parent="BODY Needle",
                    child=f"BODY {name}",
                    type="fixed",
                    parent_pivot=vec(tail_local),
                    child_pivot=Vec3(0.0, 0.0, r(p / 2)),
                    parent_axis=axis,
                    child_axis=Vec3(0.0, 0.0, 1.0),
                    offset=off,
                    passive=True,
                )
            )
            continue
        prev = element_name(i - 1)
        joints.append(
            Joint(
                identifier=f"JOINT {prev}-{name}",
                name=f"{prev}-{name}",
                parent=f"BODY {prev}",
                child=f"BODY {name}",
                type="six dof spring",
                parent_pivot=Vec3(0.0, 0.0, r(-p / 2)),
                child_pivot=Vec3(0.0, 0.0, r(p / 2)),
                parent_axis=Vec3(0.0, 1.0, 0.0),
                child_axis=Vec3(0.0, 1.0, 0.0),
                joint_limits=limits,
                stiffness=AxesGains(linear=Vec3(0.0, 0.0, 0.0), angular=Vec3(stiffness, stiffness, stiffness)),
                damping=AxesGains(linear=Vec3(0.0, 0.0, 0.0), angular=Vec3(damping, damping, damping)),
                equilibrium_point=AxesGains(linear=Vec3(0.0, 0.0, 0.0), angular=Vec3(0.0, 0.0, 0.0)),
                passive=True,
            )
        )
    return bodies, joints


__all__ = ["thread_bodies_and_joints", "element_name", "fixed_axes"]
