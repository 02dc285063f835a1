"""The suture's verdicts in AMBF as rates (`adfkit parity --suture --trials K`): the nudge each
trial gives the recording, the rates read from the trials' verdicts, and the premise that AMBF
repeats a replay to the bit and a nudge moves it. The test that plays AMBF skips, with the
reason, where no AMBF build is present."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pybullet")

from adfkit.parity import ambf, suture, trials  # noqa: E402
from adfkit.parity.traces import from_ambf  # noqa: E402

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)
ROOT = Path(__file__).resolve().parents[1]


def _recorded(steps: int = 3) -> suture.Recording:
    """The bundled suture's first control steps, recorded with the measured joints."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.tasks.suture import SutureTask

    world = open_world(
        load_scene(ROOT / "sample_scenes" / "suturing" / "launch.yaml", None), Options(renderer="tiny", visuals=False)
    )
    try:
        task = SutureTask(world, [1], seed=0)
        rec = suture._Recorder(world, task, measured=True)
        next(task.steps())
        world.step(steps)
        return suture.Recording(
            rec.commands, 0.0, [], np.zeros((0, 4)), [], None, [], "", [], prismatic=frozenset(rec.prismatic)
        )
    finally:
        world.close()


def test_a_nudge_offsets_each_psm_joint_by_one_signed_constant():
    """Every PSM joint's set-points and measured path move by the same ±1e-4 rad (the two
    insertions, prismatic, ±1e-5 m); the other commands (place, collide, the push) are as
    recorded; the signs differ between joints and between draws. Control: the recording's own
    values are not already offset (a nudge of 0 gives them back)."""
    rec = _recorded()
    assert len(rec.prismatic) == 2 and all("insertion" in n.lower() for n in rec.prismatic)
    rng = np.random.default_rng(0)
    a = trials.nudged(rec, trials.Nudge(1e-4, 1e-5), rng)
    b = trials.nudged(rec, trials.Nudge(1e-4, 1e-5), rng)
    assert len(a) == len(rec.commands)
    offsets: dict[str, set[float]] = {}
    for c, n in zip(rec.commands, a, strict=True):
        assert (c.t, c.kind, c.target, c.body, c.numbers) == (n.t, n.kind, n.target, n.body, n.numbers)
        if c.kind in ("position", "follow"):
            offsets.setdefault(c.target, set()).add(round(n.value - c.value, 12))
        else:
            assert n.value == c.value
    assert len(offsets) == 16 and all(len(v) == 1 for v in offsets.values())
    for name, (d,) in offsets.items():
        assert abs(d) == pytest.approx(1e-5 if name in rec.prismatic else 1e-4)
    assert {np.sign(d) for (d,) in offsets.values()} == {-1.0, 1.0}
    signs_b = {c.target: np.sign(n.value - c.value) for c, n in zip(rec.commands, b, strict=True) if c.kind == "follow"}
    assert signs_b != {k: np.sign(next(iter(v))) for k, v in offsets.items()}
    zero = trials.nudged(rec, trials.Nudge(0.0, 0.0), np.random.default_rng(0))
    assert [c.value for c in zero] == [c.value for c in rec.commands]


def test_the_rates_count_adfkits_verdict_among_ambfs_and_see_a_flip():
    """Pair 1 passed on both sides in every trial: rate 1, no flip; pair 2 adfkit passed, AMBF
    failed in one trial of three: rate 2/3 and a flip; a change of rule alone is a flip too."""

    def v(pair, verdict, rule=None):
        return {"pair": pair, "verdict": verdict, "rule": rule}

    mine = [v(1, "passed"), v(2, "passed"), v(3, "failed", "slip")]
    runs = [
        ([v(1, "passed"), v(2, "passed"), v(3, "failed", "slip")], {1: 0.001, 2: 0.002, 3: 0.003}),
        ([v(1, "passed"), v(2, "failed", "thread-not-through"), v(3, "failed", "entry-missed")], {1: 0.001}),
        ([v(1, "passed"), v(2, "passed"), v(3, "failed", "slip")], {}),
    ]
    out = trials.rates(mine, runs)
    p1, p2, p3 = out["pairs"]
    assert (p1["same"], p1["same_rate"], p1["ambf_flips"]) == (3, 1.0, False)
    assert (p2["same"], p2["ambf_flips"]) == (2, True) and p2["same_rate"] == pytest.approx(2 / 3)
    assert p2["ambf_rules"] == [None, "thread-not-through", None]
    assert (p3["same"], p3["ambf_flips"]) == (3, True)  # failed every time, by another rule once
    assert p1["tip_path_gap_m"] == [0.001, 0.001, None]
    assert out["same_rate"] == pytest.approx((1 + 2 / 3 + 1) / 3)


