"""A colouriser for segmentation label images a person can read: every label its own
saturated colour (golden-ratio hues), nothing black."""

from __future__ import annotations

import colorsys

import numpy as np


def palette(n: int) -> np.ndarray:
    """n distinct RGB colours (uint8), label k -> palette[k]."""
    out = np.zeros((max(n, 1), 3), dtype=np.uint8)
    for k in range(max(n, 1)):
        h = (k * 0.618033988749895) % 1.0
        s = 0.65 + 0.35 * ((k // 7) % 2)
        v = 0.95 - 0.3 * ((k // 3) % 2)
        out[k] = [round(255 * c) for c in colorsys.hsv_to_rgb(h, s, v)]
    return out


def colourise(labels: np.ndarray) -> np.ndarray:
    """H×W labels (negative: nothing) -> H×W×3 uint8 image; nothing is black."""
    labels = np.asarray(labels)
    top = int(labels.max()) + 1 if labels.size and labels.max() >= 0 else 1
    img = palette(top)[np.clip(labels, 0, None)]
    img[labels < 0] = 0
    return img
