"""PyBullet reference runner: play an ADF scene (the only package that imports pybullet)."""
from __future__ import annotations


def __getattr__(name):
    if name in ("SimWorld", "Options"):
        from . import world
        return getattr(world, name)
    raise AttributeError(name)
