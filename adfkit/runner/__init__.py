"""Play an ADF scene: the PyBullet reference runner (SimWorld; the only package that imports
pybullet) and the MuJoCo engine (MjWorld, runner/mj/), behind one public API."""

from __future__ import annotations


def __getattr__(name):
    if name in ("SimWorld", "Options"):
        from . import world

        return getattr(world, name)
    if name == "MjWorld":
        from .mj.world import MjWorld

        return MjWorld
    if name in ("PSM", "PSMModelError"):
        from . import psm

        return getattr(psm, name)
    raise AttributeError(name)
