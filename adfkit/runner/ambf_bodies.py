"""Bodies as AMBF's btRigidBodies are (Options.bodies == "ambf"), for every engine.

**Inertia.** A body whose file gives a mass and no `inertia` gets the inertia AMBF estimates
(afInertialObject::estimateInertia: Bullet's calculateLocalInertia of the body's collision
shape). A mesh body's shape is a btCompoundShape of one child a sub-mesh (a btGImpactMeshShape,
btConvexTriangleMeshShape or btConvexHullShape, each with the body's `collision margin`) placed in
the inertial frame, and the compound's inertia is the box of its bounds: the sub-meshes' bounds
grown by the margin on every side, mass/12·(ly² + lz², ...); a btConvexHullShape's or
btConvexTriangleMeshShape's bounds (`CONVEX_HULL`, `CONVEX_MESH`) are grown by Bullet's default
margin (0.04 m, CONVEX_DISTANCE_MARGIN) besides: each caches its bounds when it is made, with the
margin it is made with, and AMBF sets the file's margin after
(btPolyhedralConvexAabbCachingShape::recalcLocalAabb; getAabb adds the margin of the moment). The
corpus suturing set's needle (nine hulls within 1.7 x 1.0 x 0.1 cm, 0.5 kg) has 6.140e-4, 6.649e-4,
7.293e-4 kg·m² in AMBF, the box of its bounds grown by 4.01 cm on every side; grown by the margin
alone, 4.4e-6, 1.18e-5, 1.61e-5, and adfkit's needle landed on the phantom and tilted 2.3° in 20 ms
where AMBF's took 140 ms. PyBullet's estimate for the same mesh
adds the margin twice (btPolyhedralConvexShape's box of its bounds, which already hold it, grown by
it again): measured on the corpus KUKA's link7 (1 kg), AMBF 6.512e-4, 6.512e-4, 1.1206e-3 kg·m²,
this estimate 6.509e-4, 6.511e-4, 1.1204e-3, PyBullet's 6.90e-4, 6.90e-4, 1.176e-3. A body of
primitives is boxed too (AMBF puts even a single primitive in a compound): the corpus LND PSM's
pitch end link, a cylinder, 0.135 kg·m² about x in AMBF and here, 0.0049 in PyBullet when its
shape is made in its centre of mass (the cylinder's own inertia); every link of that PSM within
1e-15 of AMBF's.

**Joint speed.** AMBF integrates each btRigidBody with a rotation of at most π/4 a physics step
(Bullet's ANGULAR_MOTION_THRESHOLD in btTransformUtil::integrateTransform) and caps no velocity;
PyBullet's multibody caps every joint's speed at 100 rad/s (btMultiBody's maximum coordinate
velocity). A joint whose explicit controller rings (the corpus KUKA's P 2000, D 4 efforts) is held
to ±0.05 rad about its set-point by that cap and the arm stands; in AMBF its bodies turn π/4 a step
and the arm flails. ``JOINT_SPEED_TURN`` per physics step is the speed a revolute joint may reach
here: a child turning π/4 a step against a parent at rest."""

from __future__ import annotations

import math

import numpy as np

from ..adf.paths import collision_mesh_path
from ..diagnostics import AdfError
from ..model.semantics import collision_primitives, effective_mass

#: AMBF's `collision margin` when a body gives none (afCollisionAttributes.m_margin), m
AMBF_MARGIN = 0.001
#: m, the margin a Bullet convex shape is made with (CONVEX_DISTANCE_MARGIN), which a convex
#: hull's cached bounds keep after AMBF sets the file's margin
BULLET_DEFAULT_MARGIN = 0.04
#: rad a body may turn in one physics step in AMBF's Bullet (ANGULAR_MOTION_THRESHOLD, π/4)
JOINT_SPEED_TURN = math.pi / 4


def box_inertia(mass: float, lengths) -> tuple[float, float, float]:
    """Bullet's inertia of a box of side ``lengths`` (lx, ly, lz): mass/12·(ly² + lz², ...)."""
    x2, y2, z2 = (float(v) ** 2 for v in lengths)
    k = mass / 12.0
    return (k * (y2 + z2), k * (x2 + z2), k * (x2 + y2))


def _primitive_half(prim, margin: float) -> tuple[np.ndarray, np.ndarray] | None:
    """(half extents, the shape's frame in the body frame): the bounds Bullet gives the
    primitive: its outer size (a cylinder's, capsule's or cone's along its `axis`); a cone's
    grown by twice its margin (btConeShape's bounds from its support points and margin:
    the corpus PSM's yaw link, a 2 cm cone of margin 0.1 mm, 5 kg, 3.468e-4 kg·m² in AMBF)."""
    from ..model.pose import Pose, Vec3
    from ..model.semantics import ShapeKind, shortest_arc
    from .rotations import pose_to_matrix

    g, k = prim.geometry, prim.kind
    frame = pose_to_matrix(prim.pose)
    if k is ShapeKind.BOX and None not in (g.x, g.y, g.z):
        return np.array([g.x, g.y, g.z], dtype=float) / 2.0, frame
    if k is ShapeKind.SPHERE and g.radius is not None:
        return np.full(3, float(g.radius)), frame
    if k in (ShapeKind.CYLINDER, ShapeKind.CAPSULE, ShapeKind.CONE) and None not in (g.radius, g.height):
        turn = frame @ pose_to_matrix(Pose(Vec3(), shortest_arc(Vec3(0, 0, 1), prim.axis)))
        grow = 2.0 * margin if k is ShapeKind.CONE else 0.0
        return np.array([g.radius, g.radius, g.height / 2.0], dtype=float) + grow, turn
    return None


