"""A folder named where a scene is expected: its launch.yaml, or a clear error naming what is there."""

from __future__ import annotations

import json

import pytest
from conftest import ROOT

from adfkit.cli import main

PAD = ROOT / "sample_scenes" / "suturing_pad"


def test_info_of_a_scene_folder_reads_its_launch_file(capsys):
    assert main(["info", "--json", str(PAD)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["kind"] == "launch" and summary["file"] == str(PAD / "launch.yaml")


def test_info_of_several_files_summarises_each_and_reports_the_unreadable_one(tmp_path, capsys):
    """`adfkit info *.yaml`: one summary per file in order (JSON: a list); a missing file is a
    located error among them, the others still summarised, and the exit status says it."""
    files = [PAD / "pad.yaml", tmp_path / "absent.yaml", PAD / "world.yaml"]
    assert main(["info", "--json", *map(str, files)]) == 2
    out, err = capsys.readouterr()
    summaries = json.loads(out)
    assert [(s["kind"], s["file"]) for s in summaries] == [("model", str(files[0])), ("world", str(files[2]))]
    assert f"{files[1]}: error[file-not-found]" in err
    assert main(["info", str(files[0]), str(files[2])]) == 0
    text = capsys.readouterr().out
    assert (
        text.index(f"== {files[0]}")
        < text.index("kind: model")
        < text.index(f"== {files[2]}")
        < text.index("kind: world")
    )


def test_run_of_a_scene_folder_plays_its_launch_file(tmp_path, capsys):
    pytest.importorskip("pybullet")
    assert main(["run", str(PAD), "--seconds", "0.05", "--no-frames", "--out", str(tmp_path)]) == 0
    assert json.loads((tmp_path / "report.json").read_text())["bodies"] > 10


def test_a_folder_without_a_launch_file_names_the_files_to_choose_from(tmp_path, capsys):
    (tmp_path / "world.yaml").write_text("gravity: {x: 0, y: 0, z: -9.81}\n")
    (tmp_path / "pad.yaml").write_text("bodies: []\n")
    for argv in (["info", str(tmp_path)], ["run", str(tmp_path)], ["suture", str(tmp_path)]):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert f"{tmp_path}: error[not-a-regular-file]: {tmp_path} is a folder without a launch.yaml" in err
        assert "hint: name the ADF file to use: one of pad.yaml, world.yaml" in err
        assert "Traceback" not in err
