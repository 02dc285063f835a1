"""The scripted suture (adfkit/tasks): needle geometry, the grasp held and released, a one-pair
suture on the project's own scene, its metrics and pictures, the corpus set, and four pairs on
several seeds (slow)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import CORPUS, ROOT, require_corpus

from adfkit.tasks.needle import fit_needle

BUNDLED = ROOT / "sample_scenes" / "suturing" / "launch.yaml"


def _arc(radius, start, span, n=400, tube=0.0004):
    rng = np.random.default_rng(0)
    phi = rng.uniform(start, start + span, n)
    around = rng.uniform(0, 2 * np.pi, n)
    r = radius + tube * np.cos(around)
    return np.c_[r * np.cos(phi), r * np.sin(phi), tube * np.sin(around)]


def test_needle_fit_finds_circle_tip_and_tail():
    v = _arc(0.0102, math.radians(20), math.radians(150))
    tail = np.array([0.0102 * math.cos(math.radians(20)), 0.0102 * math.sin(math.radians(20)), 0.0])
    g = fit_needle(v, tail_hint=tail)
    assert g.radius == pytest.approx(0.0102, abs=2e-4)
    assert math.degrees(g.span) == pytest.approx(150, abs=3)
    tip = 0.0102 * np.array([math.cos(math.radians(170)), math.sin(math.radians(170)), 0.0])
    assert np.linalg.norm(g.tip - tip) < 5e-4 and np.linalg.norm(g.tail - tail) < 5e-4
    # turning the arc frame by +a about its z moves the tip forward, away from the tail
    a = g.arc_in_needle
    ahead = (a @ np.array([g.radius * math.cos(0.1), g.radius * math.sin(0.1), 0, 1]))[:3]
    assert np.linalg.norm(ahead - g.tail) > np.linalg.norm(g.tip - g.tail)


def _strict(path: Path) -> dict:
    def bad(x):
        raise ValueError(f"non-finite {x} in strict JSON")

    return json.loads(path.read_text(), parse_constant=bad)


def _bundled():
    if not BUNDLED.is_file():
        pytest.skip("sample_scenes/suturing is not in this checkout")
    return BUNDLED


@pytest.fixture(scope="module")
def one_pair(tmp_path_factory):
    from adfkit.tasks.episode import run_episode

    out = tmp_path_factory.mktemp("suture1")
    return run_episode(_bundled(), None, [1], seed=0, out=out, progress=False), out


@pytest.mark.slow
def test_one_pair_on_the_project_scene(one_pair):
    m, out = one_pair
    assert m["failure"] is None
    (p,) = m["pairs"]
    assert p["passed"] and p["entry_passed_s"] < p["exit_passed_s"]
    assert m["all_passed"] and not m["exploded"]


@pytest.mark.slow
def test_metrics_json_and_pictures(one_pair):
    m, out = one_pair
    j = _strict(out / "metrics.json")
    assert j["pairs"] == m["pairs"]
    names = [p["phase"] for p in j["phases"]]
    assert names[:5] == ["settle", "pick up", "carry 1", "insert 1", "regrasp 1"] and names[-1] == "done"
    assert sum(p["duration_s"] for p in j["phases"]) == pytest.approx(j["simulated_time_s"], abs=1e-6)
    assert len(j["needle_final_pose"]["position"]) == 3
    assert np.linalg.norm(j["needle_final_pose"]["orientation"]) == pytest.approx(1.0, abs=1e-6)
    assert 0 <= j["max_constraint_error_m"] < 0.01 and j["real_time_factor"] > 0
    # every joint closed to 1 mm in every phase (the needle-thread joint opened 2.3 mm while the
    # needle was carried, with its pivots 5 mm beside the thread), the fixed joint within 5 degrees
    errors, angles = j["constraint_error_by_phase_m"], j["joint_angle_error_by_phase_deg"]
    assert set(errors) == set(angles) >= {"settle", "pick", "carry", "insert", "regrasp", "pull"}
    assert max(errors.values()) <= 1e-3 and max(angles.values()) < 5.0, (errors, angles)
    assert j["thread_length_through_tissue_m"] >= 0 and j["exploded"] is False
    from PIL import Image

    assert Image.open(out / "trajectory.png").size[0] > 300
    gif = Image.open(out / "cameraL.gif")
    assert gif.n_frames > 5 and gif.size[0] <= 320
    # camera L at its own resolution as an MP4, a frame every 0.2 s simulated
    import imageio.v2 as imageio

    v = j["video"]
    assert "cameraL.mp4" in j["files"] and v["frames"] == pytest.approx(j["simulated_time_s"] / 0.2, abs=2)
    with imageio.get_reader(out / "cameraL.mp4") as r:
        frame = r.get_data(0)
    assert frame.shape == (v["height"], v["width"], 3) and v["width"] >= 640


def test_servo_holds_the_roll_at_the_limit_it_met():
    """A Cartesian set-point a little past the tool roll's limit (+3.054 rad) is clipped to that
    limit. Past +pi the IK gives the roll near -pi, and clipped that was the other limit, a full
    turn away: in the corpus set the roll turned 5.2 rad in 60 ms and threw the needle out."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.tasks.suture import SutureTask

    world = open_world(load_scene(_bundled()), Options(visuals=False))
    try:
        task = SutureTask(world, [1], seed=0)
        psm = task.psms["psm1"]
        q = np.array([0.1, -0.1, 0.12, 3.0, 0.2, -0.1])
        psm.servo_jp(q)
        hi = psm.kin.upper_limits[3]
        for roll in (3.10, math.pi + 0.05):  # past the limit; past +pi
            past = q.copy()
            past[3] = roll
            task.servo_world(psm, psm.base_in_world() @ psm.kin.fk(past))
            assert psm.setpoint_jp()[3] == pytest.approx(hi)
            psm.servo_jp(q)
        far = q.copy()
        far[3] = hi + 0.2  # -3.03 as the IK gives it: inside the limits, a full turn away
        with pytest.raises(ValueError):  # beyond what a set-point may be clipped by: refused
            task.servo_world(psm, psm.base_in_world() @ psm.kin.fk(far))
        assert psm.setpoint_jp()[3] == pytest.approx(3.0)
        assert task.clipped == 2
    finally:
        world.close()


