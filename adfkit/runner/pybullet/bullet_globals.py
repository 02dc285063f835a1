"""Bullet's contact breaking threshold, which is one per process, not one per world.

PyBullet keeps a world per client, but the threshold is a global of the library
(``gContactBreakingThreshold``, btPersistentManifold.cpp): setPhysicsEngineParameter(
contactBreakingThreshold=...) on any client sets it for every world in the process. A world reads
it whenever it detects collisions (each step's AABBs grow by it, a contact manifold made then keeps
it). A world that left it alone played with the value the last world had set: a box dropped on a
slab came to rest 1.1 mm elsewhere in a process where a world with Options(contact_threshold=0.001)
had been made before (tests/test_world_globals.py), so a test could pass alone and fail after
another.

So each world puts its own value in force (Bullet's 0.02 m where Options.contact_threshold is None)
before it steps, restores a snapshot or runs a collision pass (the ghosts' own world, ghost_pass.py,
with its dynamics world's value): a call of ~3 us, against a control step's milliseconds."""

from __future__ import annotations

import pybullet as pb

from . import broadphase_margin

#: Bullet's own default (btPersistentManifold.cpp), which PyBullet leaves as it is
DEFAULT = 0.02


def threshold(opt) -> float:
    """The contact breaking threshold a world with Options ``opt`` plays with, m."""
    return DEFAULT if opt.contact_threshold is None else float(opt.contact_threshold)


def use(value: float, cid: int, margin: float | None = None) -> None:
    """Put ``value`` in force for every world of the process (set through client ``cid``), and
    the broadphase's ``margin`` where given (broadphase_margin.py: also one per process)."""
    pb.setPhysicsEngineParameter(contactBreakingThreshold=value, physicsClientId=cid)
    if margin is not None:
        broadphase_margin.use(margin)
