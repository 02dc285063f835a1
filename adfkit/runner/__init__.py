"""PyBullet reference runner: play an ADF scene (the only package that imports pybullet)."""
from __future__ import annotations


def __getattr__(name):
    if name in ("SimWorld", "Options"):
        from . import world
        return getattr(world, name)
    if name in ("PSM", "PSMModelError"):
        from . import psm
        return getattr(psm, name)
    raise AttributeError(name)