@pytest.mark.slow
def test_needle_held_while_carried_and_released_when_the_jaws_open():
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world
    from adfkit.tasks.suture import SutureTask

    world = open_world(load_scene(_bundled()), Options())
    try:
        task = SutureTask(world, [1], seed=0)
        run = lambda gen: [world.step(1) for _ in gen]  # noqa: E731
        run(task.wait(0.3))
        task._arms_apart()
        task.plan()
        run(task.take(task.driver, task.drive_grasps[0]))
        psm = task.psms[task.driver]
        start = task.needle_pose()
        drift = []
        for _ in task.carry(lambda s: task.lifted(start, 0.03 * s), 1.0):
            world.step(1)
            ee = psm.base_in_world() @ psm.measured_cp()
            expected = ee @ np.linalg.inv(task.held_ee_in_needle)
            drift.append(np.linalg.norm(expected[:3, 3] - task.needle_pose()[:3, 3]))
        assert task.needle_pose()[2, 3] - start[2, 3] == pytest.approx(0.03, abs=2e-3)
        assert max(drift) < 1e-3
        held_z = task.needle_pose()[2, 3]
        run(task.let_go(task.driver))
        run(task.wait(0.5))
        assert held_z - task.needle_pose()[2, 3] > 0.01  # it fell once the jaws opened
        act = next(a for a in world.actuators if f"/{task.driver}/" in a.key or f"/{task.driver}/" in a.parent.key)
        assert act.target is None
    finally:
        world.close()


def test_corpus_set_needle_stays_right_side_up_while_the_scene_settles():
    """The corpus set's needle turned over in its first 0.1 s: its phantom's collision mesh (one
    object of eleven materials) was one hull, which lay 1.8 mm over the thread and 5.2 mm over
    the needle; pushed out, the thread element next to the needle spun at 316 rad/s and the
    thread's springs threw the needle over. Hulled per material, as AMBF does, it stays up."""
    require_corpus()
    from adfkit.adf import load_scene, parse_indices
    from adfkit.runner import Options, open_world
    from adfkit.tasks.episode import SOLVER_ITERATIONS

    scene = load_scene(CORPUS / "src" / "launch.yaml", parse_indices("6-11"), [])
    world = open_world(scene, Options(solver_iterations=SOLVER_ITERATIONS, visuals=False))
    try:
        needle = world.body("BODY Needle")
        up = []
        for _ in range(10):
            world.run(0.1)
            up.append(needle.world_matrix()[2, 2])
        assert min(up) > 0.9, up
    finally:
        world.close()


