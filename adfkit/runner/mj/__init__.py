"""MuJoCo engine for `adfkit run --engine mujoco`: MjWorld answers SimWorld's public API."""

from __future__ import annotations


def __getattr__(name):
    if name == "MjWorld":
        from .world import MjWorld

        return MjWorld
    raise AttributeError(name)
