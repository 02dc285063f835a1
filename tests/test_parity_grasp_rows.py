"""AMBF's constraint actuator as the plugin plays it: the file's `max impulse` and `tau` are read by
AMBF 2.0 and not used (its grasp is a btFixedConstraint without a limit), and the plugin's two
measurement knobs for a grasp, ADFKIT_PARITY_GRASP_ROWS (the grasp's rows and solver iterations) and
ADFKIT_PARITY_FINE (a sample every physics step in windows). The tests skip, with the reason, where
no AMBF build is present."""

from __future__ import annotations

import numpy as np
import pytest
from test_runner import HELD_PAST_MAX_IMPULSE

from adfkit.diagnostics import AdfError
from adfkit.parity import ambf
from adfkit.parity.traces import from_ambf

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)
GRASP = [ambf.Command(0.0, "grasp", "grip", body="box")]


def _play(tmp_path, monkeypatch, seconds: float, env: dict[str, str]):
    f = tmp_path / "held.yaml"
    f.write_text(HELD_PAST_MAX_IMPULSE)
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    return from_ambf(ambf.run(BUILD, ambf.write_stage(None, [f], None), seconds, 0.02, GRASP))


def _box_moved(trace) -> float:
    i = trace.body_names.index("box")
    return float(np.linalg.norm(trace.poses[:, i, :3] - trace.poses[0, i, :3], axis=1).max())


@needs_ambf
def test_ambf_holds_past_the_files_max_impulse(tmp_path, monkeypatch):
    """A 1 kg box hung for 1 s from an actuator whose file says `max impulse: 0.0001` (0.1 N over
    AMBF's 1 ms step): AMBF holds it (measured 0.000 mm), as adfkit's runners now do
    (test_runner.test_a_grasp_holds_past_the_files_max_impulse)."""
    assert _box_moved(_play(tmp_path, monkeypatch, 1.0, {})) < 1e-5


@needs_ambf
def test_fine_samples_every_step_and_changes_nothing(tmp_path, monkeypatch):
    """ADFKIT_PARITY_FINE "0.05 0.06": a sample every 1 ms step there besides the 20 ms ones, the
    poses at the common samples the same to the bit."""
    plain = _play(tmp_path, monkeypatch, 0.2, {})
    fine = _play(tmp_path, monkeypatch, 0.2, {"ADFKIT_PARITY_FINE": "0.05 0.06"})
    assert len(plain.times) == 11 and len(fine.times) == 21
    assert np.allclose(fine.times[3:14], np.arange(0.05, 0.0605, 0.001))
    common = np.searchsorted(fine.times, plain.times - 1e-9)
    assert np.array_equal(fine.poses[common], plain.poses)


@needs_ambf
def test_grasp_rows_knob_is_read(tmp_path, monkeypatch):
    """ADFKIT_PARITY_GRASP_ROWS "ERP CFM N" holds the box as AMBF's own rows do; a malformed value
    is refused with the plugin's message."""
    assert _box_moved(_play(tmp_path, monkeypatch, 0.2, {"ADFKIT_PARITY_GRASP_ROWS": "0.8 0 100"})) < 1e-5
    with pytest.raises(AdfError, match="GRASP_ROWS"):
        _play(tmp_path, monkeypatch, 0.2, {"ADFKIT_PARITY_GRASP_ROWS": "stiff"})
