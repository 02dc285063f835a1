"""A body whose pose stops being a number on one side is a disagreement, said with its time:
AMBF's world goes NaN under a zero joint axis or a body with a zero moment of inertia in
contact, where adfkit's stays finite, and the comparison, taking the largest gap that is a
number, said "agree" (measured on hand-made models: body b NaN in AMBF from 0.02 s)."""

from __future__ import annotations

import numpy as np
import pytest

from adfkit.parity import ambf
from adfkit.parity.compare import compare
from adfkit.parity.traces import Trace

BUILD, WHY = ambf.available()


def _trace(side: str, poses: np.ndarray) -> Trace:
    times = np.arange(poses.shape[0]) * 0.02
    made = {"body": ["a", "b"], "soft body": [], "ghost": [], "joint": [], "sensor": [], "actuator": []}
    return Trace(side, made, ["a", "b"], times, poses, [], np.zeros((len(times), 0)), 0.0)


def test_a_pose_that_is_not_a_number_on_one_side_is_a_disagreement():
    still = np.zeros((5, 2, 7))
    still[:, :, 6] = 1.0
    still[:, 1, 2] = 0.3
    blown = still.copy()
    blown[2:, 1, :] = np.nan  # b from the third sample (0.04 s)
    c = compare(_trace("ambf", blown), _trace("pybullet", still))
    assert c.not_a_number == [{"side": "ambf", "name": "b", "from_s": pytest.approx(0.04)}]
    assert "AMBF's b is not a number from 0.040 s" in c.failures()
    assert c.as_json()["agree"] is False
    assert compare(_trace("ambf", still), _trace("pybullet", still)).failures() == []


def test_a_body_ambfs_world_flings_is_a_disagreement_said_with_its_time_and_speed():
    """AMBF's world blowing up leaves numbers (its thread nudged 1 nm off its plane: bodies
    1 m off by 44 ms, 1e12 m by 2 s), which the gaps showed as 1e15 mm and nothing more."""
    still = np.zeros((5, 2, 7))
    still[:, :, 6] = 1.0
    falling = still.copy()
    falling[:, 1, 2] = -29.0 * np.arange(5) * 0.02  # 29 m/s, the fastest fall the docs measure: no blow-up
    thrown = falling.copy()
    thrown[3:, 1, 0] = 40.0  # 40 m between the samples at 0.04 and 0.06 s: 2000 m/s
    c = compare(_trace("ambf", thrown), _trace("pybullet", falling))
    assert c.flung == [{"name": "b", "from_s": pytest.approx(0.06), "speed_m_s": pytest.approx(2000.0, rel=1e-3)}]
    assert "AMBF's b is flung (2e+03 m/s) from 0.060 s" in c.failures()
    assert c.as_json()["flung"] == c.flung and c.as_json()["agree"] is False
    assert compare(_trace("ambf", falling), _trace("pybullet", falling)).flung == []
    assert compare(_trace("ambf", falling), _trace("pybullet", thrown)).flung == []  # adfkit's: its world's watch


@pytest.mark.skipif(BUILD is None, reason=WHY)
def test_ambfs_world_blowing_up_on_a_zero_joint_axis_is_said(tmp_path):
    from pathlib import Path

    from adfkit.parity import session

    box = "  collision shape: BOX\n  collision geometry: {x: 0.1, y: 0.1, z: 0.1}\n"
    (tmp_path / "z.yaml").write_text(
        "bodies: [BODY a, BODY b]\njoints: [JOINT ab]\n"
        f"BODY a:\n  name: a\n  mass: 0\n{box}  location: {{position: {{x: 0, y: 0, z: 0.5}}}}\n"
        f"BODY b:\n  name: b\n  mass: 1.0\n{box}  location: {{position: {{x: 0, y: 0, z: 0.3}}}}\n"
        "JOINT ab:\n  parent: BODY a\n  child: BODY b\n  type: revolute\n"
        "  parent pivot: {x: 0, y: 0, z: -0.1}\n  child pivot: {x: 0, y: 0, z: 0.1}\n"
        "  parent axis: {x: 0, y: 0, z: 0}\n  child axis: {x: 0, y: 0, z: 1}\n"
    )
    req = session.Request(Path(tmp_path / "z.yaml"), None, BUILD, seconds=0.2, every=0.02)
    c = session.run(req, progress=False).comparisons[0]
    assert [d["side"] for d in c.not_a_number] == ["ambf"] and c.failures()
