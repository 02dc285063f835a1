"""`adfkit suture --phantom MODEL.yaml` (adfkit/scenes/suturing/own_phantom.py): a phantom in a
model file of its own put into the bundled scene in place of its phantom, the arms, the needle
and the camera placed for its holes. Fast: the composed scene, its placement and the check
before the run; what a file it cannot use says. Slow: a generated family of good phantoms
(pairs 8-14 mm apart, 3 and 5 pairs, turned, slanted, thicker) passes every pair."""

from __future__ import annotations

import copy
import math
import re

import numpy as np
import pytest
from suture_phantoms import BUNDLED, phantom_file

from adfkit.adf import load_scene, read_file, write_file
from adfkit.scenes.suturing import layout as L
from adfkit.scenes.suturing.own_phantom import TRAY_DEPTH, PhantomError, compose, phantom_holes


def _compose(path):
    return compose(load_scene(BUNDLED / "launch.yaml"), read_file(path, "model")[0])


def test_the_arms_needle_and_camera_stand_to_the_phantoms_holes_as_to_the_bundled_ones(tmp_path):
    """A phantom turned 30 degrees and moved 20 mm, 3 mm thicker: the placement is the same turn
    and move; the PSMs' bases, the camera's frame and the needle go with it; the needle's tray
    rests on the phantom's slab, its slot free; the bundled phantom, its holes and its ghosts are
    gone, the needle's file keeps the needle, the thread and the camera frame."""
    path = phantom_file(tmp_path, pairs=3, spacing=0.010, turn_deg=30.0, at=(0.02, -0.01), thicker=0.003)
    c = _compose(path)
    assert c.pairs == [1, 2, 3]
    turn = c.placement[:3, :3]
    assert math.degrees(math.atan2(turn[1, 0], turn[0, 0])) == pytest.approx(30.0, abs=1e-6)
    # the holes' centre: (0, 0) of the phantom, 25 mm up; the bundled one: (0, 0, 22 mm)
    assert (c.placement @ [0.0, 0.0, L.RIDGE_TOP, 1.0])[:3] == pytest.approx([0.02, -0.01, L.RIDGE_TOP + 0.003])
    names = {b.name for m in c.scene.models for b in m.bodies}
    assert {"Needle", "Thread_039", "CameraFrame", "SutureTray", "Phantom", "Entry3"} <= names
    assert "Entry4" not in names and sum(b.name == "Phantom" for m in c.scene.models for b in m.bodies) == 1
    ghosts = sorted(g.name for m in c.scene.models for g in m.ghost_objects if "ghostE" in g.name)
    assert ghosts == sorted(f"ghost{k}{i}" for k in ("Entry", "Exit") for i in (1, 2, 3))
    base = next(b for m in c.scene.models for b in m.bodies if m.namespace and "psm1" in m.namespace)
    bundled = next(b for m in load_scene(BUNDLED / "launch.yaml").models for b in m.bodies if b.name == base.name)
    from adfkit.runner.rotations import pose_to_matrix

    assert pose_to_matrix(base.location) == pytest.approx(c.placement @ pose_to_matrix(bundled.location), abs=1e-9)
    # the slab's top stands 6 mm below the holes, where the tray's top is: the tray is raised
    # its depth to rest on the slab, its slot free; the needle with it
    assert c.lift_m == pytest.approx(TRAY_DEPTH, abs=1e-4)
    assert c.bed_turn_deg == 0.0  # level tissue: the needle lies as in the bundled scene


def _thread_and_tray(c):
    """The thread elements' centres (N, 3) and the tray's top (world z) where --phantom laid them."""
    from adfkit.runner.rotations import pose_to_matrix

    bodies = {b.name: b for m in c.scene.models for b in m.bodies}
    thread = np.array([pose_to_matrix(b.location)[:3, 3] for n, b in bodies.items() if n.startswith("Thread")])
    tray = bodies["SutureTray"]
    top = max(s.offset.position.z + s.geometry.z / 2 for s in tray.compound_collision_shape)
    return thread, (pose_to_matrix(tray.location) @ [0.0, 0.0, top, 1.0])[2]


@pytest.mark.parametrize("deg", [45.0, -15.0])
def test_the_needles_bed_beside_a_phantom_sloping_along_its_line_is_turned_off_the_slope(tmp_path, deg):
    """On a phantom sloping along its line of holes the bundled lay ran the thread's strip up the
    slope: at -15 degrees (pair 1's end down) into the tissue, at +45 the tray stood 30 mm up
    beside the holes. The bed is turned a quarter turn, the thread running out from the ridge
    (level across the slope): lower, the thread on the tray and clear of the tissue under it."""
    from suture_phantoms import tilt_phantom

    from adfkit.scenes.suturing.own_phantom import tissue_top

    path = tilt_phantom(phantom_file(tmp_path, pairs=2, spacing=0.012), "x", deg)
    c = _compose(path)
    assert c.bed_turn_deg == -90.0
    assert c.lift_m < (0.012 if deg > 0 else 0.001)
    thread, top = _thread_and_tray(c)
    lying = thread[3:]  # the first elements rise to the needle's tail (thread.thread_path)
    assert lying[:, 2] == pytest.approx(top + L.THREAD_RADIUS, abs=1e-4)  # straight and level, on the tray
    # running out from the ridge (world -x: the phantom is turned about x only), not along the line
    assert thread[-1, 0] - thread[0, 0] < -0.09 and abs(thread[-1, 1] - thread[0, 1]) < 0.001
    model = read_file(path, "model")[0]
    under = tissue_top([model], thread, below=0.1)
    assert (under < thread[:, 2] - 0.001).all()  # no tissue over any element


