"""Cameras (adf-format.md §9): RGB, depth in metres along the optical axis, per-body
segmentation, pinhole intrinsics, rendered headless by the renderer the world chose
(:func:`choose_renderer`): TinyRenderer, PyBullet's EGL plugin (runner/egl.py) or MuJoCo's
renderer on a mirror of the scene (runner/mjview.py)."""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass

import numpy as np
import pybullet as pb

from ..model.semantics import DEFAULT_CAMERA_FAR, DEFAULT_CAMERA_FOV, DEFAULT_CAMERA_NEAR, DEFAULT_IMAGE_SIZE
from . import egl
from .names import merge_namespace


@dataclass(eq=False)
class SimCamera:
    name: str
    key: str
    camera: object
    parent: object  # SimBody or None
    eye: np.ndarray  # in the parent body frame (or world)
    target: np.ndarray
    up: np.ndarray
    fov: float  # vertical, rad
    near: float
    far: float
    width: int
    height: int
    eye_offset: float = 0.0  # along the image's right axis (stereo eyes)

    def intrinsics(self) -> np.ndarray:
        fy = (self.height / 2) / math.tan(self.fov / 2)
        return np.array([[fy, 0, self.width / 2], [0, fy, self.height / 2], [0, 0, 1.0]])

    def view(self, world) -> tuple[list, list, list]:
        if self.parent is not None:
            t = self.parent.world_matrix()
            r, p = t[:3, :3], t[:3, 3]
        else:
            r, p = np.eye(3), np.zeros(3)
        eye, target, up = r @ self.eye + p, r @ self.target + p, r @ self.up
        if self.eye_offset:
            fwd = target - eye
            right = np.cross(fwd, up)
            right /= np.linalg.norm(right) or 1.0
            eye, target = eye + self.eye_offset * right, target + self.eye_offset * right
        return eye.tolist(), target.tolist(), up.tolist()

    def render(self, world) -> dict:
        """{'rgb': H×W×3 uint8, 'depth': H×W float32 m, 'segmentation': H×W int32 (body index, -1 none)}."""
        if world.renderer == "mujoco":
            try:
                return world.mj_view().render(self)
            except Exception as exc:  # noqa: BLE001 - another engine's build: whatever stops it, PyBullet's own renderer draws
                # MuJoCo could not build the scene or open a GL context: the frame from TinyRenderer
                world.fall_back_to_tiny(f"{type(exc).__name__}: {exc}")
        world.place_ghosts()
        eye, target, up = self.view(world)
        vm = pb.computeViewMatrix(eye, target, up, physicsClientId=world.cid)
        pm = pb.computeProjectionMatrixFOV(
            math.degrees(self.fov), self.width / self.height, self.near, self.far, physicsClientId=world.cid
        )
        with egl.quiet_stdout() if world.renderer == "egl" else contextlib.nullcontext():
            _, _, rgba, zbuf, seg = pb.getCameraImage(
                self.width,
                self.height,
                vm,
                pm,
                renderer=egl.flag(world.renderer),
                flags=pb.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX,
                shadow=0,
                physicsClientId=world.cid,
            )
        rgb = np.reshape(np.asarray(rgba, dtype=np.uint8), (self.height, self.width, 4))[:, :, :3]
        z = np.reshape(np.asarray(zbuf, dtype=np.float64), (self.height, self.width))
        n, f = self.near, self.far
        depth = (f * n / (f - (f - n) * z)).astype(np.float32)  # linearised z-buffer
        depth[z >= 1.0] = np.inf
        seg = np.reshape(np.asarray(seg, dtype=np.int64), (self.height, self.width))
        return {"rgb": rgb, "depth": depth, "segmentation": label_image(world, seg)}


RENDERERS = ("auto", "mujoco", "egl", "tiny")


