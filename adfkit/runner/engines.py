"""Open a world on either engine: the one place that knows both back ends (neither imports the
other). A PyBullet world is given the MuJoCo mirror here, so its cameras can be drawn by
MuJoCo's renderer (``renderer="mujoco"``/``"auto"``)."""

from __future__ import annotations

from .options import Options

ENGINES = ("pybullet", "mujoco")


def _mujoco_mirror(world):
    from .mujoco.mirror import MjMirror

    return MjMirror(world)


def camera_recording(world, cam, video_path=None, fps: float = 5.0, gif_width: int = 320, process: bool = True):
    """The pictures of ``cam`` over an episode (runner/recording.py's interface): drawn in a
    process of its own beside the physics where MuJoCo's renderer draws them (the MuJoCo engine,
    or a PyBullet world with the MuJoCo mirror: its rigid bodies' poses are all the mirror needs
    to know each frame, and the pictures are the same pixel for pixel), else between the steps
    here."""
    from .recording import CameraRecording

    mirrored = world.engine == "mujoco" or world.renderer == "mujoco"
    if process and mirrored and not _deforms(world):
        from .mujoco.recorder import MirrorRecording

        return MirrorRecording(world, cam, video_path, fps, gif_width)
    return CameraRecording(world, cam, video_path, fps, gif_width)


def _deforms(world) -> bool:
    """The world has shapes that change between frames (soft bodies, drilled volumes), which the
    mirror in another process would not see."""
    scene = world.scene
    return bool(getattr(world, "volumes", None)) or any(getattr(m, "soft_bodies", None) for m in scene.all_models())


def open_world(scene, options: Options | None = None, gui: bool = False, engine: str = "pybullet", **kw):
    """The scene built in ``engine`` ("pybullet", the reference runner, or "mujoco"), ready to step.
    ``kw``: the engine's own options (MuJoCo: ``sleep``)."""
    from .ambf_bodies import attach_com_estimates

    attach_com_estimates(scene, options is not None and options.bodies == "ambf")
    if engine == "pybullet":
        from .pybullet.world import PyBulletWorld

        return PyBulletWorld(scene, options, gui, mirror=_mujoco_mirror, **kw)
    if engine == "mujoco":
        from .mujoco.world import MujocoWorld

        return MujocoWorld(scene, options, gui, **kw)
    raise ValueError(f"engine {engine!r} is not one of {', '.join(ENGINES)}")
