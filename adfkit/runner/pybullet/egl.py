"""PyBullet's EGL renderer plugin: the cameras' pictures through OpenGL (a GPU, or Mesa's
multi-threaded llvmpipe) instead of the single-threaded TinyRenderer — a 640×480 RGB + depth +
segmentation frame of the suturing set in ~65 ms instead of ~220 ms on the 2-core box (MuJoCo's
renderer on a mirror of the scene, runner/mjview.py, is faster still).

The plugin must be loaded before the first body is created (it converts each visual shape as
the body is made) and, when it cannot open an EGL display, it ends the whole process instead of
failing the call. So whether it works is asked once per process in a child process
(:func:`available`), and the world loads it only when the answer is yes.

Known plugin crash (PyBullet 3.2.7), avoided by the world: a body whose only collision shape is
a PLANE and that has no visual shape segfaults when it is converted (and the plugin has no visual
plane either); such bodies get a thin slab visual of their own (:func:`plane_visual`).
"""

from __future__ import annotations

import contextlib
import ctypes
import importlib.util
import os
import subprocess
import sys

import pybullet as pb

_PROBE = r"""
import numpy as np, pybullet as pb, sys
cid = pb.connect(pb.DIRECT)
if pb.loadPlugin(sys.argv[1], "_eglRendererPlugin", physicsClientId=cid) < 0:
    sys.exit(3)
c = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[0.1, 0.1, 0.1], physicsClientId=cid)
pb.createMultiBody(0, c, -1, [0, 0, 0], physicsClientId=cid)
vm = pb.computeViewMatrix([1, 1, 1], [0, 0, 0], [0, 0, 1])
pm = pb.computeProjectionMatrixFOV(60, 1, 0.01, 10)
img = pb.getCameraImage(64, 64, vm, pm, renderer=pb.ER_BULLET_HARDWARE_OPENGL, physicsClientId=cid)
sys.exit(0 if (np.asarray(img[4]).ravel() == 0).any() else 4)
"""

_answer: tuple[bool, str] | None = None


def plugin_path() -> str | None:
    spec = importlib.util.find_spec("eglRenderer")
    return spec.origin if spec is not None and spec.origin else None


def available() -> tuple[bool, str]:
    """(usable, why not): the plugin exists and renders a box in a child process. Asked once
    per process; ``ADFKIT_EGL=0`` says no without asking."""
    global _answer
    if _answer is not None:
        return _answer
    path = plugin_path()
    if os.environ.get("ADFKIT_EGL", "").strip() == "0":
        _answer = (False, "ADFKIT_EGL=0")
    elif path is None:
        _answer = (False, "PyBullet's eglRenderer plugin is not installed")
    else:
        try:
            r = subprocess.run([sys.executable, "-c", _PROBE, path], capture_output=True, timeout=60)
            ok = r.returncode == 0
            why = "" if ok else f"the EGL renderer did not render (probe exit {r.returncode}: no EGL display?)"
        except (OSError, subprocess.TimeoutExpired) as exc:
            ok, why = False, f"the EGL probe failed: {exc}"
        _answer = (ok, why)
    return _answer


def load(cid: int) -> tuple[bool, str]:
    """Load the plugin into client ``cid`` (before its first body) when it works here:
    (loaded, why not)."""
    ok, why = available()
    if not ok:
        return False, why
    with quiet_stdout():
        loaded = pb.loadPlugin(plugin_path(), "_eglRendererPlugin", physicsClientId=cid)
    if loaded < 0:
        return False, "PyBullet refused to load the eglRenderer plugin"
    return True, ""


@contextlib.contextmanager
def quiet_stdout(discard: bool = False):
    """The plugin prints its OpenGL vendor and window messages on the process's standard output
    (C stdio); while it runs, file descriptor 1 goes to standard error, so that ``--json``
    output and pipes stay clean. ``discard``: to /dev/null instead (what PyBullet prints is
    said once by adfkit's own located warning)."""
    try:
        sys.stdout.flush()
        saved = os.dup(1)
        target = os.open(os.devnull, os.O_WRONLY) if discard else 2
    except (OSError, ValueError, AttributeError):
        yield
        return
    try:
        os.dup2(target, 1)
        yield
    finally:
        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None).fflush(None)
        os.dup2(saved, 1)
        os.close(saved)
        if discard:
            os.close(target)


def plane_visual(cid: int, normal, offset: float, half: float = 50.0) -> int:
    """A visual for a body whose only collision shape is a PLANE (see the module note): a thin
    square slab, 2·``half`` m wide, on the plane (the plugin has no visual plane either)."""
    import numpy as np

    n = np.asarray(normal, dtype=float)
    n = n / (np.linalg.norm(n) or 1.0)
    axis = np.cross([0.0, 0.0, 1.0], n)
    s, c = float(np.linalg.norm(axis)), float(n[2])
    if s < 1e-9:
        quat = [0.0, 0.0, 0.0, 1.0] if c > 0 else [1.0, 0.0, 0.0, 0.0]
    else:
        half_angle = 0.5 * np.arctan2(s, c)
        quat = [*(axis / s * np.sin(half_angle)), float(np.cos(half_angle))]
    thick = 5e-4
    centre = n * (offset - thick)
    return pb.createVisualShape(
        pb.GEOM_BOX,
        halfExtents=[half, half, thick],
        visualFramePosition=centre.tolist(),
        visualFrameOrientation=[float(q) for q in quat],
        physicsClientId=cid,
    )


def flag(renderer: str) -> int:
    return pb.ER_BULLET_HARDWARE_OPENGL if renderer == "egl" else pb.ER_TINY_RENDERER