def test_corpus_set_hole_bodies_are_tissue_to_the_observer():
    """The corpus set's Entry/Exit bodies (0.2 kg on springs to the phantom, not static) are
    tissue to the verdicts: a needle or a tool pressing on them is seen, as on the bundled
    scene's static holes."""
    require_corpus()
    from adfkit.adf import load_scene, parse_indices
    from adfkit.runner import Options, open_world
    from adfkit.tasks.metrics import SutureObserver
    from adfkit.tasks.suture import SutureTask

    scene = load_scene(CORPUS / "src" / "launch.yaml", parse_indices("6-11"), [])
    world = open_world(scene, Options(visuals=False))
    try:
        obs = SutureObserver(SutureTask(world, [1], seed=0))
        names = {sb.key.split("/")[-1] for sb in obs.tissue}
        assert {f"BODY {k}{i}" for k in ("Entry", "Exit") for i in range(1, 5)} <= names
        assert "BODY Phantom" in names and not any("Needle" in n or "Thread" in n for n in names)
    finally:
        world.close()


def _corpus_through(pairs: list[int], seed: int) -> dict:
    """A corpus-set episode, checked: every pair passed from the physics, the needle never
    pressed on the tissue from the first insertion on (it used to, with up to 512 N, through
    PyBullet's 1 mm hull margins), no tool pressed on it, nothing slipped (PyBullet's newtons:
    its limits are 4x MuJoCo's, tasks/contact_forces.py)."""
    from adfkit.tasks.episode import run_episode

    m = run_episode(CORPUS / "src" / "launch.yaml", "6-11", pairs, seed=seed, out=None, progress=False, gif=False)
    assert m["failure"] is None, m["failure"]
    assert [p["passed"] for p in m["pairs"]] == [True] * len(pairs), [(p["pair"], p["reason"]) for p in m["pairs"]]
    inside = [ph for ph in m["needle_tissue_contact_n"] if ph.split()[0] in ("insert", "regrasp", "pull", "hand")]
    assert max((f for ph in inside for f in m["needle_tissue_contact_n"][ph].values()), default=0.0) < 20.0
    assert (
        m["tip_tissue_contact_n"] == {} or max(f for d in m["tip_tissue_contact_n"].values() for f in d.values()) < 20.0
    )
    assert max((e["max_force_n"] for e in m["tool_tissue_events"]), default=0.0) < 20.0  # a touch at most
    assert m["slips"] == []
    assert m["max_constraint_error_m"] < 1e-3
    return m


@pytest.mark.slow
def test_corpus_set_pair_1():
    """The corpus set's own phantom collision, everything colliding: the needle goes in through
    Entry1 and out through Exit1 without pressing on the phantom's slab or its ridge blocks."""
    require_corpus()
    _corpus_through([1], seed=0)


@pytest.mark.slow
def test_corpus_set_four_pairs():
    """Pairs 1-4 of the corpus set, the thread drawn through each: the puller takes the needle
    at every regrasp and the driver at every hand-back."""
    require_corpus()
    m = _corpus_through([1, 2, 3, 4], seed=0)
    assert 0 < m["thread_length_through_tissue_m"] <= m["thread_length_m"]


@pytest.fixture(scope="module")
def four_pairs_ten_seeds():
    from adfkit.tasks.episode import run_episode

    return [run_episode(_bundled(), None, [1, 2, 3, 4], seed=s, out=None, progress=False, gif=False) for s in range(10)]