def test_a_pair_on_a_slope_the_arms_cannot_turn_the_needle_to_says_so_before_the_arms_move(tmp_path):
    """The 2-pair phantom 45 degrees along its line, pair 1's end down: no grasp reaches (psm2's
    wrist 4.8 degrees past its limit); the reach says the slope (the arms stand for level tissue);
    at 30 degrees the plan finds its grasps and says nothing of a slope."""
    from suture_phantoms import tilt_phantom

    from adfkit.runner import Options, open_world
    from adfkit.tasks.suture import SutureError, SutureTask

    said = {}
    for deg in (-45.0, -30.0):
        c = _compose(tilt_phantom(phantom_file(tmp_path / str(deg), pairs=2, spacing=0.012), "x", deg))
        world = open_world(c.scene, Options(renderer="tiny", visuals=False))
        try:
            task = SutureTask(world, c.pairs[:1], seed=0)
            try:
                task.plan()
                said[deg] = ""
            except SutureError as exc:
                said[deg] = str(exc)
        finally:
            world.close()
    assert said[-30.0] == ""
    assert "no grasp of the needle reachable" in said[-45.0]
    assert said[-45.0].endswith(
        "; Entry1 and Exit1 lie on tissue sloping 45° from level: the arms stand for level tissue (turned "
        "about the vertical only) and do not turn the needle that far, lay the pairs on a gentler slope"
    )


def test_a_phantom_numbered_from_the_other_end_is_sutured_from_the_needles_end(tmp_path):
    """The needle lies beyond the end of the line where the bundled pair 1 is. A phantom whose
    pair 1 is at the other end is sutured from its last pair to its first (each pair still from
    Entry k to Exit k), so the suture starts next to the needle as in the bundled scene; numbered
    as the bundled one, 1 to N. The needle is placed the same way for both."""
    fwd = _compose(phantom_file(tmp_path / "fwd", pairs=4, spacing=0.024))
    back = _compose(phantom_file(tmp_path / "back", pairs=4, spacing=0.024, numbered_back=True))
    assert fwd.pairs == [1, 2, 3, 4] and back.pairs == [4, 3, 2, 1]

    def needle(c):
        return next(b for m in c.scene.models for b in m.bodies if b.name == "Needle").location.position

    a, b = needle(fwd), needle(back)
    assert (a.x, a.y, a.z) == pytest.approx((b.x, b.y, b.z), abs=1e-12)
    # the first pair visited stands to the needle in both as the bundled pair 1 does

    def entry(c, k):
        return next(bd for m in c.scene.models for bd in m.bodies if bd.name == f"Entry{k}").location.position

    assert b.y - entry(back, 4).y == pytest.approx(a.y - entry(fwd, 1).y, abs=1e-9) and a.y - entry(fwd, 1).y > 0.015


def test_the_swept_arc_is_clear_on_a_good_phantom_and_says_what_blocks_a_bad_one(tmp_path):
    from adfkit.runner import Options, open_world
    from adfkit.tasks.needle import wire_radius
    from adfkit.tasks.suture import SutureTask
    from adfkit.tasks.sweep import check

    for raised, expect in ((0.0, {}), (0.004, None)):
        path = phantom_file(tmp_path / f"t{raised}", pairs=3, spacing=0.012, turn_deg=20.0, thicker=0.003)
        if raised:  # the holes 4 mm above the ridge's top
            doc, _ = read_file(path, "model")
            for b in doc.bodies:
                if b.name.startswith(("Entry", "Exit")):
                    p = b.location.position
                    b.location = type(b.location)(type(p)(p.x, p.y, p.z + 0.004), b.location.orientation)
            write_file(doc, path)
        c = _compose(path)
        world = open_world(c.scene, Options(renderer="tiny", visuals=False))
        try:
            task = SutureTask(world, c.pairs, seed=0)
            got = check(task, wire_radius(task))
        finally:
            world.close()
        if expect is not None:
            assert got == expect
        else:
            assert set(got) == {1, 2, 3} and got[2].startswith("the tissue's surface is 4.0 mm below Entry2 and Exit2")


