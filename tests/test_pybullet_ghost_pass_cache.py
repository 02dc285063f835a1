"""The ghosts' collision pass (runner/pybullet/ghost_pass.py) runs again only for the ghosts
whose own pose or whose near bodies' poses moved by more than KEPT_WITHIN since their last pass:
what it returns is what a pass of every ghost afresh returns."""

from __future__ import annotations

from pathlib import Path

import pytest

pb = pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402
from adfkit.runner.ghost_rules import SAME_PLACE  # noqa: E402
from adfkit.runner.pybullet.ghost_pass import KEPT_WITHIN, GhostPass  # noqa: E402

BUNDLED = Path(__file__).resolve().parent.parent / "sample_scenes" / "suturing" / "launch.yaml"
#: the options adfkit run and adfkit parity play a scene with (AMBF's ghosts, springs and bodies)
AMBF = dict(visuals=False, ghosts="ambf", springs="ambf", bodies="ambf", control_substeps=4, ground=True)


def _afresh(w, near, poses) -> dict:
    """The counts of a pass of every ghost in ``near`` in a new ghosts' world (nothing kept)."""
    fresh = GhostPass(w)
    try:
        return fresh.counts(near, poses)
    finally:
        fresh.close()


def test_a_pass_of_the_ghosts_that_moved_counts_as_a_pass_of_all():
    """The bundled suturing scene settling under adfkit run's options (its first 80 ms): nine ghosts have bodies near
    them (the thread in the phantom's holes, the PSMs' jaws in their fingers' ghosts), 20
    penetrating points among them. Each control step some ghosts keep their last answer and the
    others are passed again; every step the counts are those of a pass of all nine afresh. Between
    the physics steps of a control step the ghosts with a moving free body near them (the thread's
    elements: ghost_steps.py) are passed again, and count as a pass of them afresh too."""
    w = open_world(load_scene(BUNDLED, None), Options(**AMBF))
    try:
        w.step(20)  # the thread still moving in the holes (at rest by 0.2 s)
        own, seen = w._ghost_pass, []
        counts = own.counts

        def checked(near, poses):
            before = {uid: last[3] for uid, last in own.last.items()}
            made = counts(near, poses)
            kept = sum(1 for g, _pq, _keys in near if made[g.uid] is before.get(g.uid))
            seen.append((len(near), kept, made == _afresh(w, near, poses), sum(sum(c.values()) for c in made.values())))
            return made

        own.counts = checked
        w.step(20)
    finally:
        w.close()
    assert all(same for _n, _k, same, _p in seen), seen
    control = [s for s in seen if s[0] == 9]  # the control steps' passes: every ghost with bodies near
    assert len(control) == 20 and {(n, points) for n, _k, _s, points in control} == {(9, 20)}, seen
    between = [s for s in seen if s[0] != 9]  # three a control step at most, of fewer ghosts
    assert 0 < len(between) <= 3 * 20 and all(n < 9 for n, *_ in between), seen
    kept = [k for _n, k, _s, _p in control]
    assert max(kept) > 0 and min(kept) < 9, kept  # some kept, some passed again


def test_a_ghost_passes_again_once_a_body_near_it_moves_past_kept_within(tmp_path):
    """The parity scene's cube resting in its ghost slab (4 points, box-box): moved by half of
    KEPT_WITHIN the ghost keeps its answer (the same dict, no pass); moved by twice KEPT_WITHIN, or
    after a collision pair changed, it is passed again. Control: the cube moved out past the slab's
    side to 1 mm from it (still near: within the contact threshold) gets what a pass afresh
    makes, no penetrating point, not the 4 kept."""
    from adfkit.scenes.parity import write_parity

    w = open_world(load_scene(write_parity(tmp_path), [3]), Options(visuals=False, ghosts="ambf"))
    try:
        w.step(60)
        (g,) = w.ghosts
        cube = w.body("cube")
        key = (cube.uid, -1)
        gp = w._ghost_pass
        ghost_pq = pb.getBasePositionAndOrientation(g.uid, physicsClientId=w.cid)
        p, q = pb.getBasePositionAndOrientation(cube.uid, physicsClientId=w.cid)

        def counts(dx: float = 0.0) -> dict:
            at = ((p[0] + dx, p[1], p[2]), q)
            return gp.counts([(g, ghost_pq, [key])], {key: at})

        first = counts()
        assert first == {g.uid: {key: 4}}
        assert counts(0.5 * KEPT_WITHIN)[g.uid] is first[g.uid]  # kept: no pass
        moved = counts(2 * KEPT_WITHIN)
        assert moved == first and moved[g.uid] is not first[g.uid]  # passed again: the same points
        w._pairs_epoch += 1  # as set_collision or a grasp does
        assert counts(2 * KEPT_WITHIN)[g.uid] is not moved[g.uid]
        out = counts(dx=0.071)  # the slab's side at x 0.05, the cube 20 mm from its centre to its side
        afresh = _afresh(w, [(g, ghost_pq, [key])], {key: ((p[0] + 0.071, p[1], p[2]), q)})
        assert out == afresh == {g.uid: {}}, (out, afresh)
    finally:
        w.close()


