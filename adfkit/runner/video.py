"""Camera frames as a video and as a small preview: an H.264 MP4 written as the frames come
(imageio's ffmpeg plugin, ``imageio-ffmpeg``), to a temporary file renamed when complete, and
frames shrunk for a GIF."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..scratch import temp_beside


class Mp4Writer:
    """Frames at their own resolution as an H.264 MP4 (not held in memory); ``close`` renames
    the finished file into place, so a stopped recording never leaves a half-written one."""

    def __init__(self, path: Path, fps: float) -> None:
        self.path, self.fps = Path(path), fps
        self.tmp: Path | None = None
        self.w = None
        self.frames = 0

    def add(self, rgb: np.ndarray) -> None:
        if self.w is None:
            import imageio.v2 as imageio

            self.path.parent.mkdir(parents=True, exist_ok=True)
            # a name of this process's own: two runs writing into one folder do not share it
            fd, tmp = temp_beside(self.path, ".mp4")
            os.close(fd)
            self.tmp = Path(tmp)
            self.w = imageio.get_writer(
                self.tmp,
                format="FFMPEG",
                fps=self.fps,
                codec="libx264",
                quality=7,
                macro_block_size=2,
                pixelformat="yuv420p",
            )
        self.w.append_data(np.ascontiguousarray(rgb))
        self.frames += 1

    def close(self) -> None:
        if self.w is not None:
            self.w.close()
            self.w = None
            assert self.tmp is not None
            self.tmp.replace(self.path)


def shrink(rgb: np.ndarray, width: int) -> np.ndarray:
    """The frame ``width`` pixels wide, its aspect kept (a preview's frame)."""
    from PIL import Image

    h, w = rgb.shape[:2]
    return np.asarray(Image.fromarray(rgb).resize((width, max(1, round(h * width / w)))))
