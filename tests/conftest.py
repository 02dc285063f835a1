"""Shared fixtures. The public ADF corpus lives in ../shared/corpus (never copied here);
tests that need it skip with a clear reason when it is absent."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CORPUS = Path(os.environ.get("ADFKIT_CORPUS", ROOT.parent / "shared" / "corpus")).resolve()
SKIP_CORPUS = "the public ADF corpus (../shared/corpus) is not present beside this checkout"


def corpus_files(pattern: str = "**/*.yaml") -> list[Path]:
    """Corpus files for parametrisation (empty list when the corpus is absent)."""
    if not CORPUS.is_dir():
        return []
    return sorted(p for p in CORPUS.glob(pattern) if p.is_file())


def corpus_id(p: Path) -> str:
    return str(p.relative_to(CORPUS))


@pytest.fixture(scope="session")
def corpus() -> Path:
    if not CORPUS.is_dir():
        pytest.skip(SKIP_CORPUS)
    return CORPUS


def require_corpus() -> None:
    if not CORPUS.is_dir():
        pytest.skip(SKIP_CORPUS)


def require_renderer(name: str) -> str:
    """Skip, with the reason, when renderer ``name`` of the PyBullet world's cameras
    (runner/cameras.choose_renderer) cannot start here; returns the name."""
    import pytest

    if name == "egl":
        from adfkit.runner.pybullet import egl

        ok, why = egl.available()
        if not ok:
            pytest.skip(f"PyBullet's EGL renderer does not work here: {why}")
    if name == "mujoco":
        from adfkit.runner.glcontext import gl_context_class

        cls, why = gl_context_class()
        if cls is None:
            pytest.skip(f"MuJoCo has no headless OpenGL here: {why}")
    return name


def box_camera_model(mass: float = 0.0, z: float = 0.0, rgb=(0.9, 0.2, 0.1)) -> str:
    """A 0.2 m box at height ``z`` and a 64x48 camera 1 m away on +x looking at its centre."""
    r, g, b = rgb
    return f"""
bodies: [BODY box]
cameras: [CAMERA cam]
BODY box:
  name: box
  mass: {mass}
  inertia: {{ix: 1.0e-3, iy: 1.0e-3, iz: 1.0e-3}}
  location: {{position: {{x: 0.0, y: 0.0, z: {z}}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
  collision shape: BOX
  collision geometry: {{x: 0.2, y: 0.2, z: 0.2}}
  shape: BOX
  geometry: {{x: 0.2, y: 0.2, z: 0.2}}
  color rgba: {{r: {r}, g: {g}, b: {b}, a: 1.0}}
CAMERA cam:
  name: cam
  location: {{x: 1.0, y: 0.0, z: {z}}}
  look at: {{x: 0.0, y: 0.0, z: {z}}}
  up: {{x: 0.0, y: 0.0, z: 1.0}}
  clipping plane: {{near: 0.01, far: 10.0}}
  field view angle: 0.7
  publish image resolution: {{width: 64, height: 48}}
"""


@pytest.fixture(scope="module")
def addon():
    """The Blender add-on loaded into the headless ``bpy`` (once per test module)."""
    pytest.importorskip("bpy")
    from adfkit.commands.blend_import import load_addon

    _, mod = load_addon()
    return mod


@pytest.fixture()
def scene(addon):
    """A fresh, empty Blender scene."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.context.scene
