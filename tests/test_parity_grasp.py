"""Where the suture's replay holds the needle in AMBF's jaws (`adfkit parity --suture --grasp`):
the recording writes each grasp with the needle's frame in the tool's, and AMBF's constraint
actuator, given it as its offset, holds the needle there; without it, where the needle lies. The
test that plays AMBF skips, with the reason, where no AMBF build is present."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pybullet")

from adfkit.parity import ambf, suture  # noqa: E402
from adfkit.parity.traces import from_ambf  # noqa: E402
from adfkit.runner.rotations import invert, matrix_to_pq, pose_matrix  # noqa: E402

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)
LAUNCH = Path(__file__).resolve().parents[1] / "sample_scenes" / "suturing" / "launch.yaml"


def _at_start():
    """The bundled scene's world and suture task at the start, a recorder on it, psm2's actuator."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.tasks.suture import SutureTask

    world = open_world(load_scene(LAUNCH, None), Options(renderer="tiny", visuals=False))
    task = SutureTask(world, [1], seed=0)
    rec = suture._Recorder(world, task)
    act = next(a for a in world.actuators if "/psm2/" in a.key or "/psm2/" in a.parent.key)
    return world, task, rec, act


def _relation(numbers) -> np.ndarray:
    return pose_matrix(np.array(numbers[:3]), np.array(numbers[3:]))


def test_a_grasp_is_recorded_with_the_needle_where_adfkits_jaws_hold_it():
    """The grasp command carries the needle's frame in the tool's frame as adfkit's grasp took it
    (to 1e-9), written after the body, and `--grasp adfkit` plays it so; the default (`lies`) plays
    it without (the needle taken where it lies in AMBF), and an unknown choice is an error."""
    world, task, rec, act = _at_start()
    try:
        world.actuate(act, task.needle)
        want = invert(act.parent.world_matrix()) @ task.needle.world_matrix()
    finally:
        world.close()
    (g,) = [c for c in rec.commands if c.kind == "grasp"]
    assert g.body == suture._name(task.needle) and len(g.numbers) == 7
    assert np.allclose(_relation(g.numbers), want, atol=1e-9)
    assert np.linalg.norm(want[:3, 3]) > 0.01  # the needle far from the tool at the start: not an identity
    assert g.line().split()[1:4] == ["grasp", g.target, g.body] and len(g.line().split()) == 11
    full = suture.Recording(rec.commands, 0.0, [], np.zeros((0, 4)), [], None, [], "", [])
    (held,) = [c for c in full.commands_for("commands", "adfkit") if c.kind == "grasp"]
    (lies,) = [c for c in full.commands_for("commands") if c.kind == "grasp"]
    assert held.numbers == g.numbers and lies.numbers == () and lies.line() == f"{g.t!r} grasp {g.target} {g.body}"
    with pytest.raises(ValueError, match="grasp is one of"):
        full.commands_for("commands", "tight")


@needs_ambf
def test_ambfs_actuator_holds_the_needle_at_the_offset_it_is_given():
    """In AMBF, psm2's constraint actuator grasps the bundled needle at the start (59 mm from the
    tool, the arm limp) three ways, 0.5 s each: where the needle lies; given the relation it lies
    at, which the plugin turns into AMBF's offset as AMBF does (the same poses, within 0.05 mm,
    at every sample); given that relation with the needle 3 mm higher in the world, where it then
    stands in the tool's frame (within 1 mm: the limp arm swings it on its 59 mm lever) and not
    where it lay (over 2 mm)."""
    world, task, rec, act = _at_start()
    try:
        tool_w, needle_w = act.parent.world_matrix(), task.needle.world_matrix()
        names = suture._name(act), suture._name(act.parent), suture._name(task.needle)
    finally:
        world.close()
    lifted = needle_w.copy()
    lifted[2, 3] += 0.003
    rel0, rel3 = invert(tool_w) @ needle_w, invert(tool_w) @ lifted
    stage = ambf.Stage(LAUNCH.resolve(), suture._all(LAUNCH))
    got = []
    for numbers in ((), tuple(np.r_[matrix_to_pq(rel0)]), tuple(np.r_[matrix_to_pq(rel3)])):
        cmds = [ambf.Command(0.0, "grasp", names[0], body=names[2], numbers=numbers)]
        trace = from_ambf(ambf.run(BUILD, stage, 0.5, 0.05, cmds))
        tool, needle = (trace.poses[:, trace.body_names.index(n)] for n in names[1:])
        got.append(
            np.array(
                [(invert(pose_matrix(t[:3], t[3:])) @ pose_matrix(n[:3], n[3:]))[:3, 3] for t, n in zip(tool, needle)]
            )
        )
    assert len(got[0]) >= 10 and np.abs(got[1] - got[0]).max() < 5e-5
    later = got[2][2:]
    assert np.linalg.norm(later - rel3[:3, 3], axis=1).max() < 1e-3
    assert np.linalg.norm(later - rel0[:3, 3], axis=1).min() > 2e-3


def _held(needle_x) -> tuple:
    """A recording of one grasp (psm2, at 0.1 s) and a synthetic AMBF trace, every 20 ms, of its
    tool at rest and the needle's frame at ``needle_x(t)`` along x."""
    from types import SimpleNamespace

    from adfkit.parity.traces import Trace

    times = np.arange(51) * 0.02
    poses = np.zeros((len(times), 2, 7))
    poses[:, :, 6] = 1.0
    poses[:, 0, 0] = [needle_x(t) for t in times]
    names = ["/n/Needle", "/n/Tool"]
    trace = Trace("ambf", {"body": names, "joint": []}, names, times, poses, [], np.zeros((len(times), 0)), 0.0)
    geom = SimpleNamespace(tip=np.array([0.01, 0.0, 0.0]), tail=np.array([-0.01, 0.0, 0.0]), arc_in_needle=np.eye(4))
    task = SimpleNamespace(pairs=[], geom=geom)
    rec = suture.Recording(
        [], 1.0, [("carry 1", 0.0)], np.zeros((0, 4)), [], task, [], "/n/Needle", [],
        grasps=[(0.1, "psm2", "/n/Needle")], tools={"psm2": "/n/Tool"},
    )  # fmt: skip
    return rec, trace


def test_a_held_grasps_slip_is_read_from_where_the_constraint_pulled_the_needle():
    """Under `--grasp adfkit` AMBF's constraint pulls the needle from where it lay (3 mm off) to
    where adfkit's grasp held it within 60 ms: no slip, read from where it stands 0.25 s after
    the grasp; read from where it lay at the grasp (`lies`), the pull is a 3 mm slip. Control: a
    needle that then moves 3 mm in the jaws slips under either."""

    def pulled(t):
        return 0.003 if t <= 0.1 else max(0.0, 0.003 - (t - 0.1) * 0.05)

    rec, trace = _held(pulled)
    assert suture.AmbfObservation(rec, trace, "adfkit").slips == []
    (slip,) = suture.AmbfObservation(rec, trace, "lies").slips
    assert slip["slip_m"] == pytest.approx(0.003) and slip["arm"] == "psm2" and slip["phase"] == "carry 1"
    rec, trace = _held(lambda t: pulled(t) + (0.003 if t >= 0.6 else 0.0))
    (slip,) = suture.AmbfObservation(rec, trace, "adfkit").slips
    assert slip["t"] == pytest.approx(0.6) and slip["slip_m"] == pytest.approx(0.003)
