"""The suture's negative controls built from the bundled scene (tests/suture_phantoms.py), played
in both engines (slow: pair 1, about 20 s simulated each): a phantom that blocks the needle
fails at its pair with a reason naming the body and the place; the phantom in a model file of
its own passes, its contacts with the needle recorded. Each of these passed, or failed as
`reach`, before the whole needle and every tissue body were judged."""

from __future__ import annotations

import pytest
from suture_phantoms import (
    fill_holes,
    narrow_channel,
    phantom_in_own_file,
    raise_floor,
    raise_phantom,
)

ENGINES = ["pybullet", "mujoco"]


def _pair_1(launch, engine: str) -> tuple[dict, dict]:
    from adfkit.tasks.episode import run_episode

    m = run_episode(launch, pairs=(1,), seed=0, progress=False, gif=False, engine=engine)
    return m["pairs"][0], m


@pytest.mark.slow
@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("width", [0.001, 0.0009])
def test_a_channel_narrower_than_the_wire_fails_at_it(tmp_path, engine, width):
    p, m = _pair_1(narrow_channel(tmp_path, width), engine)
    assert not p["passed"] and p["rule"] in ("blocked-at-entry", "blocked-in-channel"), p
    assert "pressed on Phantom" in p["reason"] or "blocked" in p["reason"] and "by Phantom" in p["reason"]
    assert f"the channel at pair 1 is {width * 1000:.1f} mm wide where the wire needs 1.23 mm" in p["reason"]


@pytest.mark.slow
@pytest.mark.parametrize("engine", ENGINES)
def test_a_channel_floor_raised_into_the_arc_fails_where_it_blocks(tmp_path, engine):
    p, _ = _pair_1(raise_floor(tmp_path, 0.020), engine)
    assert not p["passed"] and p["rule"] == "blocked-in-channel", p
    assert p["reason"].startswith("the channel between Entry1 and Exit1 is blocked ")
    assert " mm past Entry1 by Phantom: the needle's" in p["reason"]
    assert "Phantom lies in the needle's path between Entry1 and Exit1 (from 3.6 to 7.8 mm past Entry1)" in p["reason"]


@pytest.mark.slow
@pytest.mark.parametrize("engine", ENGINES)
def test_a_phantom_raised_under_its_holes_fails_and_says_so(tmp_path, engine):
    p, _ = _pair_1(raise_phantom(tmp_path), engine)
    assert not p["passed"] and p["rule"] in ("blocked-at-entry", "blocked-in-channel", "blocked-at-exit"), p
    assert "Phantom" in p["reason"] and "the tissue's surface is 4.0 mm above Entry1 and Exit1" in p["reason"]


@pytest.mark.slow
@pytest.mark.parametrize("engine", ENGINES)
def test_the_phantom_in_its_own_file_passes_with_its_contacts_recorded(tmp_path, engine):
    p, m = _pair_1(phantom_in_own_file(tmp_path), engine)
    assert p["passed"], p
    assert m["needle_tissue_contact_n"]["pick up"]["Phantom"] > 0.1
    assert max(m["thread_tissue_contact_n"]["pull 1"].values()) > 0.1


@pytest.mark.slow
@pytest.mark.parametrize("engine", ENGINES)
def test_the_solid_phantom_in_its_own_file_fails_at_the_entry(tmp_path, engine):
    p, _ = _pair_1(phantom_in_own_file(tmp_path, filled=True), engine)
    assert not p["passed"] and p["rule"] == "blocked-at-entry", p
    assert "Phantom" in p["reason"] and "before the run: Phantom lies in the needle's path" in p["reason"]


@pytest.mark.slow
def test_filled_holes_fail_at_their_entry_in_mujoco(tmp_path):
    p, _ = _pair_1(fill_holes(tmp_path, (1,)), "mujoco")
    assert not p["passed"] and p["rule"] == "blocked-at-entry", p


