"""The PyBullet world's cameras drawn (runner/cameras.py says where they look): by
TinyRenderer, PyBullet's EGL plugin (egl.py) or, given a mirror, MuJoCo's renderer on a copy of
the scene (runner/mujoco/mirror.py) — :func:`choose_renderer` picks."""

from __future__ import annotations

import contextlib
import math

import numpy as np
import pybullet as pb

from . import egl


def render(world, cam, rgb_only: bool = False) -> dict:
    """``cam`` (a runner.cameras.Camera) drawn now: RGB, linear depth and body-index segmentation
    (with ``rgb_only``: RGB alone)."""
    if world.renderer == "mujoco":
        try:
            return world.mj_view().render(cam, rgb_only)
        except Exception as exc:  # noqa: BLE001 - another engine's build: whatever stops it, PyBullet's own renderer draws
            # MuJoCo could not build the scene or open a GL context: the frame from TinyRenderer
            world.fall_back_to_tiny(f"{type(exc).__name__}: {exc}")
    world.place_ghosts()
    eye, target, up = cam.view(world)
    vm = pb.computeViewMatrix(eye, target, up, physicsClientId=world.cid)
    pm = pb.computeProjectionMatrixFOV(
        math.degrees(cam.fov), cam.width / cam.height, cam.near, cam.far, physicsClientId=world.cid
    )
    with egl.quiet_stdout() if world.renderer == "egl" else contextlib.nullcontext():
        _, _, rgba, zbuf, seg = pb.getCameraImage(
            cam.width,
            cam.height,
            vm,
            pm,
            renderer=egl.flag(world.renderer),
            flags=pb.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX,
            shadow=0,
            physicsClientId=world.cid,
        )
    rgb = np.reshape(np.asarray(rgba, dtype=np.uint8), (cam.height, cam.width, 4))[:, :, :3]
    if rgb_only:
        return {"rgb": rgb}
    z = np.reshape(np.asarray(zbuf, dtype=np.float64), (cam.height, cam.width))
    n, f = cam.near, cam.far
    depth = (f * n / (f - (f - n) * z)).astype(np.float32)  # linearised z-buffer
    depth[z >= 1.0] = np.inf
    seg = np.reshape(np.asarray(seg, dtype=np.int64), (cam.height, cam.width))
    return {"rgb": rgb, "depth": depth, "segmentation": label_image(world, seg)}


RENDERERS = ("auto", "mujoco", "egl", "tiny")


def choose_renderer(
    wanted: str, cid: int, has_cameras: bool, soft: bool, gui: bool, mirror: bool = True
) -> tuple[str, str]:
    """Who draws the PyBullet world's cameras: ("mujoco" | "egl" | "tiny", why not the one wanted).

    ``tiny``: PyBullet's TinyRenderer (CPU, nothing to set up: best for a frame or two).
    ``mujoco``: the scene mirrored into MuJoCo and drawn by its OpenGL renderer (runner/mujoco/mirror.py;
    ~1 s to build on the first picture, then ~15x faster frames). ``egl``: PyBullet's EGL plugin
    (pybullet/egl.py; loaded now, before the first body). ``auto``: for a scene with cameras,
    mujoco where MuJoCo has a headless OpenGL (and the world was given the mirror), else egl where it works, else tiny.
    Soft bodies are drawn by TinyRenderer only (neither other renderer draws deformables)."""
    if wanted not in RENDERERS:
        raise ValueError(f"renderer {wanted!r} is not one of {', '.join(RENDERERS)}")
    if wanted == "tiny" or gui:
        return "tiny", ""
    if soft:
        return "tiny", "soft bodies are drawn by TinyRenderer only"
    if wanted == "auto" and not has_cameras:
        return "tiny", ""
    notes = []
    if wanted in ("mujoco", "auto") and not mirror:
        notes.append("MuJoCo's renderer: no mirror was given to this world (open it with runner.open_world)")
    elif wanted in ("mujoco", "auto"):
        from ..glcontext import gl_context_class

        cls, why = gl_context_class()
        if cls is not None:
            return "mujoco", ""
        notes.append(f"MuJoCo's renderer: no headless OpenGL ({why})")
    if wanted in ("egl", "auto"):
        ok, why = egl.load(cid)
        if ok:
            return "egl", ""
        notes.append(f"EGL: {why}")
    return "tiny", "; ".join(notes)


def label_table(world) -> np.ndarray:
    """[uid, link + 1] -> index of the body in ``world.bodies`` (-1: none), built once per body
    count: a segmentation image is then labelled by one numpy lookup. Soft bodies follow the
    bodies: soft body k of the report's ``soft_bodies`` is label ``len(world.bodies) + k``."""
    bodies = world.bodies
    soft = list(getattr(getattr(world, "soft", None), "items", []) or [])
    cached = getattr(world, "_seg_label_table", None)
    if cached is not None and cached[0] == (len(bodies), len(soft)):
        return cached[1]
    ids = [(sb.uid, link, i) for i, sb in enumerate(bodies) if sb.uid is not None and sb.uid >= 0 for link in sb.links]
    ids += [(s.uid, -1, len(bodies) + k) for k, s in enumerate(soft) if s.uid is not None and s.uid >= 0]
    if ids:
        uids, links, index = (np.array(c) for c in zip(*ids))
        table = np.full((uids.max() + 1, links.max() + 2), -1, dtype=np.int32)
        table[uids, links + 1] = index  # as a dict would: the last body of a (uid, link) wins
    else:
        table = np.full((1, 1), -1, dtype=np.int32)
    world._seg_label_table = ((len(bodies), len(soft)), table)
    return table


def label_image(world, seg: np.ndarray) -> np.ndarray:
    """PyBullet's object-and-link segmentation (uid + (link + 1) << 24, -1 for none) as body
    indices (-1 for the background, ghosts and anything that is not a body)."""
    table = label_table(world)
    valid = seg >= 0
    uid = np.where(valid, seg & ((1 << 24) - 1), 0)
    link1 = np.where(valid, seg >> 24, 0)
    inside = valid & (uid < table.shape[0]) & (link1 < table.shape[1])
    labels = np.full(seg.shape, -1, dtype=np.int32)
    labels[inside] = table[uid[inside], link1[inside]]
    return labels