def test_holes_are_found_by_their_ghosts_names_and_bodies(tmp_path):
    doc, _ = read_file(phantom_file(tmp_path, pairs=5, spacing=0.014), "model")
    h = phantom_holes(doc)
    assert h.pairs() == [1, 2, 3, 4, 5] and h.names[5] == {"entry": "Entry5", "exit": "Exit5"}
    ys = [h.frames[k]["entry"][1, 3] for k in h.pairs()]
    assert np.diff(ys) == pytest.approx([-0.014] * 4)


def test_a_file_it_cannot_use_is_told_why(tmp_path, capsys):
    from adfkit.cli import main

    path = phantom_file(tmp_path / "a", pairs=2)
    doc, _ = read_file(path, "model")
    doc.ghost_objects = [g for g in doc.ghost_objects if g.name != "ghostExit1" and g.name != "ghostExit2"]
    write_file(doc, path)
    with pytest.raises(PhantomError, match=r"no hole pair: .* pair 1 has only its entry hole"):
        _compose(path)
    assert main(["suture", "--phantom", str(path), "--out", str(tmp_path / "o")]) == 2
    assert "no hole pair" in capsys.readouterr().err
    whole = BUNDLED / "phantom" / "phantom.yaml"  # the bundled phantom file holds the needle too
    with pytest.raises(PhantomError, match="the phantom file has its own Needle"):
        _compose(whole)
    assert main(["suture", str(BUNDLED / "launch.yaml"), "--phantom", str(path)]) == 2
    assert main(["suture", "--phantom", str(tmp_path / "none.yaml")]) == 2
    err = capsys.readouterr().err
    assert "--phantom puts your phantom into the bundled scene" in err and "none.yaml does not exist" in err


def _renamed(path, body, ghost):
    """The phantom's hole bodies and ghosts renamed: ``body(kind, k)``, ``ghost(kind, k)``."""
    doc, _ = read_file(path, "model")
    ref = {}
    for b in doc.bodies:
        m = re.fullmatch(r"(Entry|Exit)(\d+)", b.name)
        if m:
            new = body(m.group(1), int(m.group(2)))
            ref[b.identifier] = f"BODY {new}"
            b.name, b.identifier = new, f"BODY {new}"
    for g in doc.ghost_objects:
        m = re.fullmatch(r"ghost(Entry|Exit)(\d+)", g.name)
        new = ghost(m.group(1), int(m.group(2)))
        g.name, g.identifier, g.parent = new, f"GHOST {new}", ref[g.parent]
    write_file(doc, path)
    return path


@pytest.mark.parametrize(
    "body, ghost",
    [
        (lambda k, i: f"{k} {i}", lambda k, i: f"ghost {k} {i}"),  # "Entry 1" (the last word of the key was "1")
        (lambda k, i: f"{k.lower()}_{i}", lambda k, i: f"{k.lower()}_{i}_ghost"),  # the number not at the end
    ],
    ids=["spaces", "suffix"],
)
def test_holes_spelt_as_a_modeller_spells_them_are_found(tmp_path, body, ghost):
    """Hole bodies and ghosts named "Entry 1" / "ghost Entry 1" (the ghosts' parents were looked up
    by the last word of their key, "1", and both holes of a pair fell on one body: "the phantom's
    entry and exit holes lie on top of each other") or "entry_1" / "entry_1_ghost" ("no hole
    pair") are the pairs they name, each on its own hole body."""
    path = _renamed(phantom_file(tmp_path, pairs=2, spacing=0.012), body, ghost)
    h = phantom_holes(read_file(path, "model")[0])
    assert h.pairs() == [1, 2] and h.names[2] == {"entry": body("Entry", 2), "exit": body("Exit", 2)}
    assert h.frames[1]["exit"][0, 3] - h.frames[1]["entry"][0, 3] == pytest.approx(2 * L.HOLE_HALF_GAP)
    c = _compose(path)
    from adfkit.runner import Options, open_world
    from adfkit.tasks.suture import hole_pairs

    world = open_world(c.scene, Options(renderer="tiny", visuals=False))
    try:
        assert [(p.index, p.entry_name, p.exit_name) for p in hole_pairs(world)] == [
            (k, ghost("Entry", k), ghost("Exit", k)) for k in (1, 2)
        ]
    finally:
        world.close()


