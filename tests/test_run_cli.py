"""`adfkit run` and `adfkit demo` end to end: real PyBullet, the files they leave behind, exit
statuses and located errors for bad input."""

from __future__ import annotations

import json
import textwrap

import numpy as np
import pytest
from conftest import CORPUS, ROOT, box_camera_model, require_corpus

pytest.importorskip("pybullet")
Image = pytest.importorskip("PIL.Image")

from adfkit.cli import main  # noqa: E402

BOX_AND_CAMERA = box_camera_model(mass=0.5, z=0.1, rgb=(0.1, 0.8, 0.2))


@pytest.fixture
def box_model(tmp_path):
    p = tmp_path / "box.yaml"
    p.write_text(textwrap.dedent(BOX_AND_CAMERA))
    return p


def test_run_writes_report_and_camera_frames(box_model, tmp_path, capsys):
    out = tmp_path / "out"
    rc = main(["run", str(box_model), "--seconds", "0.2", "--out", str(out)])
    assert rc == 0
    rep = json.loads((out / "report.json").read_text())
    assert rep["bodies"] == 1 and rep["steps"] == 200 and rep["simulated_time_s"] == pytest.approx(0.2)
    assert rep["cameras"] == ["cam"] and rep["physics_hz"] == 1000.0
    assert rep["nan"] == rep["exploded"] == rep["fell_through_floor"] == []
    # the box rests on the floor the runner puts under a model played alone
    assert rep["ground_plane_z"] == pytest.approx(-0.001, abs=1e-6)
    assert sorted(rep["frames"]) == ["cam_depth.npy", "cam_rgb.png", "cam_seg.npy", "cam_seg.png"]
    rgb = np.asarray(Image.open(out / "cam_rgb.png"))
    assert rgb.shape == (48, 64, 3) and rgb[24, 32, 1] > 2 * rgb[24, 32, 0]  # the green box in the middle
    depth = np.load(out / "cam_depth.npy")
    assert abs(float(depth[24, 32]) - 0.9) < 2e-3  # its near face, 0.1 m in front of its centre
    seg = np.load(out / "cam_seg.npy")
    assert seg[24, 32] == 0
    printed = capsys.readouterr().out
    assert "1 bodies" in printed and str((out / "report.json").resolve()) in printed


def test_run_selects_launch_indices(tmp_path, capsys):
    require_corpus()
    out = tmp_path / "out"
    rc = main(
        ["run", str(CORPUS / "src" / "launch.yaml"), "-l", "6", "--seconds", "0.05", "--no-frames", "--out", str(out)]
    )
    assert rc == 0
    rep = json.loads((out / "report.json").read_text())
    # psm1 alone: the world's floor (its environment model) has no Plane.OBJ, so AMBF and the
    # runner leave it out
    assert rep["bodies"] == 10 and rep["joints"] == 8 and rep["multibodies"] == 1
    assert rep["skipped_bodies"] == ["/ambf/env/BODY Plane"]
    assert rep["steps"] == 48  # 0.05 s in whole control steps of 4 ms
    # the world's stereo pair hangs from the phantom's CameraFrame, which index 10 would load:
    # as AMBF leaves an object whose parent it cannot find, they stay where their location puts them
    assert "frames" not in rep and len(rep["cameras"]) == 2
    assert capsys.readouterr().err.count("warning[runner-parent]") == 2


def test_run_reports_an_unstable_scene_with_exit_status_1(box_model, capsys):
    # 1000 m/s² and no floor: the box is past 10 m/s within the run
    rc = main(["run", str(box_model), "--seconds", "0.1", "--gravity", "0,0,-1000", "--no-ground"])
    assert rc == 1
    assert "unstable" in capsys.readouterr().err


@pytest.mark.parametrize(
    "args, said",
    [
        (["--seconds", "0"], "--seconds"),
        (["--solver-iterations", "0"], "--solver-iterations"),
        (["--contact-threshold", "-1"], "--contact-threshold"),
        (["--gravity", "0,0"], "is not x,y,z"),
    ],
)
def test_run_refuses_bad_options(box_model, capsys, args, said):
    assert main(["run", str(box_model)] + args) == 2
    assert said in capsys.readouterr().err


def test_run_refuses_a_missing_file(tmp_path, capsys):
    assert main(["run", str(tmp_path / "nothing.yaml")]) == 2
    assert f"{tmp_path / 'nothing.yaml'}: error[file-not-found]: no such ADF file" in capsys.readouterr().err


def test_demo_plays_the_bundled_scene(tmp_path, capsys):
    out = tmp_path / "demo"
    rc = main(
        [
            "demo",
            "--scene",
            str(ROOT / "sample_scenes" / "suturing_pad" / "launch.yaml"),
            "--seconds",
            "0.1",
            "--out",
            str(out),
        ]
    )
    assert rc == 0
    rep = json.loads((out / "report.json").read_text())
    assert rep["steps"] == 100 and rep["bodies"] > 0
    printed = capsys.readouterr().out
    assert "stable" in printed and "image:" in printed
    assert all((out / f).is_file() for f in rep["frames"])
