"""Fan-out on Ray (adfkit/fanout.py): episodes as Ray tasks merged into one index; a failed
episode retried once and reported; a worker killed mid-run loses no episode. One local Ray
(2 CPUs) for the whole module."""

from __future__ import annotations

import json

import pytest

ray = pytest.importorskip("ray")
pytest.importorskip("gymnasium")
pytest.importorskip("pybullet")

from adfkit import fanout  # noqa: E402
from adfkit.gym import scenes  # noqa: E402


@pytest.fixture(scope="module", autouse=True)
def local_ray():
    fanout.start(2)
    yield
    ray.shutdown()


def test_a_failing_episode_is_retried_once_and_reported(tmp_path):
    from adfkit.gym.record import record_episode

    jobs = [
        {"env": "adfkit/NoSuchTask-v0", "seed": 5, "out": str(tmp_path)},
        {"env": "adfkit/NoSuchTask-v0", "seed": 6, "out": str(tmp_path), "kill_once": str(tmp_path / "k")},
    ]
    runs = fanout.fan_out(record_episode, jobs, workers=2)
    assert [r["ok"] for r in runs] == [False, False]
    assert [r["attempts"] for r in runs] == [2, 2]
    assert "NoSuchTask" in runs[0]["error"]
    assert (tmp_path / "k").is_file()  # the first run of seed 6 did kill its worker
    index = json.loads(fanout.write_index(tmp_path, runs, {"env": "x"}).read_text())
    assert index["failed"] == [5, 6] and index["retried"] == [5, 6]


@pytest.mark.slow
def test_dataset_of_4_episodes_on_2_workers_survives_a_killed_worker(tmp_path):
    try:
        scenes.default_scene()
    except scenes.SceneUnavailable as exc:
        pytest.skip(str(exc))
    from adfkit.commands.dataset import record
    from adfkit.gym.record import load_episode

    marker = tmp_path / "killed"
    assert record("adfkit/NeedleReach-v0", 4, 0, 2, None, tmp_path / "ds", {}, kill_once=str(marker)) == 0
    assert marker.is_file()
    index = json.loads((tmp_path / "ds" / "index.json").read_text())
    assert [e["seed"] for e in index["episodes"]] == [0, 1, 2, 3]
    assert all(e["ok"] for e in index["episodes"]) and index["retried"] == [0]
    assert int(marker.read_text()) != index["episodes"][0]["pid"]  # the retry ran in another worker
    for e in index["episodes"]:
        ep = load_episode(tmp_path / "ds" / e["file"])
        assert ep["action"].shape == (e["steps"], 7)
        assert ep["obs"]["needle_pose"].shape == (e["steps"] + 1, 7)
        assert bool(ep["is_success"][-1]) == e["success"]


@pytest.mark.slow
def test_suture_episodes_4_on_2_workers_write_4_episodes_and_an_index(tmp_path):
    try:
        launch, indices = scenes.default_scene()
    except scenes.SceneUnavailable as exc:
        pytest.skip(str(exc))
    marker = tmp_path / "killed"
    fanout.suture_episodes(launch, indices, [1], 0, 4, 2, None, tmp_path / "su", kill_once=str(marker))
    index = json.loads((tmp_path / "su" / "index.json").read_text())
    assert marker.is_file()
    assert [e["seed"] for e in index["episodes"]] == [0, 1, 2, 3] and all(e["ok"] for e in index["episodes"])
    assert index["retried"] == [0]
    for e in index["episodes"]:
        assert (tmp_path / "su" / e["dir"] / "metrics.json").is_file()


def test_validate_on_workers_prints_what_one_process_prints(capsys):
    from conftest import ROOT

    from adfkit.cli import main

    tree = str(ROOT / "sample_scenes")
    rc1 = main(["validate", tree, "-f", "json", "--fail-on", "warning"])
    one = capsys.readouterr().out
    rc2 = main(["validate", tree, "-f", "json", "--fail-on", "warning", "--workers", "2"])
    two = capsys.readouterr().out
    assert rc1 == rc2
    assert json.loads(one) == json.loads(two) and one == two
    assert json.loads(one)["files"] >= 10 and json.loads(one)["diagnostics"]
