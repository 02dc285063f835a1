"""Open a world on either engine: the one place that knows both back ends (neither imports the
other). A PyBullet world is given the MuJoCo mirror here, so its cameras can be drawn by
MuJoCo's renderer (``renderer="mujoco"``/``"auto"``)."""

from __future__ import annotations

from .options import Options

ENGINES = ("pybullet", "mujoco")


def _mujoco_mirror(world):
    from .mujoco.mirror import MjMirror

    return MjMirror(world)


def open_world(scene, options: Options | None = None, gui: bool = False, engine: str = "pybullet", **kw):
    """The scene built in ``engine`` ("pybullet", the reference runner, or "mujoco"), ready to step.
    ``kw``: the engine's own options (MuJoCo: ``sleep``)."""
    if engine == "pybullet":
        from .pybullet.world import PyBulletWorld

        return PyBulletWorld(scene, options, gui, mirror=_mujoco_mirror, **kw)
    if engine == "mujoco":
        from .mujoco.world import MujocoWorld

        return MujocoWorld(scene, options, gui, **kw)
    raise ValueError(f"engine {engine!r} is not one of {', '.join(ENGINES)}")
