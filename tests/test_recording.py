"""Camera L's pictures over an episode (runner/recording.py, runner/mujoco/recorder.py), in either
engine: drawn in a process of its own they are the pictures drawn between the steps, pixel for
pixel; a recorder that cannot start says why and the frames are drawn here instead."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

BUNDLED = ROOT / "sample_scenes" / "suturing" / "launch.yaml"


@pytest.fixture(scope="module", params=["pybullet", "mujoco"])
def world(request):
    """The bundled scene in each engine, drawn by MuJoCo's renderer (the PyBullet world's mirror,
    the MuJoCo engine's own cameras)."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    w = open_world(load_scene(BUNDLED), Options(renderer="mujoco"), engine=request.param)
    try:
        w.cameras[0].render(w, rgb_only=True)
    except Exception as exc:  # noqa: BLE001
        w.close()
        pytest.skip(f"MuJoCo's renderer cannot draw here: {exc}")
    if request.param == "pybullet" and w.renderer != "mujoco":
        w.close()
        pytest.skip(f"MuJoCo's renderer is not available here ({w.renderer_note})")
    yield w
    w.close()


def _frames(path):
    import imageio.v2 as imageio

    with imageio.get_reader(path) as r:
        return [f for f in r]


def test_frames_drawn_in_a_process_of_their_own_are_the_same_pictures(world, tmp_path):
    from adfkit.runner.engines import camera_recording
    from adfkit.runner.mujoco.recorder import MirrorRecording
    from adfkit.runner.recording import CameraRecording

    cam = world.cameras[0]
    here = CameraRecording(world, cam, tmp_path / "here.mp4", 5.0, 160)
    there = camera_recording(world, cam, tmp_path / "there.mp4", 5.0, 160)
    assert isinstance(there, MirrorRecording)
    for i in range(6):
        world.step(20)  # the needle and thread settle: the pictures change
        here.frame(to_video=True, to_gif=i % 2 == 0)
        there.frame(to_video=True, to_gif=i % 2 == 0)
    here.close()
    there.close()
    assert there.note is None and there.drawn_in == "a process of its own"
    assert there.video_frames == here.video_frames == 6 and (tmp_path / "there.mp4").is_file()
    assert not list(tmp_path.glob(".there.mp4.*")) and not list(tmp_path.glob(".here.mp4.*"))
    assert len(there.gif) == len(here.gif) == 3 and there.gif[0].shape == (120, 160, 3)
    assert all(np.array_equal(a, b) for a, b in zip(here.gif, there.gif))
    a, b = _frames(tmp_path / "here.mp4"), _frames(tmp_path / "there.mp4")
    assert len(a) == len(b) == 6 and all(np.array_equal(x, y) for x, y in zip(a, b))
    assert not np.array_equal(a[0], a[-1])


def test_a_recorder_that_cannot_start_says_why_and_the_frames_are_drawn_here(world, tmp_path, monkeypatch):
    from adfkit.runner.mujoco.recorder import MirrorRecording

    cam = world.cameras[0]
    monkeypatch.setenv("MUJOCO_GL", "no-such-gl")  # the recorder's process finds no OpenGL
    rec = MirrorRecording(world, cam, tmp_path / "v.mp4", 5.0, 160)
    monkeypatch.delenv("MUJOCO_GL")
    rec.proc.wait(timeout=120)  # it has said why and ended
    for _ in range(3):
        world.step(10)
        rec.frame(to_video=True, to_gif=True)
    rec.close()
    assert rec.drawn_in == "the episode's process" and "could not start" in rec.note and "no-such-gl" in rec.note
    assert rec.video_frames == 3 and len(rec.gif) == 3 and (tmp_path / "v.mp4").is_file()


def test_two_recordings_of_one_file_in_one_folder_do_not_trip_over_each_other(tmp_path):
    """Two runs writing the same video into one output folder (two `adfkit suture` started in one
    directory): each writes a file of its own name and renames it into place; the second rename
    used to find the shared temporary file gone (a traceback)."""
    from adfkit.runner.video import Mp4Writer

    a, b = Mp4Writer(tmp_path / "cameraL.mp4", 10.0), Mp4Writer(tmp_path / "cameraL.mp4", 10.0)
    for i in range(4):
        a.add(np.full((32, 48, 3), 40 * i, np.uint8))
        b.add(np.full((32, 48, 3), 200 - 40 * i, np.uint8))
    assert a.tmp is not None and b.tmp is not None and a.tmp != b.tmp
    a.close()
    b.close()
    assert [p.name for p in tmp_path.iterdir()] == ["cameraL.mp4"]
    assert len(_frames(tmp_path / "cameraL.mp4")) == 4
