"""What the MuJoCo runner keeps between control steps under AMBF's ghost rule (ghosts.py:
each ghost pair's distance while neither of its bodies moves, the ghosts' answers and the
rule's plan while nothing changed them, the held bodies weightless through MuJoCo's gravity
compensation, under which they may sleep) must follow what moves."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from adfkit.adf import load_scene
from adfkit.runner import Options, open_world


@pytest.fixture
def ghost_world(tmp_path):
    """The parity scene's cube, dropped into a ghost slab on a static post, at rest in it."""
    from adfkit.scenes.parity import write_parity

    launch = write_parity(tmp_path)
    world = open_world(load_scene(launch, [3]), Options(visuals=False, ghosts="ambf"), engine="mujoco")
    try:
        world.run(0.4)
        yield world
    finally:
        world.close()


def _points(world) -> list:
    (g,) = world.ghosts
    return [(sb.name, n) for sb, n in g.points]


def test_a_body_at_rest_in_a_ghost_sleeps_weightless_and_stays(ghost_world):
    """The cube held in the slab (4 points, box in box) falls asleep there, weightless: MuJoCo's
    gravity compensation, not a force, which would wake it every control step; it stays to the
    last bit while it sleeps, its points counted still (the collision pass runs with sleeping
    off: MuJoCo collides no pair of a sleeping and a static body)."""
    w = ghost_world
    cube = w.body("cube")
    assert _points(w) == [("cube", 4)]
    assert w.data.body_awake[cube.id] == 0 and w.model.body_gravcomp[cube.id] == 1.0
    z = cube.com_position()[2]
    w.run(0.2)
    assert cube.com_position()[2] == z and _points(w) == [("cube", 4)]
    assert w.model.body_gravcomp[w.body("twin").id] == 0.0  # the twin, on the floor beside it, is not held


def test_a_ghost_moved_off_a_sleeping_body_lets_it_fall(ghost_world):
    """The post and its ghost moved 1 cm down under the sleeping cube, which no longer
    penetrates it (9 mm apart; their bounding spheres still overlap, so only the pair's distance
    taken again tells): the next control step finds nothing in the ghost and gives the cube its
    weight back (woken: it falls); in the ghost again 1 cm lower, it is held there. Kept
    answers that did not follow the ghost would hang the cube where it was. Control: the post
    not moved, the cube stays in it."""
    w = ghost_world
    cube, post = w.body("cube"), w.body("post")
    z = cube.com_position()[2]
    t = post.world_matrix()
    t[2, 3] -= 0.01
    w.move_base(post, t)
    w.step(1)
    assert _points(w) == []
    assert w.model.body_gravcomp[cube.id] == 0.0
    w.step(5)
    assert cube.com_position()[2] < z - 1e-5  # falling
    w.run(0.3)
    assert _points(w) == [("cube", 4)]
    assert cube.com_position()[2] == pytest.approx(z - 0.01, abs=1.5e-3)


def test_the_plan_follows_a_body_that_enters_a_ghost(ghost_world):
    """A ghost answer that changes (the twin lifted into the slab beside the sleeping cube, by
    its free joint) makes the rule's plan again: the twin is held weightless with the cube, and
    its velocity is the rule's share of what it was (0.9^(points·4) a control step)."""
    w = ghost_world
    twin, cube = w.body("twin"), w.body("cube")
    m, d = w.model, w.data
    adr = m.jnt_qposadr[m.body_jntadr[twin.id]]
    dof = m.jnt_dofadr[m.body_jntadr[twin.id]]
    d.qpos[adr : adr + 3] = np.array(d.xipos[cube.id]) + np.array([0.0, 0.06, 0.0])
    d.qvel[dof : dof + 3] = (0.0, 0.0, 0.01)
    w.wake(twin)
    w.step(2)  # the twin woken where it was put, then found in the ghost
    names = [n for n, _ in _points(w)]
    assert sorted(names) == ["cube", "twin"]
    assert w.model.body_gravcomp[twin.id] == 1.0
    points = dict(_points(w))["twin"]
    before = float(d.qvel[dof + 2])
    w.step(1)
    after = float(d.qvel[dof + 2])
    assert after == pytest.approx(before * 0.9 ** (points * w.opt.control_substeps), rel=0.05)


def _afresh(world, fresh) -> list:
    """The ghosts' answers for ``world``'s state made by ``fresh`` (a world of the same scene)
    with nothing kept: its state set to ``world``'s, its caches dropped."""
    m, d = fresh.model, fresh.data
    d.qpos[:], d.qvel[:] = world.data.qpos, world.data.qvel
    mujoco.mj_forward(m, d)
    fresh._ghost_row_of, fresh._collider_key = None, None
    return [[(sb.name, n) for sb, n in found] for found in fresh._penetrating(fresh.ghosts)]


def test_kept_answers_are_those_made_afresh_step_by_step(tmp_path):
    """Step by step, while the cube falls into the slab and comes to rest and the twin is put
    into it beside the cube, the ghost's answer (with its rigid pairs looked at
    once, a pair's distance taken again only when one of its bodies moved, the collision pass's
    masks kept per set of pairs) is the one made with nothing kept. Control: a world whose pairs
    never take their distances again (as if no body moved) misses the cube entering."""
    from adfkit.scenes.parity import write_parity

    launch = write_parity(tmp_path)
    scene = load_scene(launch, [3])
    opt = Options(visuals=False, ghosts="ambf")
    world, fresh, stale = (open_world(scene, opt, engine="mujoco") for _ in range(3))
    try:
        twin = world.body("twin")
        m, d = world.model, world.data
        adr = m.jnt_qposadr[m.body_jntadr[twin.id]]
        seen, missed = set(), 0
        for k in range(160):
            if k == 100:  # the twin into the slab beside the cube, by its free joint
                d.qpos[adr : adr + 3] = np.array(d.xipos[world.body("cube").id]) + np.array([0.0, 0.06, 0.0])
                mujoco.mj_kinematics(m, d)
                world.wake(twin)
            # the answer made afresh for the state the next control step starts from
            expected, stale_expected = _afresh(world, fresh)[0], _afresh(stale, fresh)[0]
            world.step(1)
            stale.step(1)
            if k == 0:
                stale._pair_at[:] = 1 << 60  # every distance "taken" after any move
            assert _points(world) == expected
            seen.add(tuple(expected))
            missed += _points(stale) != stale_expected
        assert {(), (("cube", 4),)} <= seen and any(len(a) == 2 for a in seen)
        assert missed > 0
    finally:
        for w in (world, fresh, stale):
            w.close()