def test_a_broken_set_of_holes_is_refused_with_what_to_fix(tmp_path, capsys):
    """Exit 2 and the reason, never a suture of what is left: hole bodies without ghosts; a pair
    with one hole (Entry3 without Exit3 was dropped and pairs 1-2 passed, exit 0); two ghosts on
    one hole; a file in millimetres (positions 1000 times too large: it failed as `reach`, "entry
    and exit of pair 1 are 13996.6 mm apart"); a body named as one the bundled scene keeps (its
    own CameraFrame: the stereo camera found no parent and stayed where the bundled scene has it)."""
    from adfkit.cli import main

    def broken(name, fn, pairs=3):
        path = phantom_file(tmp_path / name, pairs=pairs, spacing=0.012)
        doc, _ = read_file(path, "model")
        fn(doc)
        write_file(doc, path)
        return path

    def refused(path, *said):
        with pytest.raises(PhantomError) as exc:
            _compose(path)
        for s in said:
            assert s in str(exc.value)
        return str(exc.value)

    bodies_only = broken("bodies", lambda d: setattr(d, "ghost_objects", []))
    refused(bodies_only, "no hole pair", "it has hole bodies (Entry1, Entry2, Entry3, Exit1, ...) but no hole ghosts")
    lone = broken("lone", lambda d: setattr(d, "ghost_objects", [g for g in d.ghost_objects if g.name != "ghostExit3"]))
    refused(lone, "pair 3 has only its entry hole (ghostEntry3), no Exit3 hole ghost (its whole pairs: 1, 2)")
    assert main(["suture", "--phantom", str(lone), "--pairs", "all", "--out", str(tmp_path / "o")]) == 2
    assert "pair 3 has only its entry hole" in capsys.readouterr().err

    def twice(d):
        extra = copy.deepcopy(next(g for g in d.ghost_objects if g.name == "ghostExit2"))
        extra.name, extra.identifier = "Exit2_ghost", "GHOST Exit2_ghost"
        d.ghost_objects.append(extra)

    refused(broken("twice", twice), "pair 2's exit hole has 2 ghosts (ghostExit2, Exit2_ghost)")

    def millimetres(d):
        for b in d.bodies:
            p = b.location.position
            b.location = type(b.location)(type(p)(p.x * 1000, p.y * 1000, p.z * 1000), b.location.orientation)

    refused(broken("mm", millimetres), "Entry1 and Exit1 are 14.0 m apart", "is the file in millimetres (14.0 mm)?")

    def camera_frame(d):  # as the challenge's phantom files carry one: the cameras lost their parent
        from adfkit.model import Body, Pose

        d.bodies.append(Body(identifier="BODY CameraFrame", name="CameraFrame", mass=0.0, location=Pose()))

    refused(broken("camera", camera_frame), "has a body named CameraFrame", "the stereo camera hangs from it")


# ---- the good family, played (slow) ----------------------------------------------------------
FAMILY = {
    "3 pairs 8 mm apart": dict(pairs=3, spacing=0.008),
    "5 pairs 14 mm apart": dict(pairs=5, spacing=0.014),
    "turned 30 degrees, moved": dict(pairs=4, spacing=0.011, turn_deg=30.0, at=(0.02, -0.01)),
    "turned 90 degrees on the table, moved": dict(pairs=3, spacing=0.012, turn_deg=90.0, at=(0.01, 0.02)),
    "turned -90 degrees on the table, moved": dict(pairs=3, spacing=0.012, turn_deg=-90.0, at=(0.01, 0.02)),
    "turned 180 degrees on the table, moved": dict(pairs=3, spacing=0.012, turn_deg=180.0, at=(0.01, 0.02)),
    "line slanted 30 degrees": dict(pairs=3, spacing=0.010, line_deg=30.0),
    "3 mm thicker": dict(pairs=3, spacing=0.012, thicker=0.003),
    "numbered from the other end": dict(pairs=4, spacing=0.024, numbered_back=True),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(FAMILY))
def test_a_good_phantom_passes_every_pair(tmp_path, name):
    from adfkit.tasks.episode import run_episode

    path = phantom_file(tmp_path, **FAMILY[name])
    m = run_episode(BUNDLED / "launch.yaml", pairs=None, seed=0, progress=False, gif=False, phantom=path)
    assert m["failure"] is None and m["all_passed"], [(p["pair"], p["rule"], p["reason"]) for p in m["pairs"]]
    assert len(m["pairs"]) == FAMILY[name]["pairs"] and m["swept_arc_check"] == {}


def _solid(doc):
    """The ridge's gaps filled: holes drilled into nothing."""
    from suture_phantoms import _box

    phantom = next(b for b in doc.bodies if b.name == "Phantom")
    phantom.compound_collision_shape.append(
        _box((-L.RIDGE_HALF_X, -0.03, L.SLAB[2]), (L.RIDGE_HALF_X, 0.03, L.RIDGE_TOP))
    )


def _mesh_collision(doc):
    """No collision primitives: the body collides as its mesh, a concave triangle mesh for a
    static body (AMBF's default collision mesh type; the runner plays it as its triangles)."""
    next(b for b in doc.bodies if b.name == "Phantom").compound_collision_shape = None


def _small_ghosts(doc):
    from adfkit.model import Geometry

    for g in doc.ghost_objects:
        g.geometry = g.collision_geometry = Geometry(x=0.001, y=0.001, z=0.0002)


def _scaled_holes(doc):
    for obj in [b for b in doc.bodies if b.name.startswith(("Entry", "Exit"))] + list(doc.ghost_objects):
        obj.scale = 0.2


