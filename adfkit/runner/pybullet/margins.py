"""Each collision shape gets its file's `collision margin` (adf-format.md §7.4), as AMBF sets it
on every hull and primitive it makes (afShapeUtils::createCollisionShape calls setMargin on each
child of a body's compound).

Why this needs a detour: PyBullet creates every shape with a 1 mm margin
(PhysicsServerCommandProcessor's m_defaultCollisionMargin, which no command changes), and a convex
hull's margin lies outside it: Bullet collides the hull grown by its margin. For a body of
several hulls that is the corpus suturing set's needle (nine hulls 0.83-0.98 mm thick, each
colliding as if 2.8-3 mm thick) against its phantom's blocks and slab (grown by 1 mm each): the
needle met the channel's side 0.5 mm and its floor 0.1 mm before the files' 0.1 mm margins
would let it, and was forced through with up to 130 N. ``changeDynamics(collisionMargin=...)``
sets the collision shape of a maximal-coordinate body, which for several hulls is their compound,
whose own margin no child uses; on a multibody's base it sets every child of the compound too
(PhysicsServerCommandProcessor, CHANGE_DYNAMICS_INFO_SET_COLLISION_MARGIN). The children are the
shape's own objects, shared by every body made from the shape: a fixed multibody made from it,
given the margin and removed again, leaves them with the margin for the body made next.

A box's and a cylinder's margin lie inside them (Bullet keeps their outer size) and a sphere's
or a capsule's is their radius, so for those the margin changes only how round the edges are;
a hull's changes its size, which is what the file's margin is for.
"""

from __future__ import annotations

import math

import pybullet as pb

#: m, the margin PyBullet gives every shape it creates, and AMBF's default `collision margin`
PYBULLET_MARGIN = 0.001


def file_margin(obj) -> float | None:
    """The object's `collision margin` when it is one PyBullet must be told (a finite value
    >= 0 other than PyBullet's own 1 mm), else None."""
    m = getattr(obj, "collision_margin", None)
    if isinstance(m, bool) or not isinstance(m, (int, float)) or not math.isfinite(m) or m < 0:
        return None
    return None if abs(m - PYBULLET_MARGIN) < 1e-12 else float(m)


def give_margin(col: int, margin: float | None, cid: int) -> None:
    """Every child of collision shape ``col`` gets ``margin`` (None: PyBullet's 1 mm stays).
    Call it before a body is made from the shape, so that the body's compound sizes its
    children with their margins."""
    if col < 0 or margin is None:
        return
    probe = pb.createMultiBody(0.0, col, -1, [0.0, 0.0, 0.0], physicsClientId=cid)
    try:
        pb.changeDynamics(probe, -1, collisionMargin=margin, physicsClientId=cid)
    finally:
        pb.removeBody(probe, physicsClientId=cid)
