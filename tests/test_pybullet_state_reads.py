"""AMBF's ghost rule in the PyBullet runner takes the states its control step has already read (the
springs' free bodies, the damped links: PyBulletWorld._state_now) rather than reading them again:
each is what PyBullet gives at that moment, to the bit, including a velocity a ghost set since."""

from __future__ import annotations

from pathlib import Path

import pytest

pb = pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402

BUNDLED = Path(__file__).resolve().parent.parent / "sample_scenes" / "suturing" / "launch.yaml"
#: the options adfkit run and adfkit parity play a scene with (AMBF's ghosts, springs and bodies)
AMBF = dict(visuals=False, ghosts="ambf", springs="ambf", bodies="ambf", control_substeps=4, ground=True)


def test_the_ghosts_take_the_states_read_this_control_step():
    """The bundled suturing scene under adfkit run's options: every state the ghosts ask for over 20
    control steps equals a fresh read, most come from the springs' or the damping's reads.
    Controls: after a physics step the springs' read of a thread body is no longer PyBullet's, nor
    after its velocity was set."""
    w = open_world(load_scene(BUNDLED, None), Options(**AMBF))
    try:
        w.step(100)
        asked, now = [], w._state_now

        def checked(sb):
            key = (sb.uid, sb.link)
            where = (
                "reset"
                if key in w._reset_now
                else "read"
                if w.springs.last_state(key) or key in w.link_damping.read
                else "new"
            )
            got = now(sb)
            asked.append((where, got == sb.state()))
            return got

        w._state_now = checked
        w.step(20)
        del w._state_now
        assert asked and all(same for _w, same in asked), asked
        where = [w_ for w_, _s in asked]
        assert where.count("read") + where.count("reset") > where.count("new"), where
        # controls: the springs' last read goes stale after a physics step, and after a velocity set
        thread = next(sb for sb in w.springs.bodies if sb.link < 0 and not sb.static)
        key = (thread.uid, -1)
        w.control()
        assert w.springs.last_state(key) == thread.state()
        pb.stepSimulation(physicsClientId=w.cid)
        assert w.springs.last_state(key) != thread.state()
        w.control()
        pb.resetBaseVelocity(thread.uid, [0.0, 0.0, 0.01], [0.0, 0.0, 0.0], physicsClientId=w.cid)
        assert w.springs.last_state(key) != thread.state()
    finally:
        w.close()


def test_a_velocity_a_ghost_set_is_the_state_asked_after_it(tmp_path):
    """The parity scene's cube resting in its ghost slab: the ghost sets its velocity each control
    step; asked after that, its state is PyBullet's with that velocity (_reset_now), to the bit.
    Control: the cube's state read before the ghosts acted differs from it."""
    from adfkit.scenes.parity import write_parity

    w = open_world(load_scene(write_parity(tmp_path), [3]), Options(visuals=False, ghosts="ambf"))
    try:
        w.step(60)
        cube = w.body("cube")
        key = (cube.uid, -1)
        before = cube.state()
        w.control()
        assert key in w._reset_now
        assert w._state_now(cube) == cube.state()
        assert cube.state()[:2] == before[:2] and cube.state()[2:] != before[2:]
    finally:
        w.close()


def test_the_ghosts_ask_no_distance_of_a_body_without_points_in_their_pass(monkeypatch):
    """AMBF's rule acts on the points of the ghosts' pass alone: on the bundled suturing set at rest
    a ghost asks PyBullet's distance query only of the bodies near it with penetrating points, and
    finds the bodies the query over all of them finds inside. Control: without the pass's points
    (the ghosts' friction, overlapping()) every body near it is asked."""
    w = open_world(load_scene(BUNDLED, None), Options(**AMBF))
    try:
        w.step(100)
        manifolds = w._manifold_points(w._acting_ghosts, {})
        real, asked = pb.getClosestPoints, []
        monkeypatch.setattr(pb, "getClosestPoints", lambda *a, **kw: asked.append(a[:2]) or real(*a, **kw))
        near = skipped = 0
        for g in w._acting_ghosts:
            keys = [k for k in w._near_keys[g.uid] if k in w._dynamic_lookup]
            inside = {k for k in keys if real(g.uid, k[0], 0.0, -1, k[1], physicsClientId=w.cid)}
            del asked[:]
            found = w._overlap(g, None, with_parent=True, manifolds=manifolds)
            assert {(sb.uid, sb.link) for sb in found} == inside, g.key
            assert all(n > 0 for _sb, n in g.points)
            near, skipped = near + len(keys), skipped + len(keys) - len(asked)
            del asked[:]
            w._overlap(g, None, with_parent=True)
            assert len(asked) == len(keys)
        assert near > 0 and skipped > near // 2, (near, skipped)
    finally:
        w.close()
