"""Who draws the PyBullet world's cameras (cameras.choose_renderer): PyBullet's EGL plugin
(runner/egl.py) and MuJoCo's renderer on a mirror of the scene (runner/mjview.py) give the same
pictures as TinyRenderer; the EGL plugin's known crash is avoided and its chatter kept off
standard output. Each skips where its OpenGL cannot start here."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from conftest import require_renderer

from adfkit.adf import load_scene
from adfkit.runner import Options, open_world

ROOT = Path(__file__).resolve().parent.parent


PLANE_AND_CAMERA = """
bodies: [BODY floor, BODY box]
cameras: [CAMERA cam]
BODY floor:
  name: floor
  mass: 0.0
  location: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: PLANE
  collision geometry: {normal: {x: 0.0, y: 0.0, z: 1.0}, offset: 0.0}
BODY box:
  name: box
  mass: 1.0
  inertia: {ix: 0.01, iy: 0.01, iz: 0.01}
  location: {position: {x: 0.0, y: 0.0, z: 0.05}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 0.1, y: 0.1, z: 0.1}
CAMERA cam:
  name: cam
  location: {x: 0.0, y: 0.0, z: 1.0}
  look at: {x: 0.0, y: 0.0, z: -1.0}
  up: {x: 0.0, y: 1.0, z: 0.0}
  clipping plane: {near: 0.01, far: 10.0}
  field view angle: 0.8
  publish image resolution: {width: 64, height: 48}
"""


@pytest.mark.parametrize("renderer", ["egl", "mujoco"])
def test_lone_plane_without_visual_renders_and_stdout_stays_clean(tmp_path, renderer):
    """A PLANE-only body with no visual segfaults PyBullet 3.2.7's EGL plugin; the runner gives
    it a slab visual. Run in a child process: a crash must fail this test, not end the run."""
    require_renderer(renderer)
    model = tmp_path / "model.yaml"
    model.write_text(textwrap.dedent(PLANE_AND_CAMERA))
    out = tmp_path / "run"
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "adfkit",
            "run",
            str(model),
            "--seconds",
            "0.05",
            "--renderer",
            renderer,
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr[-2000:]
    assert "GL_VENDOR" not in r.stdout and "EGL" not in r.stdout  # the plugin's chatter went to stderr
    report = json.loads((out / "report.json").read_text())
    assert report["renderer"] == renderer
    seg = np.load(out / "cam_seg.npy")
    depth = np.load(out / "cam_depth.npy")
    assert seg[24, 32] == 1  # the box (body index 1) under the camera
    assert abs(float(depth[24, 32]) - 0.9) < 2e-3  # its top face 0.9 m below the camera
    if renderer == "egl":  # (the MJCF writer has no PLANE on a body: MuJoCo draws only its own ground there)
        assert seg[0, 0] == 0 and abs(float(depth[0, 0]) - 1.0) < 2e-3  # the floor (depth along the optical axis)


@pytest.mark.parametrize("renderer", ["egl", "mujoco"])
def test_renderer_agrees_with_tinyrenderer_on_the_suturing_pad(renderer):
    require_renderer(renderer)
    scene = load_scene(ROOT / "sample_scenes" / "suturing_pad" / "launch.yaml")
    frames = {}
    for name in (renderer, "tiny"):
        world = open_world(scene, Options(renderer=name))
        try:
            assert world.renderer == name and world.cameras
            world.run(0.05)
            frames[name] = [c.render(world) for c in world.cameras]
        finally:
            world.close()
    (a_frames, b_frames) = frames.values()
    for a, b in zip(a_frames, b_frames):
        assert (a["segmentation"] == b["segmentation"]).mean() > 0.97
        # the same bodies in view (MuJoCo draws a plane to the horizon, PyBullet a finite one: -1 may differ)
        assert set(np.unique(a["segmentation"])) - {-1} == set(np.unique(b["segmentation"])) - {-1}
        both = np.isfinite(a["depth"]) & np.isfinite(b["depth"])
        assert (np.isfinite(a["depth"]) == np.isfinite(b["depth"])).mean() > 0.97
        assert np.median(np.abs(a["depth"][both] - b["depth"][both])) < 1e-3


def test_mujoco_renderer_draws_a_resized_copy_of_a_camera():
    """The Gymnasium environments render copies of the scene's cameras at their own size."""
    from dataclasses import replace

    require_renderer("mujoco")
    world = open_world(load_scene(ROOT / "sample_scenes" / "suturing_pad" / "launch.yaml"), Options(renderer="mujoco"))
    try:
        full = world.cameras[0].render(world)
        small = replace(world.cameras[0], width=64, height=48).render(world)
        assert world.renderer == "mujoco" and not [d for d in world.diagnostics if d.rule == "runner-renderer"]
        assert small["rgb"].shape == (48, 64, 3) and full["rgb"].shape[:2] == (
            world.cameras[0].height,
            world.cameras[0].width,
        )
        # the same view: the centre pixel sees the same body at the same depth
        h, w = full["segmentation"].shape
        assert small["segmentation"][24, 32] == full["segmentation"][h // 2, w // 2]
        assert abs(float(small["depth"][24, 32]) - float(full["depth"][h // 2, w // 2])) < 5e-3
    finally:
        world.close()


@pytest.mark.parametrize("renderer", ["tiny", "mujoco"])
def test_a_picture_alone_is_the_same_rgb_in_one_pass(renderer):
    """``rgb_only`` (the suture's video and GIF frames) gives the full frame's RGB, bit for bit,
    and nothing else."""
    require_renderer(renderer)
    world = open_world(load_scene(ROOT / "sample_scenes" / "suturing_pad" / "launch.yaml"), Options(renderer=renderer))
    try:
        world.run(0.02)
        cam = world.cameras[0]
        full, picture = cam.render(world), cam.render(world, rgb_only=True)
        assert set(picture) == {"rgb"}
        assert picture["rgb"].shape == full["rgb"].shape and np.array_equal(picture["rgb"], full["rgb"])
        assert picture["rgb"].std() > 5  # a picture, not a blank
    finally:
        world.close()
