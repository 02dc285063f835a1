"""`adfkit score-needle-pose`: the challenge's position/orientation errors on known poses."""

from __future__ import annotations

import json
import math

import pytest

from adfkit.cli import main


def _write(path, doc):
    path.write_text(json.dumps(doc))
    return str(path)


def test_known_poses(tmp_path, capsys):
    gt = _write(tmp_path / "gt.json", {"position": [0.1, 0.2, 0.7], "orientation": [0, 0, 0, 1]})
    # 3 mm off along x-y-z (1, 2, 2 mm) and turned 0.3 rad about z
    est = _write(tmp_path / "est.json", {"position": [0.101, 0.202, 0.702], "rpy": [0, 0, 0.3]})
    assert main(["score-needle-pose", gt, est, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["poses"][0]["position_error_m"] == pytest.approx(0.003, abs=1e-12)
    assert out["poses"][0]["orientation_error_rad"] == pytest.approx(0.3, abs=1e-9)


def test_quaternion_and_matrix_agree(tmp_path, capsys):
    h = math.sqrt(0.5)
    gt = _write(tmp_path / "gt.json", {"poses": [{"position": [0, 0, 0], "orientation": [h, 0, 0, h]}]})
    est = _write(
        tmp_path / "est.json", {"poses": [{"matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}]}
    )
    assert main(["score-needle-pose", gt, est, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["poses"][0]["orientation_error_rad"] == pytest.approx(math.pi / 2, abs=1e-9)
    assert out["poses"][0]["position_error_m"] == 0.0


@pytest.mark.parametrize(
    "doc, rule",
    [
        ({"position": [0, 0]}, "bad-pose"),
        ({"position": [0, 0, 0], "orientation": [0, 0, 0, 2]}, "bad-pose"),
        ({"poses": []}, "bad-pose"),
    ],
)
def test_bad_input_is_exit_2(tmp_path, capsys, doc, rule):
    gt = _write(tmp_path / "gt.json", {"position": [0, 0, 0], "orientation": [0, 0, 0, 1]})
    est = _write(tmp_path / "est.json", doc)
    assert main(["score-needle-pose", gt, est]) == 2
    err = capsys.readouterr().err
    assert rule in err and "est.json:1:1" in err


def test_not_json_and_missing(tmp_path, capsys):
    gt = _write(tmp_path / "gt.json", {"position": [0, 0, 0], "orientation": [0, 0, 0, 1]})
    (tmp_path / "bad.json").write_text('{"position": [0, 0,\n')
    assert main(["score-needle-pose", gt, str(tmp_path / "bad.json")]) == 2
    assert "bad-json" in capsys.readouterr().err
    assert main(["score-needle-pose", gt, str(tmp_path / "none.json")]) == 2
