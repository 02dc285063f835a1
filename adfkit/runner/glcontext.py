"""Which headless OpenGL context MuJoCo's renderer can use here (EGL, else OSMesa, or the one
MUJOCO_GL names). Probed by the camera set-up of either world without importing an engine's
renderer."""

from __future__ import annotations

import os


def gl_context_class():
    """The first headless GL context class that imports; (class, None) or (None, reason)."""
    tried = []
    want = os.environ.get("MUJOCO_GL", "").lower().strip()
    names = [want] if want else ["egl", "osmesa"]
    for name in names:
        try:
            if name == "egl":
                from mujoco.egl import GLContext
            elif name == "osmesa":
                from mujoco.osmesa import GLContext
            else:
                from mujoco.rendering.classic.gl_context import GLContext
            return GLContext, None
        except Exception as e:  # a missing libEGL/libOSMesa surfaces as ImportError, OSError or AttributeError
            tried.append(f"{name}: {type(e).__name__}: {e}")
    return None, "; ".join(tried)