def choose_renderer(wanted: str, cid: int, has_cameras: bool, soft: bool, gui: bool) -> tuple[str, str]:
    """Who draws the PyBullet world's cameras: ("mujoco" | "egl" | "tiny", why not the one wanted).

    ``tiny``: PyBullet's TinyRenderer (CPU, nothing to set up: best for a frame or two).
    ``mujoco``: the scene mirrored into MuJoCo and drawn by its OpenGL renderer (runner/mjview.py;
    ~1 s to build on the first picture, then ~15x faster frames). ``egl``: PyBullet's EGL plugin
    (runner/egl.py; loaded now, before the first body). ``auto``: for a scene with cameras,
    mujoco where MuJoCo has a headless OpenGL, else egl where it works, else tiny.
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
    if wanted in ("mujoco", "auto"):
        from .glcontext import gl_context_class

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
    ids = [(sb.uid, sb.link, i) for i, sb in enumerate(bodies) if sb.uid is not None and sb.uid >= 0]
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


def _camera(world, cam, ns: str) -> list[SimCamera]:
    parent = None
    if cam.parent:
        key, hit = world.registry.find(cam.parent)
        if key is None or hit is None:
            world._warn("runner-camera", f"{cam.identifier}: parent {cam.parent!r} is not a body; camera skipped", cam)
            return []
        parent = hit
    loc = np.array(cam.location or (0, 0, 0), float)
    look = np.array(cam.look_at or (0, 0, 0), float)
    up = np.array(cam.up or (0, 0, 1), float)
    if np.allclose(loc, look) or np.linalg.norm(np.cross(look - loc, up)) < 1e-12:
        world._warn("runner-camera", f"{cam.identifier}: look at equals location or up is parallel to the view", cam)
    clip = cam.clipping_plane
    near = clip.near if clip is not None and clip.near is not None else DEFAULT_CAMERA_NEAR
    far = clip.far if clip is not None and clip.far is not None else DEFAULT_CAMERA_FAR
    res = cam.publish_image_resolution
    w = int(res.width) if res is not None and res.width else DEFAULT_IMAGE_SIZE[0]
    h = int(res.height) if res is not None and res.height else DEFAULT_IMAGE_SIZE[1]
    fov = cam.field_view_angle if cam.field_view_angle is not None else DEFAULT_CAMERA_FOV
    name = cam.name or cam.identifier
    key = merge_namespace(ns, cam.namespace) + cam.identifier
    base = SimCamera(name, key, cam, parent, loc, look, up, fov, near, far, w, h)
    if cam.stereo is None:
        return [base]
    sep = cam.stereo.eye_separation if cam.stereo.eye_separation is not None else 0.2
    return [
        SimCamera(name + "_left", key, cam, parent, loc, look, up, fov, near, far, w, h, -sep / 2),
        SimCamera(name + "_right", key, cam, parent, loc, look, up, fov, near, far, w, h, sep / 2),
    ]


def build_cameras(world) -> list[SimCamera]:
    out = []
    w = world.scene.world
    if w is not None:
        for cam in w.cameras:
            out += _camera(world, cam, w.namespace or "")
    for m in world.scene.all_models():
        for cam in m.cameras:
            out += _camera(world, cam, m.namespace or "")
    return out


def save_frames(world, out_dir, size_limit: int | None = None) -> list[str]:
    """Write <camera>_rgb.png, <camera>_depth.npy, <camera>_seg.npy (+ _seg.png) for every camera."""
    from pathlib import Path

    from PIL import Image

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for cam in world.cameras:
        frame = cam.render(world)
        stem = cam.name.replace("/", "_")
        Image.fromarray(frame["rgb"]).save(out / f"{stem}_rgb.png")
        np.save(out / f"{stem}_depth.npy", frame["depth"])
        np.save(out / f"{stem}_seg.npy", frame["segmentation"])
        from ..dataset.colors import colourise  # every body its own colour (was grey, nearly black)

        Image.fromarray(colourise(frame["segmentation"])).save(out / f"{stem}_seg.png")
        written += [f"{stem}_rgb.png", f"{stem}_depth.npy", f"{stem}_seg.npy", f"{stem}_seg.png"]
    return written
