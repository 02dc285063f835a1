"""Play an ADF scene. One engine-neutral core (the :class:`World` interface in world.py, the
scene resolved once in plan.py and springs.py, cameras, grasping, stability, options) and two
back ends of the same layout, ``pybullet/`` (the reference runner) and ``mujoco/``, each
translating the plan into its engine; :func:`open_world` opens either."""

from __future__ import annotations

from .engines import ENGINES, open_world
from .options import Options
from .world import World

__all__ = ["ENGINES", "Options", "World", "open_world", "PyBulletWorld", "MujocoWorld", "PSM", "PSMModelError"]


def __getattr__(name):
    if name == "PyBulletWorld":
        from .pybullet.world import PyBulletWorld

        return PyBulletWorld
    if name == "MujocoWorld":
        from .mujoco.world import MujocoWorld

        return MujocoWorld
    if name in ("PSM", "PSMModelError"):
        from . import psm

        return getattr(psm, name)
    raise AttributeError(name)
