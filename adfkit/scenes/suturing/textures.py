"""Procedural textures of the phantom (PNG, made with numpy and Pillow, same seed, same bytes):
a tissue colour map with fibres and mottling, and the normal map of the same height field."""

from __future__ import annotations

import io

import numpy as np

SIZE = 256


def _smooth_noise(rng, size: int, cells: int) -> np.ndarray:
    """Value noise: a coarse random grid bilinearly interpolated, periodic."""
    g = rng.random((cells, cells))
    x = np.arange(size) * cells / size
    i0 = np.floor(x).astype(int)
    f = x - i0
    f = f * f * (3 - 2 * f)
    i1 = (i0 + 1) % cells
    rows = g[i0][:, i0] * (1 - f)[None, :] + g[i0][:, i1] * f[None, :]
    rows1 = g[i1][:, i0] * (1 - f)[None, :] + g[i1][:, i1] * f[None, :]
    return rows * (1 - f)[:, None] + rows1 * f[:, None]


def height_field(seed: int = 15) -> np.ndarray:
    """Tissue relief in 0..1: fibres along one direction plus mottling."""
    rng = np.random.default_rng(seed)
    h = sum(_smooth_noise(rng, SIZE, c) * w for c, w in ((4, 0.45), (8, 0.25), (16, 0.15), (32, 0.1)))
    y = np.arange(SIZE)[:, None] * np.ones((1, SIZE))
    fibres = 0.5 + 0.5 * np.sin(2 * np.pi * (y / 9.0 + 1.5 * _smooth_noise(rng, SIZE, 4)))
    h = 0.75 * h + 0.25 * fibres
    return (h - h.min()) / (h.max() - h.min())


def _png(a: np.ndarray) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(a).save(buf, format="PNG", optimize=True)
    return buf.getvalue()


def tissue_png(seed: int = 15) -> bytes:
    h = height_field(seed)
    light = np.array([0.93, 0.62, 0.58])
    deep = np.array([0.70, 0.30, 0.30])
    rgb = deep[None, None, :] + (light - deep)[None, None, :] * h[:, :, None]
    return _png(np.clip(rgb * 255 + 0.5, 0, 255).astype(np.uint8))


def normal_png(seed: int = 15, strength: float = 3.0) -> bytes:
    """Tangent-space normal map (RGB = (n + 1) / 2) of the same height field."""
    h = height_field(seed)
    dx = (np.roll(h, -1, axis=1) - np.roll(h, 1, axis=1)) * strength
    dy = (np.roll(h, -1, axis=0) - np.roll(h, 1, axis=0)) * strength
    n = np.stack([-dx, -dy, np.ones_like(h)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return _png(np.clip((n + 1) * 127.5 + 0.5, 0, 255).astype(np.uint8))