@needs_ambf
def test_ambf_repeats_a_replay_to_the_bit_and_a_nudge_moves_it(tmp_path):
    """The parity arm's joint following a path twice in AMBF: the same poses to the bit; the
    same path nudged 1e-4 rad: the joint stands 1e-4 rad over (within 2e-5 past the first
    steps) and the arm's poses differ. What the trials' rates rest on."""
    from adfkit.scenes.parity import write_parity

    stage = ambf.Stage(write_parity(tmp_path), [1])
    joint = "/ambf/env/arm/base-arm"
    ts = np.arange(0.0, 0.5 + 1e-9, 0.004)
    cmds = [ambf.Command(float(t), "follow", joint, float(0.5 * np.sin(2 * np.pi * t))) for t in ts]
    rec = suture.Recording(cmds, 0.5, [], np.zeros((0, 4)), [], None, [], "", [])
    runs = [from_ambf(ambf.run(BUILD, stage, 0.5, 0.02, c)) for c in (cmds, cmds)]
    nudged = trials.nudged(rec, trials.Nudge(1e-4, 1e-5), np.random.default_rng(1))
    sign = np.sign(nudged[0].value - cmds[0].value)
    moved = from_ambf(ambf.run(BUILD, stage, 0.5, 0.02, nudged))
    assert np.array_equal(runs[0].poses, runs[1].poses) and np.array_equal(runs[0].joints, runs[1].joints)
    j = runs[0].joint_names.index(joint)
    d = (moved.joints[:, j] - runs[0].joints[:, j])[5:]
    assert np.allclose(d, sign * 1e-4, atol=2e-5)
    assert not np.array_equal(moved.poses, runs[0].poses)


@needs_ambf
def test_trials_follow_the_measured_joints_so_a_pace_is_a_bad_option(capsys):
    """--trials replays follow adfkit's measured joints: with --pace on it is the user's error
    (exit 2, before any suture is played), as are no trials, a nudge of 0, NaN, infinite or
    negative, and trials without --suture."""
    from adfkit.cli import main

    launch = ROOT / "sample_scenes" / "suturing" / "launch.yaml"
    assert main(["parity", "--suture", str(launch), "--trials", "3", "--pace", "on"]) == 2
    assert "--trials replays follow adfkit's measured joints" in capsys.readouterr().err
    assert main(["parity", "--suture", str(launch), "--trials", "2", "--nudge", "0"]) == 2
    assert "--nudge a positive offset" in capsys.readouterr().err
    assert main(["parity", "--suture", str(launch), "--trials", "0"]) == 2
    assert "--trials takes 1 or more" in capsys.readouterr().err
    for bad in ("nan", "inf", "-1e-4"):
        assert main(["parity", "--suture", str(launch), "--trials", "2", f"--nudge={bad}"]) == 2
        assert "--nudge a positive offset" in capsys.readouterr().err
    assert main(["parity", str(launch), "--trials", "3"]) == 2  # a scene's parity is not a suture's
    assert "--trials replays a suture" in capsys.readouterr().err
    assert main(["parity", str(launch), "--grasp", "adfkit"]) == 2  # nor is its grasp
    assert "--grasp is how a suture's replay grasps" in capsys.readouterr().err


def test_the_trials_are_printed_per_pair_and_any_other_verdict_fails(monkeypatch, capsys):
    """The text names each pair's AMBF rules in trial order, how many were adfkit's verdict and
    when AMBF's own flipped; exit 1 when any trial differs from adfkit's on any pair, 0 when none
    does. The nudge reaches compare_trials as named (a prismatic joint a tenth of it in m)."""
    from adfkit.cli import main

    seen = {}

    def fake(path, indices, pairs, build, count, nudge, seed, progress, options, grasp):
        seen.update(count=count, nudge=nudge, seed=seed, grasp=grasp)
        same = seen.get("same", 1)
        runs = [([{"pair": 1, "verdict": "passed", "rule": None}], {1: 0.0019})] * count
        if not same:
            runs[-1] = ([{"pair": 1, "verdict": "failed", "rule": "thread-not-through"}], {1: 0.006})
        out = trials.rates([{"pair": 1, "verdict": "passed", "rule": None}], runs)
        return {"seconds": 89.0, "trials": out | {"count": count}}

    monkeypatch.setattr(trials, "compare_trials", fake)
    monkeypatch.setattr(ambf, "find_build", lambda path: None)
    assert main(["parity", "--suture", "--pairs", "1", "--trials", "3", "--nudge", "2e-4", "--seed", "5"]) == 0
    assert seen["count"] == 3 and seen["nudge"] == trials.Nudge(2e-4, 2e-5) and seen["seed"] == 5
    assert seen["grasp"] == "lies"
    text = capsys.readouterr().out
    assert "replayed in AMBF 3 times" in text and "pair 1: adfkit passed; AMBF passed, passed, passed" in text
    assert "adfkit's verdict 3 of 3" in text and "flips" not in text and "1.9-1.9 mm" in text
    assert main(["parity", "--suture", "--pairs", "1", "--trials", "3", "--grasp", "adfkit"]) == 0
    assert seen["grasp"] == "adfkit"
    capsys.readouterr()
    seen["same"] = 0
    assert main(["parity", "--suture", "--pairs", "1", "--trials", "3"]) == 1
    text = capsys.readouterr().out
    assert "AMBF passed, passed, thread-not-through: adfkit's verdict 2 of 3" in text
    assert "AMBF's own verdict changes with the nudge" in text and "1.9-6.0 mm" in text