def test_the_hand_back_path_carries_the_tail_on_a_straight_line():
    """SutureTask.about_tail: from pose a to pose b the needle's tail (where the thread is tied)
    runs on the straight line between its two places while the needle turns about it, and the
    path starts at a and ends at b."""
    from types import SimpleNamespace

    import numpy as np

    from adfkit.runner.rotations import rotation_exp
    from adfkit.tasks.suture import SutureTask

    tail = np.array([0.01, -0.004, 0.0])
    a, b = np.eye(4), np.eye(4)
    a[:3, 3] = [0.02, 0.01, 0.05]
    b[:3, :3], b[:3, 3] = rotation_exp(np.array([0.2, -1.1, 2.0])), [-0.03, 0.04, 0.08]
    path = SutureTask.about_tail(SimpleNamespace(geom=SimpleNamespace(tail=tail)), a, b)
    assert np.allclose(path(0.0), a, atol=1e-12) and np.allclose(path(1.0), b, atol=1e-12)
    ta, tb = (p[:3, :3] @ tail + p[:3, 3] for p in (a, b))
    for s in np.linspace(0.05, 0.95, 7):
        p = path(s)
        at = p[:3, :3] @ tail + p[:3, 3]
        off = (at - ta) - np.dot(at - ta, tb - ta) / np.dot(tb - ta, tb - ta) * (tb - ta)
        assert np.linalg.norm(off) < 1e-12  # on the line
    mid = path(0.5)  # the needle's centre does not go straight: it turns about the tail
    assert np.linalg.norm(mid[:3, 3] - (a[:3, 3] + b[:3, 3]) / 2) > 1e-3


def test_a_take_reaims_where_its_grasp_moved_past_the_jaws_room():
    """motions._apart, what Motions.take compares with REAIM: a grasp pose shifted or turned
    (a turn counts as the arc it sweeps at the jaws' depth) is that far from where it was aimed;
    1.7 mm and 6 degrees (the springy-holes copy's seed 1 at hand back 3) re-aim, the 0.5-0.6 mm
    a needle settling on the tissue moves it at the pick-up does not."""
    import numpy as np

    from adfkit.runner.rotations import rotation_exp
    from adfkit.tasks.grasping import JAW_DEPTH
    from adfkit.tasks.motions import REAIM, _apart

    a = np.eye(4)
    a[:3, 3] = [0.01, 0.02, 0.03]
    shifted, turned = a.copy(), a.copy()
    shifted[:3, 3] += [0.0003, -0.0004, 0.0]
    turned[:3, :3] = rotation_exp(np.array([0.0, 0.0, 0.3]))
    assert abs(_apart(a, shifted) - 0.0005) < 1e-12 and abs(_apart(a, turned) - 0.3 * JAW_DEPTH) < 1e-12
    assert _apart(a, a) == 0.0 and _apart(a, shifted) < REAIM
    seed_1 = a.copy()
    seed_1[:3, :3] = rotation_exp(np.radians([0.0, 6.0, 0.0]))
    seed_1[:3, 3] += [0.0, -0.0017, 0.0]
    assert _apart(a, seed_1) > REAIM


def test_a_joint_move_onto_a_limit_stays_within_it():
    """Motions.move_jp from a wrist yaw of -0.5207 rad to its upper limit (a goal ``move``
    clipped there): the line q0 + (q1 - q0) * s rounds to one ulp past the limit at its end,
    which servo_jp refuses (a phantom's carry 1 stopped so, its plan good); the move ends on the
    limit, every set-point on the way within it."""

    from suture_phantoms import BUNDLED

    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.tasks.suture import SutureTask

    world = open_world(load_scene(BUNDLED / "launch.yaml"), Options(renderer="tiny", visuals=False))
    try:
        task = SutureTask(world, [1], seed=0)
        task.phase = "test"
        psm = next(iter(task.psms.values()))
        hi = float(psm.kin.upper_limits[5])
        q0 = psm.setpoint_jp().copy()
        q0[5] = -0.520749
        assert q0[5] + (hi - q0[5]) * 1.0 > hi  # the straight line's end, as floats add it
        psm.servo_jp(q0)
        q1 = q0.copy()
        q1[5] = hi
        seen = []
        for _ in task.move_jp(psm, q1, 0.05, settle=0.0):
            seen.append(psm.setpoint_jp()[5])
        assert seen[-1] == hi and max(seen) <= hi and len(seen) > 2
    finally:
        world.close()
