"""The suture replayed in AMBF (`adfkit parity --suture`): what the recording tells AMBF beyond
set-points and grasps. The tests that play AMBF skip, with the reason, where no AMBF build is
present; the others always run."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pybullet")

from adfkit.parity import ambf, suture  # noqa: E402
from adfkit.parity.traces import from_ambf  # noqa: E402

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)
ROOT = Path(__file__).resolve().parents[1]


def _recording_setup(launch: Path, indices, measured: bool = False, steps: int = 1):
    """adfkit's suture on ``launch`` recorded for AMBF through its first control steps: where
    the setup puts the arms, their first set-points, the pairs the task lets pass through each
    other (and the needle's push); with ``measured``, also each PSM joint's measured position
    each step, and the joints' values read after each step but the last (by AMBF name)."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.tasks.suture import SutureTask

    world = open_world(load_scene(launch, indices), Options(renderer="tiny", visuals=False))
    try:
        task = SutureTask(world, [1], seed=0)
        rec = suture._Recorder(world, task, measured)
        assert not [c for c in rec.commands if c.kind == "collide"]  # nothing before the task says so
        plan = task.steps()
        next(plan)
        read = []
        for _ in range(steps):
            world.step(1)
            read.append(
                {
                    rec.joint_names[(id(psm.art), i)]: q
                    for psm in task.psms.values()
                    for i, q in enumerate(psm.art.joint_values())
                    if (id(psm.art), i) in rec.joint_names
                }
            )
        rec.read = read[:-1]
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


def _as_recording(rec) -> suture.Recording:
    return suture.Recording(rec.commands, 0.0, [], np.zeros((0, 4)), [], None, [], "", [])


class _Commands:
    def __init__(self, commands) -> None:
        self.commands = commands


def test_the_recording_holds_the_measured_joints_each_control_step():
    """Recorded with ``measured``, each PSM joint's position is written every control step
    (``follow`` lines), the value adfkit's joint had at that step's start; the replay that
    follows them leaves those joints' set-points unplayed, the set-point replay leaves the
    paths out. Control: recorded without it, there are no paths to follow."""
    rec, task, world = _recording_setup(ROOT / "sample_scenes" / "suturing" / "launch.yaml", None, True, 3)
    follow = [c for c in rec.commands if c.kind == "follow"]
    positions = {c.target for c in rec.commands if c.kind == "position"}
    assert len(positions) == 2 * 8  # both arms' joints (yaw, pitch, insertion, wrist, both jaws)
    cdt = world.dt * world.opt.control_substeps
    times = sorted({c.t for c in follow})
    assert times == pytest.approx([0.0, cdt, 2 * cdt])
    for k, t in enumerate(times):
        at = {c.target: c.value for c in follow if c.t == t}
        assert set(at) == positions
        if k:  # read back after the step before: the same values, to the bit
            assert at == rec.read[k - 1]
    moved = [abs(rec.read[1][n] - rec.read[0][n]) for n in positions]
    assert max(moved) > 0  # the arms move: a test of values, not of zeros
    full = _as_recording(rec)
    assert full.measured_paths()[follow[0].target].shape == (3, 2)
    played = full.commands_for("measured")
    assert not [c for c in played if c.kind == "position"] and len([c for c in played if c.kind == "follow"]) == 48
    assert {c.kind for c in played} >= {"place", "collide", "follow"}
    plain = full.commands_for("commands")
    assert (
        not [c for c in plain if c.kind == "follow"] and {c.target for c in plain if c.kind == "position"} == positions
    )
    assert follow[0].line() == f"0.0 follow {follow[0].target} {follow[0].value!r}"
    bare, _, _ = _recording_setup(ROOT / "sample_scenes" / "suturing" / "launch.yaml", None)
    assert not [c for c in bare.commands if c.kind == "follow"]
    with pytest.raises(ValueError, match="no measured joint paths"):
        _as_recording(bare).commands_for("measured")


def test_tracking_is_read_against_the_measured_path_after_its_first_point():
    """AMBF's joint against adfkit's path (linear between its points) at each sample after the
    path's first point: 0.6 at 0.5 s on a path through 0.5 is 0.1 off; the sample at 0 s, before
    any command, and the one past the path's end are not read."""
    from adfkit.parity.traces import Trace

    rec = _as_recording(_Commands([ambf.Command(0.0, "follow", "j", 0.0), ambf.Command(1.0, "follow", "j", 1.0)]))
    times = np.array([0.0, 0.5, 1.0, 1.5])
    joints = np.array([[5.0], [0.6], [1.0], [9.0]])
    tr = Trace("ambf", {}, ["b"], times, np.zeros((4, 1, 7)), ["j"], joints, 0.0)
    assert suture.tracking(rec, tr) == {"j": {"median": pytest.approx(0.05), "max": pytest.approx(0.1)}}
    # a revolute joint read a turn away is where the path is
    tr.joints[1, 0] = 0.5 + 2 * np.pi
    assert suture.tracking(rec, tr)["j"]["max"] == pytest.approx(0.0, abs=1e-12)


def test_the_replay_modes():
    """Following the measured joints is played at AMBF's own time, judged first with --follow both."""
    assert suture.replay_modes((None, suture.PACE), "commands") == [(None, "commands"), (suture.PACE, "commands")]
    assert suture.replay_modes((None,), "measured") == [(None, "measured")]
    assert suture.replay_modes((suture.PACE,), "both") == [(None, "measured"), (suture.PACE, "commands")]
    with pytest.raises(ValueError, match="no pace"):
        suture.replay_modes((suture.PACE,), "measured")


@needs_ambf
def test_a_joint_follows_a_path_on_its_measured_position_in_ambf(tmp_path):
    """The parity arm's joint given a path (0.5 rad · sin 2πt, a point each 4 ms as the suture's
    recording has them): each 1 ms step a velocity command of the path's slope plus 100/s times
    its error keeps it within a milliradian (measured 0.68 mrad at most, 0.08 mrad median). The
    control: the same points as position commands, through AMBF's controller, trail the path
    (measured 0.33 rad at most). A follow on a joint AMBF has not is the plugin's located error."""
    from adfkit.diagnostics import AdfError
    from adfkit.scenes.parity import write_parity

    stage = ambf.Stage(write_parity(tmp_path), [1])
    joint = "/ambf/env/arm/base-arm"
    ts = np.arange(0.0, 1.0 + 1e-9, 0.004)
    path = 0.5 * np.sin(2 * np.pi * ts)

    def error_of(kind: str):
        run = ambf.run(
            BUILD, stage, 1.0, 0.02, [ambf.Command(float(t), kind, joint, float(q)) for t, q in zip(ts, path)]
        )
        tr = from_ambf(run)
        return np.abs(tr.joints[:, tr.joint_names.index(joint)] - 0.5 * np.sin(2 * np.pi * tr.times)), run.end

    err, end = error_of("follow")
    assert err.max() < 2e-3 and np.median(err) < 5e-4
    assert end["follow"][joint]["steps"] == 1000 and end["follow"][joint]["max_error"] < 0.01
    trailing, end = error_of("position")
    assert trailing.max() > 0.1 and end["follow"] == {}
    with pytest.raises(AdfError, match="no joint /ambf/env/arm/elbow"):
        ambf.run(BUILD, stage, 0.1, 0.05, [ambf.Command(0.0, "follow", "/ambf/env/arm/elbow", 0.1)])


@needs_ambf
def test_a_scene_without_a_suture_is_a_setup_error_not_a_traceback(tmp_path, capsys):
    """`adfkit parity --suture` on a scene with no needle, holes or PSMs (the parity arm) says
    what the suture needs, exit 2, as `adfkit suture` does (it raised a KeyError from the
    suture's setup). Control: the message names what is missing."""
    from adfkit.cli import main
    from adfkit.scenes.parity import write_parity

    launch = write_parity(tmp_path)
    assert main(["parity", "--suture", str(launch), "-l", "1", "--pairs", "1"]) == 2
    err = capsys.readouterr().err
    assert "error[suture-setup]: no unique body matches 'Needle'" in err and "Traceback" not in err
    assert "the scene needs a Needle" in err


def _velocities(run, name: str) -> np.ndarray:
    """A body's linear velocity at each sample (the plugin's ADFKIT_PARITY_VELOCITIES record)."""
    i = run.body_names().index(name)
    return np.array([s["velocities"][i] for s in run.samples], float)


@needs_ambf
def test_ambfs_hole_ghosts_give_the_static_phantom_a_velocity_its_hole_bodies_take(monkeypatch):
    """AMBF's ghost sets the velocity of every rigid body it senses, the static phantom too (its
    hull reaches into the hole ghosts): Bullet never moves a static body, but the six-dof springs
    that hang the hole bodies on it damp them towards that velocity, and the ghosts give the
    phantom their hole bodies' velocities back. At rest, 1 s (the corpus phantom and its ghosts
    alone): the phantom 5.9e-5 m/s, Entry1 5.1e-5 m/s, measured. Control: the plugin's
    ADFKIT_PARITY_STILL_STATIC puts every static body at rest after each step, and nothing moves."""
    from conftest import CORPUS, require_corpus

    require_corpus()
    stage = ambf.Stage(CORPUS / "src/launch.yaml", [10, 11])
    monkeypatch.setenv("ADFKIT_PARITY_VELOCITIES", "1")
    monkeypatch.delenv("ADFKIT_PARITY_STILL_STATIC", raising=False)
    run = ambf.run(BUILD, stage, 1.0, 0.1)
    phantom, entry = "/ambf/env/phantom/Phantom", "/ambf/env/phantom/Entry1"
    assert run.created["bodies"][run.body_names().index(phantom)]["mass"] == 0.0
    assert np.abs(_velocities(run, phantom)).max() > 1e-5
    assert np.linalg.norm(_velocities(run, entry), axis=1).max() > 1e-5
    monkeypatch.setenv("ADFKIT_PARITY_STILL_STATIC", "1")
    still = ambf.run(BUILD, stage, 1.0, 0.1)
    assert np.abs(_velocities(still, phantom)).max() == 0.0
    assert np.linalg.norm(_velocities(still, entry), axis=1).max() < 1e-9


@needs_ambf
def test_undoing_what_ambfs_ghost_did_to_a_cube_lets_it_fall_through_the_slab(tmp_path, monkeypatch):
    """The plugin's ADFKIT_PARITY_UNGHOST ("NAME PARTS") gives the bodies named back, after each
    step, the velocities Bullet's step left them and the world's gravity, undoing AMBF's ghosts:
    the parity scene's cube, which AMBF's ghost slab stops (z 0.20-0.25 m), falls through it to
    the floor as its twin beside the slab does. Control: without the knob it stops in the slab."""
    from adfkit.scenes.parity import write_parity

    stage = ambf.Stage(write_parity(tmp_path), [3])
    cube, twin = "/ambf/env/ghost/cube", "/ambf/env/ghost/twin"

    def heights() -> tuple[float, float]:
        tr = from_ambf(ambf.run(BUILD, stage, 0.6, 0.3))
        return tuple(float(tr.poses[-1, tr.body_names.index(n), 2]) for n in (cube, twin))

    monkeypatch.delenv("ADFKIT_PARITY_UNGHOST", raising=False)
    z_cube, z_twin = heights()
    assert 0.2 < z_cube < 0.25 and z_twin < 0.1
    monkeypatch.setenv("ADFKIT_PARITY_UNGHOST", "ghost/cube linear angular gravity")
    z_cube, z_twin_again = heights()
    assert z_cube == pytest.approx(z_twin, abs=1e-3) and z_twin_again == pytest.approx(z_twin, abs=1e-6)


@needs_ambf
def test_friction_rows_started_from_zero_bring_ambfs_rolling_ball_onto_adfkits(tmp_path, monkeypatch):
    """The plugin's ADFKIT_PARITY_FRICTION, a measurement knob: "fresh" starts every friction row
    of AMBF's Bullet from zero, as PyBullet's Bullet does, "two" solves two friction directions per
    contact point, as PyBullet's world does. On the parity scene's ramp the ball without rolling
    friction ends 17.2 mm from adfkit's after 1 s as AMBF plays it (its row restarted from 0.85 of
    its last impulse, "Friction in AMBF's Bullet"); from zero, 0.00 mm; with the second direction
    alone, 17.2 mm again (measured). Control: the knob off, the gap is back."""
    from adfkit.parity import session
    from adfkit.scenes.parity import SCENES, write_parity

    launch = write_parity(tmp_path)
    req = session.Request(launch, [SCENES.index("ramp")], BUILD, seconds=1.0)

    def rolling_gap() -> float:
        (c,) = session.run(req, progress=False).comparisons
        return next(g.max_position for g in c.bodies if g.name.endswith("/rolling"))

    monkeypatch.setenv("ADFKIT_PARITY_FRICTION", "fresh")
    assert rolling_gap() < 0.5e-3
    monkeypatch.setenv("ADFKIT_PARITY_FRICTION", "two")
    assert rolling_gap() > 10e-3
    monkeypatch.delenv("ADFKIT_PARITY_FRICTION")
    assert rolling_gap() > 10e-3


@needs_ambf
def test_a_threads_joints_solved_with_iterations_of_their_own_stand_closed_in_ambf(tmp_path, monkeypatch):
    """The plugin's ADFKIT_PARITY_JOINT_ITERATIONS ("SUBSTRING N"), a measurement knob: the joints
    whose names hold SUBSTRING solved with N iterations of their own. The parity scene's thread
    falling from its held needle, 1 s: AMBF's joints stand open 2.0 mm at most, 13.2 mm summed at
    once, at the world's 10 iterations; 0.35 and 2.2 mm with 100 of their own (measured). adfkit's
    side is not touched. Control: the knob naming no joint leaves them open."""
    from adfkit.parity import session
    from adfkit.scenes.parity import SCENES, write_parity

    launch = write_parity(tmp_path)
    req = session.Request(launch, [SCENES.index("thread")], BUILD, seconds=1.0)

    def opening() -> tuple[float, float]:
        (c,) = session.run(req, progress=False).comparisons
        o = c.as_json()["joint_opening"]
        return o["ambf"]["summed_m"], o["pybullet"]["summed_m"]

    monkeypatch.setenv("ADFKIT_PARITY_JOINT_ITERATIONS", "nothing-named-so 100")
    open_ambf, open_adfkit = opening()
    assert open_ambf > 8e-3
    monkeypatch.setenv("ADFKIT_PARITY_JOINT_ITERATIONS", "/thread/Thread 100")
    closed_ambf, same_adfkit = opening()
    assert closed_ambf < open_ambf / 3 and same_adfkit == open_adfkit


def _parity_args(*extra: str):
    from adfkit.cli import build_parser

    return build_parser().parse_args(["parity", "--suture", *extra])


def test_the_suture_is_recorded_under_the_options_the_user_names():
    """`adfkit parity --suture` records under the suture's own Options (those `adfkit suture`
    plays: implicit springs, PyBullet's bodies, hole friction, shapes about the links' centres of
    mass, a 4 ms control step, 50 solver iterations) unless the user names others; what they name
    and nothing else changes."""
    from adfkit.commands.parity import recording_options
    from adfkit.runner import Options
    from adfkit.tasks.episode import SOLVER_ITERATIONS

    own = suture.record_options(recording_options(_parity_args()))
    plain = Options()
    assert [getattr(own, k) for k in suture.RECORD_OPTIONS] == [getattr(plain, k) for k in suture.RECORD_OPTIONS]
    assert own.solver_iterations == SOLVER_ITERATIONS
    named = suture.record_options(recording_options(_parity_args("--springs", "ambf", "--link-shapes", "body")))
    assert (named.springs, named.link_shapes) == ("ambf", "body")
    assert (named.bodies, named.ghosts, named.control_substeps) == (plain.bodies, plain.ghosts, plain.control_substeps)
    every = recording_options(
        _parity_args("--bodies", "ambf", "--ghosts", "ambf", "--control-substeps", "1", "--springs", "implicit")
    )
    assert every == {
        "springs": "implicit",
        "bodies": "ambf",
        "ghosts": "ambf",
        "link_shapes": None,
        "control_substeps": 1,
    }
    with pytest.raises(ValueError, match="not solver_iterations"):
        suture.record_options({"solver_iterations": 10})


def _needle_after(world, seconds: float) -> tuple[float, float]:
    """How far (m) and through what angle (deg) the needle has moved from where it started."""
    needle = next(sb for sb in world.bodies if sb.key.endswith("Needle"))
    m0 = needle.world_matrix().copy()
    while world.sim_time < seconds - 1e-9:
        world.step(1)
    m = needle.world_matrix()
    turn = np.clip((np.trace(m0[:3, :3].T @ m[:3, :3]) - 1.0) / 2.0, -1.0, 1.0)
    return float(np.linalg.norm(m[:3, 3] - m0[:3, 3])), float(np.degrees(np.arccos(turn)))


def test_the_recording_world_plays_the_springs_the_user_names(tmp_path):
    """The springy-holes copy lays its thread's first joint bent 15.4°: in the suture's own world
    (implicit springs over the 4 ms control step) the joint straightens within 20 ms and throws the
    needle 2.3 mm and 8°; recorded under AMBF's springs (explicit at every 1 ms step) the needle
    moves 0.4 mm (AMBF's: 0.73 mm, turned 1.4°). The world the recording is made in is the one
    that plays what was named."""
    import subprocess
    import sys

    subprocess.run([sys.executable, str(ROOT / "bench" / "springy_holes.py"), str(tmp_path)], check=True)
    launch = tmp_path / "launch.yaml"
    moved = {}
    for springs in ("implicit", "ambf"):
        world = suture.recording_world(launch, None, {"springs": springs})
        try:
            assert world.opt.springs == springs and world.opt.solver_iterations == 50
            moved[springs] = _needle_after(world, 0.02)
        finally:
            world.close()
    assert moved["implicit"][0] > 0.002 and moved["implicit"][1] > 7.0
    assert moved["ambf"][0] < 0.001 and moved["ambf"][1] < 7.0


def test_the_suture_reads_contact_forces_alike_however_the_world_steps():
    """The bundled needle at rest on the phantom presses on it with the same newtons (5.3 N of
    its 4.9 N weight and its thread's share) whether a control step is one stepSimulation of
    four physics steps (the suture's own world, where PyBullet reports a quarter of the force,
    multiplied back by physics_steps_a_call) or they are stepped one by one (AMBF's springs)."""
    read = {}
    for springs in ("implicit", "ambf"):
        world = suture.recording_world(ROOT / "sample_scenes" / "suturing" / "launch.yaml", None, {"springs": springs})
        try:
            needle = next(sb for sb in world.bodies if sb.key.endswith("Needle"))
            while world.sim_time < 0.2 - 1e-9:
                world.step(1)
            read[springs] = (world.physics_steps_a_call, sum(f for _, _, f, _ in world.contacts_among([needle])))
        finally:
            world.close()
    assert read["implicit"][0] == 4 and read["ambf"][0] == 1
    assert read["ambf"][1] == pytest.approx(read["implicit"][1], rel=0.05)
    assert read["implicit"][1] > 4.0  # the needle lies on the phantom: a test of forces, not of zeros


@needs_ambf
def test_the_contact_points_between_two_bodies_every_step_with_the_shapes_as_bullet_holds_them(tmp_path, monkeypatch):
    """The plugin's ADFKIT_PARITY_POINTS ("T0 T1 A B[,B...]", written to ADFKIT_PARITY_POINTS_OUT),
    a measurement knob: every physics step from T0 to T1, each contact point between a body named
    A and one named B. The parity stack's top box (8 cm, 0.4 kg) resting on the middle one, 0.9-1.0
    s: one manifold a step, its four points on the top box's bottom face (4 cm under its centre),
    the normal upright, the impulses summing to the box's weight over the 1 ms step (3.92 N on the
    mean, 3.83-4.03 N a step, measured); the shapes line holds both boxes' shapes as Bullet holds
    them (AMBF's compound of one box, with AMBF's 1 mm margin) and AMBF's 10 solver iterations.
    Control: a name that matches nothing writes the shapes line alone."""
    from adfkit.scenes.parity import write_parity

    stage = ambf.Stage(write_parity(tmp_path), [2])
    out = tmp_path / "points.jsonl"
    monkeypatch.setenv("ADFKIT_PARITY_POINTS_OUT", str(out))
    monkeypatch.setenv("ADFKIT_PARITY_POINTS", "0.9 1.0 stack/box3 stack/box2")
    ambf.run(BUILD, stage, 1.0, 0.5)
    import json

    shapes, *steps = [json.loads(line) for line in out.read_text().splitlines()]
    assert shapes["kind"] == "shapes" and shapes["double"] is True and shapes["solver"]["iterations"] == 10
    held = {b["name"]: b["shape"] for b in shapes["bodies"]}
    assert set(held) == {"/ambf/env/stack/box3", "/ambf/env/stack/box2"}
    assert held["/ambf/env/stack/box3"]["type"] == "Compound"
    box = held["/ambf/env/stack/box3"]["children"][0]["shape"]
    assert box["type"] == "Box" and box["margin"] == pytest.approx(0.001)
    assert len(steps) == 101 and steps[0]["t"] == pytest.approx(0.9) and steps[-1]["t"] == pytest.approx(1.0)
    weight = [sum(p[8] for p in s["points"]) / 1e-3 for s in steps]  # N: the impulses over the 1 ms step
    assert np.mean(weight) == pytest.approx(0.4 * 9.81, rel=0.005) and np.ptp(weight) < 0.4
    for s in steps:
        top_is_a = s["A"].endswith("box3")
        assert {s["A"], s["B"]} == set(held) and len(s["points"]) == 4
        for p in s["points"]:
            normal = np.array(p[6]) * (1 if top_is_a else -1)  # on B, towards A: up onto the top box
            assert normal @ [0, 0, 1] > 0.999 and abs(p[7]) < 1e-4
            local_on_top = np.array(p[4] if top_is_a else p[5])
            assert local_on_top[2] == pytest.approx(-0.04, abs=1e-4)
    monkeypatch.setenv("ADFKIT_PARITY_POINTS", "0.9 1.0 stack/box3 nothing-named-so")
    ambf.run(BUILD, stage, 1.0, 0.5)
    lines = out.read_text().splitlines()
    assert len(lines) == 1 and json.loads(lines[0])["bodies"][0]["name"] == "/ambf/env/stack/box3"