@pytest.mark.slow
def test_four_pairs_on_ten_of_ten_seeds_with_the_needle_held_and_the_joints_closed(four_pairs_ten_seeds):
    """Issue 23, with the needle, the thread and the tools colliding with the phantom and the hole
    boundaries: every pair passed on every seed, the needle within 1 mm of where the grasp took
    it while one arm holds it, and every joint closed to 1 mm in every phase."""
    failed = {
        m["seed"]: [(p["pair"], p["rule"]) for p in m["pairs"] if not p["passed"]] or m["failure"]
        for m in four_pairs_ten_seeds
        if not m["all_passed"]
    }
    assert failed == {}
    for m in four_pairs_ten_seeds:
        drift, errors = m["grasp_drift_one_arm_by_phase_m"], m["constraint_error_by_phase_m"]
        assert max(drift.values()) <= 1e-3, (m["seed"], drift)
        assert max(errors.values()) <= 1e-3, (m["seed"], errors)
        assert 0 <= m["thread_length_through_tissue_m"] <= m["thread_length_m"]  # never more than there is


def test_cli_bad_input_is_exit_2(tmp_path, capsys):
    from adfkit.cli import main

    assert main(["suture", "--pairs", "0", "--out", str(tmp_path)]) == 2
    assert main(["suture", "--pairs", "x", "--out", str(tmp_path)]) == 2
    assert main(["suture", str(tmp_path / "none.yaml"), "--out", str(tmp_path)]) == 2
    assert "bad-option" in capsys.readouterr().err


@pytest.fixture(scope="module")
def mujoco_pair_1(tmp_path_factory):
    from adfkit.cli import main

    out = tmp_path_factory.mktemp("mj")
    rc = main(["suture", "--engine", "mujoco", "--pairs", "1", "--out", str(out)])
    return rc, _strict(out / "metrics.json"), out


@pytest.mark.slow
def test_the_suture_runs_on_the_mujoco_engine(mujoco_pair_1):
    """Issue 17: the same suture script on MuJoCo, with the needle colliding with the phantom
    and the hole boundaries (issue 23): it plays the pair to its end and gives a verdict with
    a reason, the pictures and no explosion."""
    rc, j, out = mujoco_pair_1
    assert rc in (0, 1)
    (p,) = j["pairs"]
    assert p["passed"] == (rc == 0) and (p["passed"] or (p["rule"] and p["reason"]))
    assert (out / "cameraL.gif").stat().st_size > 10_000 and not j["exploded"]


@pytest.mark.slow
def test_the_suture_passes_pair_1_on_the_mujoco_engine(mujoco_pair_1):
    """Issue 23, with everything colliding: the needle goes in through Entry1 and out through
    Exit1 and the thread follows. It used to be blocked beside Entry1 (the tip on the phantom
    with 52-65 N, 1.2-1.5 mm off the opening): the wrist's PD servos, sized for its light links,
    let the held needle turn the wrist 0.3 rad; MuJoCo's joint motors are constraints now
    (runner/mujoco/drives.py). The needle stays within 1 mm of where the grasp took it (it
    slid 5-12 mm)."""
    rc, j, _ = mujoco_pair_1
    (p,) = j["pairs"]
    assert rc == 0 and p["passed"] and p["entry_passed_s"] < p["exit_passed_s"], p
    assert j["grasp_drift_max_m"] < 1e-3 and not j["instabilities"]


@pytest.fixture(scope="module")
def mujoco_four_pairs():
    from adfkit.tasks.episode import run_episode

    return [
        run_episode(_bundled(), None, [1, 2, 3, 4], seed=s, out=None, progress=False, gif=False, engine="mujoco")
        for s in (0, 1)
    ]


@pytest.mark.slow
def test_the_suture_passes_four_pairs_on_the_mujoco_engine(mujoco_four_pairs):
    """Four pairs in MuJoCo, everything colliding, on two seeds (seed 1's driver touches the slab
    as it takes the needle, a one-step spike): every pair passes, nothing unstable, the needle
    within 1 mm of where each grasp took it. `adfkit suture --engine mujoco --pairs 4
    --episodes 10` gives the figures on ten seeds (docs/suture.md)."""
    for m in mujoco_four_pairs:
        assert m["failure"] is None and m["all_passed"], [(p["pair"], p["rule"], p["reason"]) for p in m["pairs"]]
        assert not m["instabilities"] and m["grasp_drift_max_m"] < 1e-3
        assert 0 < m["thread_length_through_tissue_m"] <= m["thread_length_m"]