def test_same_place_is_within_same_place_in_every_number_and_never_for_nan():
    """in_same_place, which decides whether a ghost keeps its last pass's points: every number of
    every (position, quaternion) within SAME_PLACE, NaN never (a body read afresh as NaN), equal
    pairs skipped; one number past the bound, anywhere, is enough to pass again."""
    from adfkit.runner.ghost_rules import in_same_place

    a = [((0.1, 0.2, 0.3), (0.0, 0.0, 0.0, 1.0)), ((1.0, 2.0, 3.0), (0.5, 0.5, 0.5, 0.5))]
    assert in_same_place(a, [tuple(map(tuple, pq)) for pq in a])
    near = [((0.1 + 0.9 * SAME_PLACE, 0.2, 0.3), (0.0, 0.0, 0.0, 1.0)), a[1]]
    assert in_same_place(a, near)
    for i in range(2):  # the last number of either pair, position or quaternion, past the bound
        for part in range(2):
            moved = [list(map(list, pq)) for pq in a]
            moved[i][part][-1] += 1.1 * SAME_PLACE
            assert not in_same_place(a, [tuple(map(tuple, pq)) for pq in moved]), (i, part)
    wider = [((0.1 + 0.9 * KEPT_WITHIN, 0.2, 0.3), (0.0, 0.0, 0.0, 1.0)), a[1]]  # the bound as asked
    assert in_same_place(a, wider, KEPT_WITHIN) and not in_same_place(a, wider)
    assert not in_same_place(a, [((0.1 + 1.1 * KEPT_WITHIN, 0.2, 0.3), (0.0, 0.0, 0.0, 1.0)), a[1]], KEPT_WITHIN)
    nan = [((float("nan"), 0.2, 0.3), (0.0, 0.0, 0.0, 1.0)), a[1]]
    assert not in_same_place(a, nan)
    assert not in_same_place(nan, [((float("nan"), 0.2, 0.3), (0.0, 0.0, 0.0, 1.0)), a[1]])


def test_the_ghosts_read_the_bodies_in_their_boxes_from_the_pass_as_a_query_afresh_finds_them():
    """The bundled suturing scene at rest under adfkit run's options: each control step each ghost's
    overlapping bodies and their points are read from the box queries the collision pass made
    (``_near_keys``) rather than queried again; after each of 20 control steps they are what
    ``_overlap`` finds querying every ghost's box afresh (``_near_keys`` None, as a pass in the
    dynamics world, which moves the boxes, leaves it): four ghosts hold bodies. The ghosts passed
    again between the physics steps (ghost_steps.py) are read after the control step's pass alone.
    Control: read from queries that found nothing, the four hold none."""
    w = open_world(load_scene(BUNDLED, None), Options(**AMBF))
    try:
        w.step(100)
        seen = []
        stepped = w._ghost_steps.between
        w._ghost_steps.between = lambda: None  # the control step's pass the last the ghosts made
        for _ in range(20):
            w.step(1)
            assert w._near_keys is not None  # the pass ran in the ghosts' own world
            read = {g.uid: (list(g.overlapping), list(g.points)) for g in w._acting_ghosts}
            manifolds = w._manifold_made
            near, w._near_keys = w._near_keys, None
            afresh = {}
            for g in w._acting_ghosts:
                found = w._overlap(g, None, with_parent=True, manifolds=manifolds)
                afresh[g.uid] = (found, list(g.points))
            w._near_keys = near
            seen.append(sum(1 for found, _p in read.values() if found))
            assert read == afresh
        w._near_keys = {uid: [] for uid in w._near_keys}
        assert not any(w._overlap(g, None, True, w._manifold_made) for g in w._acting_ghosts)
        w._ghost_steps.between = stepped
    finally:
        w.close()
    assert set(seen) == {4}, seen
