"""A world's camera frames (a PyBullet world's, or the MuJoCo engine's) drawn by the MuJoCo
mirror (mirror.py) in a process of its own, beside the physics: at each frame the episode's
process sends only the drawn bodies' poses (a few kilobytes); the other process puts the
mirror's bodies there, renders, writes the MP4 and keeps the preview's frames, which it hands
back at the end. The pictures are the ones the mirror draws in the episode's process, pixel
for pixel; the episode's process no longer waits for them (in the bundled suture ~20 ms a
frame, 450 frames). A recorder that cannot start (no OpenGL
there) says why and the frames are drawn in the episode's process from then on."""

from __future__ import annotations

import socket
import subprocess
import sys
from multiprocessing.connection import Connection
from types import SimpleNamespace

import numpy as np

from ..recording import CameraRecording


class _Posed:
    """A body of the episode's world as the mirror reads it: its key and its last pose."""

    def __init__(self, key: str) -> None:
        self.key = key
        self.matrix = np.eye(4)

    def world_matrix(self) -> np.ndarray:
        return self.matrix


def _serve(conn, scene, opt, keys, cameras, index, video_path, fps, gif_width) -> None:
    """The recorder's process: build the mirror, then draw every frame sent until None."""
    try:
        from .mirror import MjMirror

        bodies = [_Posed(k) for k in keys]
        cams = [SimpleNamespace(name=n, key=None, eye_offset=None, width=w, height=h) for n, w, h in cameras]
        mirror = MjMirror(SimpleNamespace(scene=scene, opt=opt, bodies=bodies, cameras=cams))
        cam = cams[index]
        mirror.render(cam, rgb_only=True)  # the GL context opens now: a failure is told before any frame
        drawn = sorted({i for _, i, _, _ in mirror._drawn})
        conn.send(("ready", drawn))
    except Exception as exc:  # noqa: BLE001 - whatever stops the mirror here, the episode draws its frames itself
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
        conn.close()
        return
    rec = CameraRecording(None, None, video_path, fps, gif_width)
    try:
        while (msg := conn.recv()) is not None:
            to_video, to_gif, mats = msg
            for i, m in zip(drawn, mats):
                bodies[i].matrix = m
            rec.add(mirror.render(cam, rgb_only=True)["rgb"], to_video, to_gif)
        rec.close()
        conn.send(("done", rec.gif, rec.video_frames))
    finally:
        mirror.close()
        conn.close()


class MirrorRecording:
    """CameraRecording's interface, the frames drawn in the recorder's process."""

    def __init__(self, world, cam, video_path, fps: float, gif_width: int) -> None:
        self.world, self.cam = world, cam
        self.fps, self.gif_width = fps, gif_width
        self._video_path = video_path
        self.gif: list[np.ndarray] = []
        self.note: str | None = None
        self._frames = 0
        self._drawn: list[int] | None = None
        self._pending: list[tuple] = []  # frames asked for before the recorder was ready
        self._local: CameraRecording | None = None  # drawing here, when the recorder could not start
        index = next(i for i, c in enumerate(world.cameras) if c is cam)
        # a fresh interpreter running this module (not multiprocessing's spawn, which would run
        # the user's own script again in it): no engine or GL state shared, a socket between
        ours, theirs = socket.socketpair()
        self.proc = subprocess.Popen(
            [sys.executable, "-m", __name__, str(theirs.fileno())],
            pass_fds=(theirs.fileno(),),
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
        )
        theirs.close()
        self.conn = Connection(ours.detach())
        cameras = [(c.name, c.width, c.height) for c in world.cameras]
        keys = [sb.key for sb in world.bodies]
        path = None if video_path is None else str(video_path)
        self.conn.send((world.scene, world.opt, keys, cameras, index, path, fps, gif_width))

    def _poses(self, which) -> np.ndarray:
        bodies = self.world.bodies
        return np.array([bodies[i].world_matrix() for i in which])

    def _answer(self, block: bool) -> None:
        """Read what the recorder said: ready (send what waited), or why it cannot draw."""
        if self._drawn is not None or self._local is not None or not (block or self.conn.poll()):
            return
        try:
            kind, what = self.conn.recv()
        except (EOFError, OSError):
            kind, what = "error", f"the recorder's process ended (exit code {self.proc.poll()})"
        if kind == "ready":
            self._drawn = what
            for to_video, to_gif, mats in self._pending:
                self._send(to_video, to_gif, mats[what])
        else:
            lost = len(self._pending)
            self.note = f"frames drawn in the episode's process: the recorder's could not start ({what})" + (
                f"; the first {lost} frames were lost" if lost else ""
            )
            self._local = CameraRecording(self.world, self.cam, self._video_path, self.fps, self.gif_width)
            self._local.note = self.note
        self._pending = []

    def _send(self, to_video: bool, to_gif: bool, mats: np.ndarray) -> None:
        self.conn.send((to_video, to_gif, mats))
        self._frames += bool(to_video)

    def frame(self, to_video: bool, to_gif: bool) -> None:
        self._answer(block=False)
        if self._local is not None:
            self._local.frame(to_video, to_gif)
        elif self._drawn is None:
            self._pending.append((to_video, to_gif, self._poses(range(len(self.world.bodies)))))
        else:
            self._send(to_video, to_gif, self._poses(self._drawn))

    @property
    def drawn_in(self) -> str:
        return self._local.drawn_in if self._local is not None else "a process of its own"

    @property
    def video_frames(self) -> int:
        return self._local.video_frames if self._local is not None else self._frames

    @property
    def video_path(self):
        return self._video_path

    def close(self) -> None:
        """Wait for the recorder to draw and write what it was sent; its preview frames come back."""
        self._answer(block=True)
        if self._local is not None:
            self._local.close()
            self.gif = self._local.gif
        else:
            try:
                self.conn.send(None)
                kind, self.gif, self._frames = self.conn.recv()
            except (EOFError, OSError, ValueError) as exc:
                code = self.proc.poll()
                self.note = f"the recorder's process stopped before it finished ({type(exc).__name__}, exit code {code}): no video"
                self._frames = 0
        try:
            self.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.proc.kill()
        self.conn.close()


def _main(fd: int) -> None:
    conn = Connection(fd)
    try:
        args = conn.recv()
    except EOFError:
        return
    _serve(conn, *args)


if __name__ == "__main__":
    _main(int(sys.argv[1]))