def _turned_over_holes(doc):
    """Each hole body turned half a turn about its x: its z into the tissue."""
    from adfkit.runner.rotations import pose_to_matrix
    from adfkit.scenes.suturing.frames import pose, rot_x

    for b in doc.bodies:
        if b.name.startswith(("Entry", "Exit")):
            b.location = pose(pose_to_matrix(b.location) @ rot_x(math.pi))


def _free_on_a_table(doc):
    """The phantom a 0.3 kg body lying 0.5 mm over a static table, its holes 5 g bodies on fixed
    joints to it: nothing holds it but friction, and the needle pushes it."""
    from suture_phantoms import _box

    from adfkit.model import Body, Joint, Pose, Vec3
    from adfkit.runner.rotations import pose_to_matrix

    next(b for b in doc.bodies if b.name == "Phantom").mass = 0.3
    for b in [b for b in doc.bodies if b.name.startswith(("Entry", "Exit"))]:
        b.mass = 0.005
        z = pose_to_matrix(b.location)[:3, 2]  # the hole's z as the joint's axis: it keeps its tilt
        doc.joints.append(
            Joint(
                identifier=f"JOINT Phantom-{b.name}",
                name=f"Phantom-{b.name}",
                parent="BODY Phantom",
                child=b.identifier,
                type="fixed",
                parent_pivot=copy.deepcopy(b.location.position),
                parent_axis=Vec3(*map(float, z)),
                child_pivot=Vec3(0, 0, 0),
                child_axis=Vec3(0, 0, 1),
            )
        )
    for b in doc.bodies:
        q = b.location.position
        b.location = Pose(Vec3(q.x, q.y, q.z + 0.0005), b.location.orientation)
    doc.bodies.append(
        Body(
            identifier="BODY Table",
            name="Table",
            mass=0.0,
            location=Pose(),
            compound_collision_shape=[_box((-0.06, -0.12, -0.01), (0.06, 0.12, 0.0))],
            collision_margin=0.0001,
        )
    )


#: a modeller's phantom, changed one way, and pair 1's verdict and what its reason says (seed 0)
ODD = {
    # the driver's jaws, closing round the wire on the tray, held 56 N on it: tool-hit-tissue on
    # SutureTray in the pick-up, before the needle met the filled channel
    "holes into solid tissue": (_solid, "blocked-at-entry", "blocked at Entry1"),
    # the same 56 N on the tray failed it; its channels are free in its triangles (and read so
    # before the run: test_a_phantom_colliding_as_its_mesh_is_read_as_the_engine_collides_it)
    "tissue colliding as its mesh": (_mesh_collision, None, None),
    # aimed at the ghosts' centres, a 14 mm bite: the wrist reached its limit in carry 1
    "1 mm ghosts": (_small_ghosts, "entry-ghost-off-hole", "the ghost (1.0 × 1.0 mm) covers less than the opening"),
    # read as 1.0 mm openings and 1 mm ghosts: the same 14 mm bite, `reach` in carry 1
    "holes scaled 0.2": (_scaled_holes, None, None),
    # the needle went through; its crossings were read the wrong way: entry-missed, "0.0 mm"
    "holes turned over": (_turned_over_holes, None, None),
    # a 1 mm sheet over the ridge's place, not cut: the needle does not go through it
    "1 mm membrane": (lambda doc: _membrane(doc), "blocked-at-entry", "blocked at Entry1"),
    # passed before; the check before the run read its cylinders as capsules filling the channels
    "curved ridge": (lambda doc: _curved_ridge(doc), None, None),
    # the needle pushed the phantom 8.0 mm along the table and turned it 2.0°: the exit 4.0 mm
    # outside its opening, for where the hole went (the reason names the moved bodies, not how far)
    "free on a table": (_free_on_a_table, "exit-outside-opening", "the tissue moved during the run (Entry1 "),
}


def _membrane(doc):
    """The ridge taken away and a 1 mm sheet of tissue laid over its place, at its top, uncut:
    the holes on it, the channels under it open (the slab 5 mm below)."""
    from suture_phantoms import _box

    phantom = next(b for b in doc.bodies if b.name == "Phantom")
    top = L.RIDGE_TOP
    phantom.compound_collision_shape = [
        phantom.compound_collision_shape[0],
        _box((-0.015, -0.02, top - 0.001), (0.015, 0.02, top)),
    ]


