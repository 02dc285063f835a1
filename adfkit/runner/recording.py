"""An episode's pictures from one camera: an MP4 at the camera's own resolution and small
frames for a GIF preview. ``CameraRecording`` draws each frame here, between two steps, with the
world's renderer; runner/mujoco/recorder.py draws them in a process of its own beside the
physics (``runner.engines.camera_recording`` picks)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .video import Mp4Writer, shrink


class CameraRecording:
    """Frames of ``cam`` drawn in this process: ``frame`` renders the world now and keeps the
    picture for the video and/or the preview."""

    drawn_in = "the episode's process"

    def __init__(self, world, cam, video_path: Path | None, fps: float, gif_width: int) -> None:
        self.world, self.cam = world, cam
        self.video = Mp4Writer(video_path, fps) if video_path is not None else None
        self.fps, self.gif_width = fps, gif_width
        self.gif: list[np.ndarray] = []
        self.note: str | None = None  # what went wrong with the pictures, if anything

    def frame(self, to_video: bool, to_gif: bool) -> None:
        self.add(self.cam.render(self.world, rgb_only=True)["rgb"], to_video, to_gif)

    def add(self, rgb: np.ndarray, to_video: bool, to_gif: bool) -> None:
        if to_video and self.video is not None:
            self.video.add(rgb)
        if to_gif:
            self.gif.append(shrink(rgb, self.gif_width))

    @property
    def video_frames(self) -> int:
        return self.video.frames if self.video is not None else 0

    @property
    def video_path(self) -> Path | None:
        return self.video.path if self.video is not None else None

    def close(self) -> None:
        if self.video is not None:
            self.video.close()
