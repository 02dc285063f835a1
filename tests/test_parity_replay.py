"""The suture replayed in AMBF (`adfkit parity --suture`): what the recording tells AMBF beyond
set-points and grasps. The tests that play AMBF skip, with the reason, where no AMBF build is
present; the others always run."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pybullet")

from adfkit.parity import ambf, suture  # noqa: E402
from adfkit.parity.traces import from_ambf  # noqa: E402

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)
ROOT = Path(__file__).resolve().parents[1]


def _recording_setup(launch: Path, indices):
    """adfkit's suture on ``launch`` recorded for AMBF through its first control step: where the
    setup puts the arms, their first set-points, the pairs the task lets pass through each
    other (and the needle's push)."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.tasks.suture import SutureTask

    world = open_world(load_scene(launch, indices), Options(renderer="tiny", visuals=False))
    try:
        task = SutureTask(world, [1], seed=0)
        rec = suture._Recorder(world, task)
        assert not [c for c in rec.commands if c.kind == "collide"]  # nothing before the task says so
        steps = task.steps()
        next(steps)
        world.step(1)
        return rec, task, world
    finally:
        world.close()


def test_the_recording_tells_ambf_which_pairs_the_suture_lets_pass():
    """The suture lets the two arms' links pass through each other (SutureTask._arms_apart):
    every pair of a psm1 link and a psm2 link is written as a `collide A B 0` command at the
    start, by the names AMBF gives the bodies, and adfkit's own world has those pairs off."""
    rec, task, world = _recording_setup(ROOT / "sample_scenes" / "suturing" / "launch.yaml", None)
    collide = [c for c in rec.commands if c.kind == "collide"]
    links = {n: {suture._name(sb) for sb in task.roles.robots[n]} for n in ("psm1", "psm2")}
    assert len(links["psm1"]) == len(links["psm2"]) == 9
    assert {(c.target, c.body) for c in collide} == {(a, b) for a in links["psm1"] for b in links["psm2"]}
    assert all(c.t == 0.0 and c.value == 0.0 for c in collide)
    assert collide[0].line() == f"0.0 collide {collide[0].target} {collide[0].body} 0"
    assert len(world._pairs_off) == 81


@needs_ambf
def test_a_collide_command_lets_two_bodies_pass_through_each_other_in_ambf(tmp_path, monkeypatch):
    """The parity stack's top box (8 cm) told to pass through the box under it (14 cm) falls
    through it onto the bottom box; let collide again at the same instant it rests on it, as
    with no command (the control). The plugin's contact record (ADFKIT_PARITY_CONTACTS) lists
    the pair's manifold where they touch, and none where they pass."""
    from adfkit.scenes.parity import write_parity

    monkeypatch.setenv("ADFKIT_PARITY_CONTACTS", "1")
    stage = ambf.Stage(write_parity(tmp_path), [2])
    top, middle, bottom = "/ambf/env/stack/box3", "/ambf/env/stack/box2", "/ambf/env/stack/box1"
    off = ambf.Command(0.0, "collide", top, 0.0, body=middle)
    on = ambf.Command(0.0, "collide", top, 1.0, body=middle)

    def played(commands) -> tuple[float, set]:
        run = ambf.run(BUILD, stage, 1.0, 0.5, commands)
        tr = from_ambf(run)
        touching = {frozenset(c[:2]) for c in run.samples[-1]["contacts"] if c[3] < 1e-4}
        return float(tr.poses[-1, tr.body_names.index(top), 2]), touching

    resting, touching = played([])
    # the stack settled: 0.2 m, 0.14 m and 0.08 m boxes, the top one's centre 0.38 m up
    assert resting == pytest.approx(0.38, abs=0.003) and frozenset((top, middle)) in touching
    z, touching = played([off, on])
    assert z == pytest.approx(resting, abs=1e-4) and frozenset((top, middle)) in touching
    # through the middle box onto the bottom one: 0.2 + 0.04 m up, 0.14 m lower
    z, touching = played([off])
    assert z == pytest.approx(0.24, abs=0.003)
    assert frozenset((top, bottom)) in touching and frozenset((top, middle)) not in touching