@pytest.mark.slow
@pytest.mark.parametrize("name", list(ODD))
def test_a_phantom_made_another_way_gets_the_verdict_its_physics_earns(tmp_path, name):
    from adfkit.tasks.episode import run_episode

    change, rule, said = ODD[name]
    path = phantom_file(tmp_path, pairs=2, spacing=0.012)
    doc, _ = read_file(path, "model")
    change(doc)
    write_file(doc, path)
    m = run_episode(BUNDLED / "launch.yaml", pairs=[1], seed=0, progress=False, gif=False, phantom=path)
    (p,) = m["pairs"]
    assert p["rule"] == rule and p["passed"] == (rule is None), (p["rule"], p["reason"])
    assert said is None or said in p["reason"]
    # motions.GUARD_N (20) in PyBullet's newtons: 80 N
    assert not [e for e in m["tool_tissue_events"] if e["phase"] == "pick up" and e["sustained_force_n"] >= 80.0]
    if change is _mesh_collision:  # the check before the run reads its triangles, as PyBullet collides them
        assert not m["swept_arc_check"]


def test_a_phantom_colliding_as_its_mesh_is_read_as_the_engine_collides_it(tmp_path):
    """The phantom without collision primitives: a static body colliding as its mesh, which AMBF
    and PyBullet collide as its triangles (its channels open) and MuJoCo as its hull. The needle's
    tray rests on the slab as with the primitives (read as the hull: 4.5 mm higher, on the
    ridge's top) and the check before the run finds the arcs clear in PyBullet; in MuJoCo it
    reads the hull and says so."""
    from adfkit.runner import Options, open_world
    from adfkit.tasks.needle import wire_radius
    from adfkit.tasks.suture import SutureTask
    from adfkit.tasks.sweep import check

    path = phantom_file(tmp_path, pairs=2, spacing=0.012)
    boxes = _compose(path)
    doc, _ = read_file(path, "model")
    _mesh_collision(doc)
    write_file(doc, path)
    bundled = load_scene(BUNDLED / "launch.yaml")
    mesh = compose(bundled, doc)
    assert mesh.lift_m == pytest.approx(boxes.lift_m, abs=1e-9)
    assert compose(bundled, doc, triangles=False).lift_m - boxes.lift_m == pytest.approx(0.0045, abs=2e-4)
    said = {}
    for engine, c in (("pybullet", mesh), ("mujoco", compose(bundled, doc, triangles=False))):
        world = open_world(c.scene, Options(renderer="tiny", visuals=False), engine=engine)
        try:
            task = SutureTask(world, c.pairs, seed=0)
            said[engine] = check(task, wire_radius(task))
        finally:
            world.close()
    assert said["pybullet"] == {}
    assert (
        set(said["mujoco"]) == {1, 2} and "the convex hull of Phantom's collision mesh, as MuJoCo" in said["mujoco"][1]
    )


def _curved_ridge(doc, radius=0.012):
    """The ridge a horizontal cylinder along the line of pairs (a gap at each pair), its top where
    the ridge's was; the holes on its curved surface, each turned to its normal there."""
    from adfkit.model import Geometry, Pose, ShapeEntry, Vec3
    from adfkit.scenes.suturing.frames import pose, rot_y, translation

    phantom = next(b for b in doc.bodies if b.name == "Phantom")
    zc = L.RIDGE_TOP - radius
    ys = sorted({b.location.position.y for b in doc.bodies if b.name.startswith("Entry")})
    edges = [-max(abs(y) for y in ys) - 0.014]
    for y in ys:
        edges += [y - L.RIDGE_GAP / 2, y + L.RIDGE_GAP / 2]
    edges.append(-edges[0])
    phantom.compound_collision_shape = phantom.compound_collision_shape[:1] + [
        ShapeEntry(
            shape="Cylinder",
            geometry=Geometry(radius=radius, height=b - a, axis="y"),
            offset=Pose(Vec3(0.0, (a + b) / 2, zc)),
        )
        for a, b in zip(edges[0::2], edges[1::2])
    ]
    x = L.HOLE_HALF_GAP
    for b in doc.bodies:
        for kind, sign in (("Entry", -1.0), ("Exit", 1.0)):
            if b.name.startswith(kind):
                z = zc + math.sqrt(radius**2 - x * x)
                b.location = pose(translation(sign * x, b.location.position.y, z) @ rot_y(sign * math.asin(x / radius)))


def _tilted(doc, deg=30.0):
    """The whole phantom turned ``deg`` about x: the line of pairs runs uphill."""
    from adfkit.runner.rotations import pose_to_matrix
    from adfkit.scenes.suturing.frames import pose, rot_x

    for b in doc.bodies:
        b.location = pose(rot_x(math.radians(deg)) @ pose_to_matrix(b.location))


@pytest.mark.parametrize("change", [_curved_ridge, _tilted])
def test_holes_on_a_curved_or_sloping_surface_are_read_as_lying_on_it(tmp_path, change):
    """Holes on a ridge of 12 mm radius (each turned to the surface's normal) and on a phantom
    tilted 30 degrees: the check before the run finds the arcs clear (the ridge's cylinders read
    as capsules filled the channels: "Phantom lies in the needle's path ... 3.4 mm inside it")
    and the holes on the surface (the highest ray of the ring stood 1.8 and 2.9 mm above them)."""
    from adfkit.runner import Options, open_world
    from adfkit.tasks.needle import wire_radius
    from adfkit.tasks.suture import SutureTask
    from adfkit.tasks.sweep import check

    path = phantom_file(tmp_path, pairs=2, spacing=0.012)
    doc, _ = read_file(path, "model")
    change(doc)
    write_file(doc, path)
    c = _compose(path)
    world = open_world(c.scene, Options(renderer="tiny", visuals=False))
    try:
        task = SutureTask(world, c.pairs, seed=0)
        assert check(task, wire_radius(task)) == {}
    finally:
        world.close()


