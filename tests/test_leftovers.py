"""Nothing left behind: what a command writes in $TMPDIR goes when it ends, and what a killed
one (SIGKILL) left is removed by the next (adfkit/scratch.py). The fuzz suite checks every
command's $TMPDIR and scene folder after success and failure (tests/fuzzkit.py: left_behind);
these tests kill real processes."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import ROOT

from adfkit import scratch

PY = sys.executable


def _env(tmpdir: Path) -> dict:
    return {**os.environ, "TMPDIR": str(tmpdir), "PYTHONPATH": str(ROOT)}


def _wait_for(pred, seconds: float = 120.0):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        hit = pred()
        if hit:
            return hit
        time.sleep(0.05)
    return None


def test_run_cleans_its_tmpdir_and_a_later_command_what_a_killed_one_left(tmp_path):
    """adfkit run --engine mujoco (its MJCF is written to $TMPDIR) leaves nothing there when it
    ends; killed with SIGKILL while it plays, its scratch folder stays, and the next command
    (here a validate) removes it."""
    tmpdir = tmp_path / "tmp"
    tmpdir.mkdir()
    scene = ROOT / "sample_scenes" / "soft_phantom" / "launch.yaml"
    argv = [PY, "-m", "adfkit", "run", str(scene), "--engine", "mujoco", "--no-frames", "--out", str(tmp_path / "o")]
    done = subprocess.run([*argv, "--seconds", "0.01"], env=_env(tmpdir), capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert list(tmpdir.iterdir()) == []  # success: nothing left
    proc = subprocess.Popen(
        [*argv, "--seconds", "600"], env=_env(tmpdir), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    try:
        left = _wait_for(lambda: list(tmpdir.glob(f"{scratch.PREFIX}{proc.pid}-*")))
        assert left, "the run made no scratch folder"
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=60)
    assert all(p.exists() for p in left)  # SIGKILL: nothing could remove it
    other = tmpdir / f"{scratch.PREFIX}{os.getpid()}-live"  # a running process's folder is kept
    other.mkdir()
    check = subprocess.run(
        [PY, "-m", "adfkit", "validate", str(scene)], env=_env(tmpdir), capture_output=True, text=True, timeout=300
    )
    assert check.returncode == 0, check.stderr
    assert sorted(tmpdir.iterdir()) == [other]


def test_a_write_killed_before_its_rename_is_removed_by_the_next_write(tmp_path):
    """A process killed between writing its temporary file beside the target and renaming it
    (as a convert killed mid-write) leaves `.<name>.<pid>.*.tmp`; the next write of that target
    removes it, and keeps the temporary file of a writer still running."""
    target = tmp_path / "out.xml"
    child = subprocess.Popen(
        [
            PY,
            "-c",
            "import sys, time; from pathlib import Path; from adfkit.scratch import temp_beside; "
            "fd, tmp = temp_beside(Path(sys.argv[1])); print(tmp, flush=True); time.sleep(600)",
            str(target),
        ],
        env=_env(tmp_path),
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        stale = Path(child.stdout.readline().strip())
    finally:
        child.send_signal(signal.SIGKILL)
        child.wait(timeout=60)
    assert stale.exists() and stale.name.startswith(f".out.xml.{child.pid}.")
    mine = scratch.temp_beside(target)  # a write of this process, still going
    os.close(mine[0])
    model = ROOT / "sample_scenes" / "soft_phantom" / "floor.yaml"
    done = subprocess.run(
        [PY, "-m", "adfkit", "convert", str(model), str(target)], env=_env(tmp_path), capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    assert target.is_file() and not stale.exists() and Path(mine[1]).exists()
    os.unlink(mine[1])


def test_a_failed_write_leaves_the_target_and_no_temporary_file(tmp_path, monkeypatch):
    from adfkit.adf.writer import atomic_write_bytes

    target = tmp_path / "model.yaml"
    target.write_text("old\n")

    def refuse(_src, _dst):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", refuse)
    with pytest.raises(OSError):
        atomic_write_bytes(target, b"new\n")
    monkeypatch.undo()
    assert target.read_text() == "old\n" and sorted(p.name for p in tmp_path.iterdir()) == ["model.yaml"]
