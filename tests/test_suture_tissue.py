"""What is tissue to the suture (adfkit/tasks/roles.py), the check of the needle's swept arc
before the run (adfkit/tasks/sweep.py) and the constraint figures each engine can measure.
Fast: worlds are built, not played (a few control steps at most)."""

from __future__ import annotations

import pytest
from suture_phantoms import (
    copy_scene,
    fill_holes,
    narrow_channel,
    phantom_in_own_file,
    raise_floor,
    raise_phantom,
)

from adfkit.adf import load_scene
from adfkit.runner import Options, open_world
from adfkit.tasks.needle import wire_radius
from adfkit.tasks.suture import SutureTask
from adfkit.tasks.sweep import check


def _task(launch, pairs=(1,), engine="pybullet", **kw):
    world = open_world(load_scene(launch), Options(renderer="tiny", visuals=False), engine=engine)
    return world, SutureTask(world, list(pairs), seed=0, **kw)


def test_tissue_is_every_body_but_the_arms_the_needle_and_the_thread_from_whichever_file(tmp_path):
    """The phantom moved into a model file of its own is tissue as it was in the needle's file;
    the thread is the chain joined to the needle, in its order; a body the scene names as not
    tissue is left out."""
    world, task = _task(phantom_in_own_file(tmp_path))
    try:
        r = task.roles
        names = sorted(sb.name for sb in r.tissue)
        assert names == sorted(["Floor", "Phantom"] + [f"{k}{i}" for k in ("Entry", "Exit") for i in range(1, 5)])
        assert next(sb for sb in r.tissue if sb.name == "Phantom").model is not task.needle.model
        assert [sb.name for sb in r.thread] == ["Thread"] + [f"Thread_{i:03d}" for i in range(1, 40)]
        assert sorted(r.robots) == ["psm1", "psm2"] and all(len(links) == 9 for links in r.robots.values())
        assert not {id(sb) for links in r.robots.values() for sb in links} & r.tissue_ids()
        # the planner's clearance reads the same bodies
        task.plan()
        assert "Phantom" not in task.tissue_shapes.unknown and len(task.tissue_shapes.boxes) >= 10
    finally:
        world.close()
    world, task = _task(copy_scene(tmp_path / "b") / "launch.yaml", not_tissue=("Floor",))
    try:
        assert "Floor" not in {sb.name for sb in task.roles.tissue} and "CameraFrame" not in {
            sb.name for sb in task.roles.tissue
        }  # no collision shape: nothing can press on it
    finally:
        world.close()


def test_the_observer_records_the_needle_on_a_phantom_in_its_own_file(tmp_path):
    """The issue's control: the phantom in its own file, the needle lying on it, its contacts
    recorded (the observer saw none: tissue was the needle's file's static bodies)."""
    from adfkit.tasks.metrics import SutureObserver

    world, task = _task(phantom_in_own_file(tmp_path))
    try:
        obs = SutureObserver(task)
        for _ in range(25):
            world.step(1)
            obs.observe()
        assert obs.needle_contacts["start"]["Phantom"] > 0.1
        assert obs.thread_contacts["start"]["Phantom"] > 0.1
        assert {e["part"] for e in obs.needle_events} >= {"body", "thread"}
    finally:
        world.close()


def _swept(launch, pairs=(1,)):
    world, task = _task(launch, pairs)
    try:
        return check(task, wire_radius(task))
    finally:
        world.close()


def test_the_swept_arc_check_finds_nothing_on_the_bundled_phantom(tmp_path):
    assert _swept(copy_scene(tmp_path) / "launch.yaml", (1, 2, 3, 4)) == {}


def test_the_swept_arc_check_says_where_the_phantom_blocks_the_needle(tmp_path):
    """Before any motion: a channel narrower than the wire (its width, the wire's), a floor
    raised into the arc (from where to where past the entry), the phantom raised under its
    holes (how far its surface stands above them), a filled hole, a hole narrower than the wire."""
    got = _swept(narrow_channel(tmp_path / "a", 0.001))
    assert got[1].startswith("the channel at pair 1 is 1.0 mm wide where the wire needs 1.23 mm (Phantom, from ")
    assert _swept(narrow_channel(tmp_path / "b", 0.0009))[1].startswith("the channel at pair 1 is 0.9 mm wide")
    got = _swept(raise_floor(tmp_path / "c", 0.0206))
    assert got == {
        1: "Phantom lies in the needle's path between Entry1 and Exit1 (from 1.6 to 9.6 mm past Entry1): "
        "the wire's centre line up to 0.2 mm inside it"
    }
    got = _swept(raise_phantom(tmp_path / "d"), (1, 2))
    assert set(got) == {1, 2}
    assert got[2].startswith(
        "the tissue's surface is 4.0 mm above Entry2 and Exit2 (holes lie on the surface); Phantom"
    )
    got = _swept(fill_holes(tmp_path / "e", (2,)), (1, 2))
    assert set(got) == {2} and "Phantom lies in the needle's path between Entry2 and Exit2" in got[2]
    from test_suture_verdicts import _narrow, _scene

    got = _swept(_scene(tmp_path / "f", _narrow("Entry1")))
    assert got == {1: "Entry1's opening (0.6 mm) is narrower than the needle's wire (1.23 mm)"}


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_the_constraint_error_is_measured_where_there_is_one_and_absent_where_not(tmp_path, engine):
    """PyBullet builds the thread's joints as point constraints, whose ends drift: measured.
    MuJoCo plays them as a tree of hinges, exact by construction: no figure (it read exactly 0),
    and a note that says why."""
    from adfkit.tasks.metrics import SutureObserver

    world, task = _task(copy_scene(tmp_path) / "launch.yaml", engine=engine)
    try:
        obs = SutureObserver(task, error_every=1)
        for _ in range(3):
            world.step(1)
            obs.observe()
        m = obs.metrics(1.0)
        if engine == "pybullet":
            assert m["constraint_error_by_phase_m"]["start"] > 0.0 and m["max_constraint_error_m"] > 0.0
            assert "constraint_error_note" not in m
        else:
            assert "constraint_error_by_phase_m" not in m and m["max_constraint_error_m"] is None
            assert m["constraint_error_note"].startswith("not measured: the mujoco world built none")
    finally:
        world.close()


def test_a_hole_ghosts_box_is_read_from_its_shape_its_collision_or_its_compound():
    """The bundled ghosts have a shape; the Blender add-on writes a ghost's box as its compound
    collision shape: the planner aims inside the ghost by its box either way (it read no box from
    the add-on's ghosts, and drove their pairs through the holes' centres, a wider bite)."""
    from types import SimpleNamespace

    from adfkit.model import Geometry, Ghost, ShapeEntry
    from adfkit.tasks.holes import ghost_box

    box = Geometry(x=0.005, y=0.004, z=0.0005)
    for g in (
        Ghost(shape="Box", geometry=box),
        Ghost(collision_shape="Box", collision_geometry=box),
        Ghost(compound_collision_shape=[ShapeEntry(shape="Box", geometry=box)], scale=2.0),
    ):
        # a scale leaves a primitive collision shape as it is (AMBF 2.x, adf-format.md §12.3; the runner)
        assert ghost_box(SimpleNamespace(ghost=g)) == pytest.approx([0.005, 0.004, 0.0005])
    assert ghost_box(SimpleNamespace(ghost=Ghost(shape="Sphere", geometry=Geometry(radius=0.003)))) is None