def test_a_phantom_given_as_a_launch_file_of_several_model_files_is_composed_as_one(tmp_path):
    """The phantom's tissue in one model file, its hole bodies and ghosts in another, a launch
    file listing both (and a world of its own): --phantom takes the launch's model files (the
    ghosts' parents found in the other file) and composes them as the one-file phantom; the
    launch's world is the bundled scene's, and it says so. A launch file was refused: "this
    looks like a launch file, not a model file"."""
    from adfkit.model import ModelFile
    from adfkit.scenes.suturing.own_phantom import load_phantom

    one = phantom_file(tmp_path / "one", pairs=3, spacing=0.012)
    doc, _ = read_file(one, "model")
    folder = one.parent
    tissue = ModelFile(namespace=doc.namespace, high_resolution_path="./meshes/", low_resolution_path="./meshes/")
    holes = ModelFile(namespace=doc.namespace)
    tissue.bodies = [b for b in doc.bodies if b.name == "Phantom"]
    holes.bodies, holes.ghost_objects = [b for b in doc.bodies if b.name != "Phantom"], doc.ghost_objects
    (folder / "parts").mkdir()
    write_file(tissue, folder / "tissue.yaml")
    write_file(holes, folder / "parts" / "holes.yaml")
    (folder / "launch.yaml").write_text(
        "world config: ./world.yaml\nmultibody configs:\n  - ./tissue.yaml\n  - ./parts/holes.yaml\n"
    )
    (folder / "world.yaml").write_text("enclosure size: {length: 10.0, width: 10.0, height: 3.0}\n")
    diags: list = []
    files = load_phantom(folder / "launch.yaml", diags)
    assert isinstance(files, list) and len(files) == 2
    assert any(d.rule == "phantom-launch" and "world config" in d.message for d in diags)
    bundled = load_scene(BUNDLED / "launch.yaml")
    a, b = compose(bundled, doc), compose(bundled, files)
    assert b.pairs == a.pairs == [1, 2, 3] and b.lift_m == pytest.approx(a.lift_m, abs=1e-12)
    assert b.placement == pytest.approx(a.placement, abs=1e-12)
    names = sorted(x.name for m in b.scene.models for x in m.bodies)
    assert names == sorted(x.name for m in a.scene.models for x in m.bodies)


def test_a_skin_body_without_its_low_resolution_mesh_is_left_out_and_said(tmp_path, capsys):
    """A textured skin body over the phantom with no collision keys and its mesh in the
    high-resolution folder only: AMBF looks for its collision mesh in the low-resolution folder
    and, not finding it, does not make the body; the runner neither (it is not tissue, the pairs
    pass: tested played in w94's audit), and `adfkit suture` now says so before the run (it said
    nothing)."""
    from adfkit.model import Body
    from adfkit.tasks.episode import run_episode

    path = phantom_file(tmp_path, pairs=2, spacing=0.012)
    (tmp_path / "high_res").mkdir()
    (tmp_path / "high_res" / "Skin.OBJ").write_text("o Skin\nv 0 0 0\nv 0.01 0 0\nv 0 0.01 0\nf 1 2 3\n")
    doc, _ = read_file(path, "model")
    doc.high_resolution_path = "./high_res/"
    doc.bodies.append(Body(identifier="BODY Skin", name="Skin", mass=0.0, mesh="Skin.OBJ"))
    write_file(doc, path)
    m = run_episode(BUNDLED / "launch.yaml", pairs=[9], seed=0, progress=True, gif=False, phantom=path)
    assert m["failure"].startswith("setup:")  # no pair 9: the run stops after the world is made
    err = capsys.readouterr().err
    assert "BODY Skin: collision mesh" in err and "Skin.OBJ not found" in err


def test_a_pair_out_of_the_arms_reach_is_named_with_how_far(tmp_path):
    """Two pairs 170 mm apart: the arms, placed for their centre, reach neither; the plan says
    which hole, which joint and by how much, before anything moves."""
    from adfkit.runner import Options, open_world
    from adfkit.tasks.suture import SutureError, SutureTask

    c = _compose(phantom_file(tmp_path, pairs=2, spacing=0.17))
    world = open_world(c.scene, Options(renderer="tiny", visuals=False))
    try:
        task = SutureTask(world, c.pairs, seed=0)
        with pytest.raises(SutureError) as exc:
            task.plan()
        msg = str(exc.value)
        assert "no grasp of the needle reachable along the whole plan (pair 1, driving); the nearest needs " in msg
        assert re.search(
            r"'s outer_\w+ \d+\.\d(°| mm) past its limit with the needle's tip \d+\.\d mm from (Entry|Exit)1", msg
        )
        # the pairs' centre, for which the arms stand, is 85 mm from each: said, with each pair's distance
        assert msg.endswith(
            "; the pairs lie up to 85.0 mm from their centre, for which the arms are set up (pair 1 85.0 mm, pair 2 85.0 mm)"
        )
    finally:
        world.close()