#: kg·m², a principal moment standing for an infinite one (a body that cannot turn about that axis)
FROZEN_INERTIA = 1.0e4


def frozen_inertia(body) -> tuple[float, float, float] | None:
    """The file's `inertia` of a moving body as AMBF's Bullet plays it where a moment is 0: Bullet
    inverts only the moments that are not 0 (btRigidBody::setMassProps), so the body cannot turn
    about that axis at all, where an engine given 0 (or the floor it raises it to) turns it
    freely. Each 0 becomes FROZEN_INERTIA; None where no moment is 0, one is negative or missing,
    or the body has no mass."""
    given = body.inertia
    if given is None or None in (given.ix, given.iy, given.iz) or not body.mass or body.mass <= 0:
        return None
    moments = (float(given.ix), float(given.iy), float(given.iz))
    if min(moments) < 0 or min(moments) > 0:
        return None
    return tuple(m if m > 0 else FROZEN_INERTIA for m in moments)  # type: ignore[return-value]


def estimated_inertia(model, body, com_in_body: np.ndarray) -> tuple[float, float, float] | None:
    """The principal inertia AMBF estimates for ``body`` about its inertial frame ``com_in_body``
    (a 4x4 pose in the body frame): the box of its collision shape's bounds there, as Bullet's
    btCompoundShape gives it. None where the engine's own estimate stands: the file gives
    `inertia`, the body has no mass, no shape, a plane, or a mesh that cannot be read (the
    engine reports that)."""
    from ..geometry.meshio import load_mesh
    from ..model.semantics import CollisionMeshType, collision_mesh_type

    given = body.inertia
    if body.mass is not None and given is not None and None not in (given.ix, given.iy, given.iz):
        return None
    mass = effective_mass(body)  # without `mass` AMBF takes 1 kg and reads no `inertia` (§7.2)
    if not mass or mass <= 0:
        return None
    margin = body.collision_margin
    if isinstance(margin, bool) or not isinstance(margin, (int, float)) or not margin >= 0:
        margin = AMBF_MARGIN
    to_com = np.linalg.inv(com_in_body)
    boxes = []  # (centre, half extents, rotation) of each child's bounds, in the body frame
    prims = collision_primitives(body)
    if prims is not None:
        for prim in prims:
            half = _primitive_half(prim, float(margin))
            if half is None:
                return None  # a plane or a shape without its size: not estimated here
            boxes.append((half[1][:3, 3], half[0], half[1][:3, :3]))
    else:
        path = collision_mesh_path(model, body)
        if path is None:
            return None
        try:
            mesh = load_mesh(path, body.scale or 1.0, getattr(model, "tree", None))
        except (AdfError, ValueError):
            return None
        grow = float(margin)
        if collision_mesh_type(body.collision_mesh_type)[0] in (
            CollisionMeshType.CONVEX_HULL,
            CollisionMeshType.CONVEX_MESH,
        ):
            grow += BULLET_DEFAULT_MARGIN  # the bounds each convex shape cached (module docstring)
        lo, hi = mesh.bounds[0] - grow, mesh.bounds[1] + grow
        boxes.append(((lo + hi) / 2.0, (hi - lo) / 2.0, np.eye(3)))
    if not boxes:
        return None
    # each child's bounds carried into the inertial frame as btCompoundShape carries them
    # (btTransformAabb: the centre moved, the half extents through the rotation's absolute values)
    lows, highs = [], []
    for centre, half, rot in boxes:
        c = to_com[:3, :3] @ centre + to_com[:3, 3]
        h = np.abs(to_com[:3, :3] @ rot) @ half
        lows.append(c - h)
        highs.append(c + h)
    return box_inertia(float(mass), np.max(highs, axis=0) - np.min(lows, axis=0))


def attach_com_estimates(scene, on: bool) -> None:
    """Give every body of ``scene`` AMBF's estimated centre of mass (geometry/chai3d_com.py) as
    ``ambf_com`` where ``on`` (AMBF's bodies asked for: Options.bodies "ambf") and AMBF estimates
    it (model.semantics.com_estimated), else None: model.semantics.inertial_offset and
    collision_mesh_pose read it, so the engines put the centre of mass and the collision mesh
    where AMBF does."""
    from ..geometry.chai3d_com import body_com

    for m in scene.all_models():
        for b in m.bodies:
            b.ambf_com = body_com(m, b) if on else None
