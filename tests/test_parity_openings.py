"""How far joints stand open on each side of a parity run (adfkit/parity/openings.py): read from
body poses alone, so the engines' own traces are tested here without AMBF (test_parity.py reads
AMBF's)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.parity.openings import Pivots, holds_pivots, opening, openings, shut_pivots  # noqa: E402
from adfkit.parity.traces import AdfkitPlayer, Trace  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402


@pytest.fixture(scope="module")
def thread_scene(tmp_path_factory):
    from adfkit.scenes.parity import write_parity

    return write_parity(tmp_path_factory.mktemp("parity")).parent / "launch.yaml"


def _trace(poses) -> Trace:
    poses = np.asarray(poses, float)
    return Trace("test", {}, ["a", "b"], np.arange(len(poses)) * 0.1, poses, [], np.zeros((len(poses), 0)), 0.0)


def test_an_opening_is_the_distance_between_the_pivots_each_body_carries():
    turned = [0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)]  # 90° about z
    p = Pivots("j", "a", "b", np.array([0.01, 0.0, 0.0]), np.array([0.0, -0.02, 0.0]))
    # shut: a's pivot at (0.01, 0, 0); b turned 90° carries (0, -0.02, 0) to (0.02, 0, 0), placed at -0.01
    shut = [[0, 0, 0, 0, 0, 0, 1], [-0.01, 0, 0, *turned]]
    opened = [[0, 0, 0, 0, 0, 0, 1], [-0.01, 0.003, 0.004, *turned]]
    o = openings(_trace([shut, opened]), [p])
    assert o[0, 0] == pytest.approx(0.0, abs=1e-12)
    assert o[1, 0] == pytest.approx(0.005, abs=1e-12)
    summary = opening(_trace([shut, opened]), [p])
    assert (summary.widest, summary.widest_m, summary.summed_end_m) == ("j", pytest.approx(0.005), pytest.approx(0.005))
    # a trace without one of the joint's bodies has nothing to say about it
    assert opening(_trace([shut]), [Pivots("k", "a", "c", np.zeros(3), np.zeros(3))]) is None


def test_only_joints_that_lock_their_linear_axes_hold_pivots_together(thread_scene):
    from adfkit.model import Joint

    assert holds_pivots(Joint(identifier="JOINT r", type="revolute"))
    assert holds_pivots(Joint(identifier="JOINT f", type="fixed"))
    assert not holds_pivots(Joint(identifier="JOINT s", type="prismatic"))
    assert not holds_pivots(Joint(identifier="JOINT d", type="six dof"))  # linear axes free by default
    scene = load_scene(thread_scene, [4], [])
    springs = [j for m in scene.all_models() for j in m.joints if j.type == "six dof spring"]
    assert len(springs) == 39 and all(holds_pivots(j) for j in springs)  # linear limits 0..0


@pytest.mark.parametrize(
    "engine, widest_mm, summed_mm", [("pybullet", (0.5, 1.5), (15.0, 25.0)), ("mujoco", None, None)]
)
def test_the_falling_threads_joints_open_under_bullets_solver_only(thread_scene, engine, widest_mm, summed_mm):
    pytest.importorskip(engine)
    scene = load_scene(thread_scene, [4], [])
    opt = Options(visuals=False)
    opt.ghosts, opt.springs, opt.link_shapes, opt.bodies = "ambf", "ambf", "body", "ambf"
    w = open_world(scene, opt, engine=engine)
    try:
        player = AdfkitPlayer(w)
        pivots = shut_pivots(w, player.made)
        assert len(pivots) == 40  # the needle's fixed joint and the thread's 39 springs
        o = opening(player.play(0.3, 0.02), pivots)
    finally:
        w.close()
    if widest_mm is None:
        # MuJoCo plays the thread as a tree of hinges: its joints cannot open
        assert o.widest_m < 1e-9 and o.summed_m < 1e-9
    else:
        # measured at 0.3 s: the widest 0.93 mm, 19 mm summed at most (AMBF: 2.0 and 13.2 mm over 2 s)
        assert widest_mm[0] * 1e-3 < o.widest_m < widest_mm[1] * 1e-3
        assert summed_mm[0] * 1e-3 < o.summed_m < summed_mm[1] * 1e-3