def test_a_plan_whose_tool_comes_into_the_tissue_is_warned_of_before_the_arms_move(tmp_path):
    """A block of tissue (its own body, Wall) standing 20 mm over the slab beside pair 1's entry,
    where the driver's wrist goes at the end of the insertion: no grasp that reaches keeps the
    tool off it, and the plan says so (which arm, how deep, which body and where in the file,
    when in the suture, a hint) before anything moves; the phantom without it is planned without
    a warning. A phantom sloping 30 degrees across its holes was played to a `reach` in the
    pick-up with its -4.6 mm planned clearance said nowhere."""
    from suture_phantoms import _box

    from adfkit.model import Body, Pose
    from adfkit.runner import Options, open_world
    from adfkit.tasks.suture import SutureTask

    said = {}
    for wall in (False, True):
        path = phantom_file(tmp_path / str(wall), pairs=2, spacing=0.012)
        if wall:
            doc, _ = read_file(path, "model")
            box = _box((-0.026, -0.02, L.SLAB[2]), (-0.016, 0.02, L.SLAB[2] + 0.02))
            doc.bodies.append(
                Body(identifier="BODY Wall", name="Wall", mass=0.0, location=Pose(), compound_collision_shape=[box])
            )
            write_file(doc, path)
        c = _compose(path)
        world = open_world(c.scene, Options(renderer="tiny", visuals=False))
        try:
            task = SutureTask(world, c.pairs[:1], seed=0)
            task.plan()
            said[wall] = [str(d) for d in task.plan_warnings]
            clearance = task.drive_grasps[0].clearance
        finally:
            world.close()
    assert said[False] == []
    (w,) = said[True]
    assert clearance < -0.001
    assert re.match(r".*phantom\.yaml:\d+:\d+: warning\[plan-tool-in-tissue\]: pair 1, the plan: psm2's tool comes ", w)
    assert f"comes {-clearance * 1000:.1f} mm into Wall in insertion 1 (at (" in w
    assert "hint: Wall stands in psm2's way there" in w


def _slope(axis, deg, said):
    """A sloping phantom not handled yet: expected to pass, known to fail with the verdict ``said``
    (an assertion on the pair; anything raised otherwise fails the test)."""
    return pytest.param(
        axis, deg, marks=pytest.mark.xfail(strict=True, raises=AssertionError, reason=f"on a slope: {said}")
    )


#: sloping phantoms (tilt_phantom: turned, standing on the floor), pair 1, seed 0: good phantoms,
#: each should pass; those that do not yet, with the verdict they get (docs/phantom.md). 45 degrees
#: along, pair 1's end down, is a reach before any motion that says the slope (the test above)
SLOPES = [
    pytest.param("x", 15.0),
    pytest.param("y", 15.0),
    pytest.param("y", -15.0),
    pytest.param("x", 30.0),
    pytest.param("x", 45.0),
    pytest.param("x", -15.0),
    _slope("x", -30.0, "reach in the pick-up, psm2's open jaws on SutureTray (the needle's bed turned)"),
    _slope("y", 30.0, "reach in the pick-up"),
    _slope("y", 45.0, "reach in the pick-up"),
    # the needle driven 15 degrees further through the exit (the high side) before psm1 takes its
    # tip (suture.FURTHER): the puller's planned clearance 0.09 -> 1.5 mm (its pitch link had struck Phantom)
    pytest.param("y", -30.0),
    # driven 5 degrees further (0.57 mm planned; further, the driver's clearance would go): psm1's
    # pitch link on Phantom (7.7 kN, one step) as it comes for the tip beyond the exit, the high side
    _slope("y", -45.0, "reach in regrasp 1, psm1 missed the needle by 5.8 mm (its pitch link on Phantom)"),
]


@pytest.mark.slow
@pytest.mark.parametrize("axis, deg", SLOPES)
def test_a_sloping_phantom_passes(tmp_path, axis, deg):
    from suture_phantoms import tilt_phantom

    from adfkit.tasks.episode import run_episode

    path = tilt_phantom(phantom_file(tmp_path, pairs=2, spacing=0.012), axis, deg)
    m = run_episode(BUNDLED / "launch.yaml", pairs=[1], seed=0, progress=False, gif=False, phantom=path)
    (p,) = m["pairs"]
    assert p["passed"], (p["rule"], p["reason"], m["warnings"])
