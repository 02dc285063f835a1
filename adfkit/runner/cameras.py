"""Cameras (adf-format.md §9), the same for every engine: where each ADF camera (two for a
stereo pair) looks from, its intrinsics and image size, resolved once from the scene; RGB,
depth in metres along the optical axis and per-body segmentation come from the engine's
renderer (``world.render_camera``: runner/pybullet/cameras.py, runner/mujoco/render.py)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.semantics import DEFAULT_CAMERA_FAR, DEFAULT_CAMERA_FOV, DEFAULT_CAMERA_NEAR, DEFAULT_IMAGE_SIZE
from .names import merge_namespace


@dataclass(eq=False)
class Camera:
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

    def render(self, world, rgb_only: bool = False) -> dict:
        """{'rgb': H×W×3 uint8, 'depth': H×W float32 m, 'segmentation': H×W int32 (body index, -1 none)},
        drawn by the engine's renderer (``world.render_camera``); with ``rgb_only`` only 'rgb'
        (one pass instead of two where the renderer draws segmentation separately)."""
        return world.render_camera(self, rgb_only)


def _camera(world, cam, ns: str) -> list[Camera]:
    from .frames import resolve_frame

    loc = np.array(cam.location or (0, 0, 0), float)
    look = np.array(cam.look_at or (0, 0, 0), float)
    up = np.array(cam.up or (0, 0, 1), float)
    if np.allclose(loc, look) or np.linalg.norm(np.cross(look - loc, up)) < 1e-12:
        world._warn("runner-camera", f"{cam.identifier}: look at equals location or up is parallel to the view", cam)
    # a parent body, or a parent camera (AMBF's stereoL under main_camera): the view in the
    # frame of the body at the root of its parents (None: the world)
    parent, t = resolve_frame(world, cam.parent, ns, cam)
    r, p = t[:3, :3], t[:3, 3]
    loc, look, up = r @ loc + p, r @ look + p, r @ up
    clip = cam.clipping_plane
    near = clip.near if clip is not None and clip.near is not None else DEFAULT_CAMERA_NEAR
    far = clip.far if clip is not None and clip.far is not None else DEFAULT_CAMERA_FAR
    res = cam.publish_image_resolution
    w = int(res.width) if res is not None and res.width else DEFAULT_IMAGE_SIZE[0]
    h = int(res.height) if res is not None and res.height else DEFAULT_IMAGE_SIZE[1]
    fov = cam.field_view_angle if cam.field_view_angle is not None else DEFAULT_CAMERA_FOV
    name = cam.name or cam.identifier
    key = merge_namespace(ns, cam.namespace) + cam.identifier
    base = Camera(name, key, cam, parent, loc, look, up, fov, near, far, w, h)
    if cam.stereo is None:
        return [base]
    sep = cam.stereo.eye_separation if cam.stereo.eye_separation is not None else 0.2
    return [
        Camera(name + "_left", key, cam, parent, loc, look, up, fov, near, far, w, h, -sep / 2),
        Camera(name + "_right", key, cam, parent, loc, look, up, fov, near, far, w, h, sep / 2),
    ]


def build_cameras(world) -> list[Camera]:
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
