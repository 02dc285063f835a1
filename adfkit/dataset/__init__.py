"""The suture dataset: per camera and every N control steps an RGB PNG, depth (a 16-bit PNG
in 0.1 mm; float32 metres in a deflated .npz when a frame sees beyond 6.55 m), a segmentation label image (uint16 PNG, 0 = nothing, k+1 = body k of
labels.json) with a colourised PNG beside it, the camera's intrinsics and extrinsics, and the
needle and PSM poses; ``index.jsonl`` lists the frames (layout in writer.py).

    from adfkit.dataset import load
    for frame in load("out/dataset"):
        frame.rgb(), frame.depth(), frame.labels(), frame.K, frame.T_world_camera, frame.needle
"""

from __future__ import annotations

from .colors import colourise  # noqa: F401
from .loader import Frame, load  # noqa: F401
