"""The project's own suturing scene (adfkit build-scene suturing): deterministic files, a
clean validation, the expected objects in the runner, PSMs that calibrate to the DH
kinematics and reach every hole from above, a stable short play, the bundled copy current."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from adfkit.adf import load_scene
from adfkit.cli import main
from adfkit.scenes import BUILDERS, write_suturing
from adfkit.scenes.suturing import layout

ROOT = Path(__file__).resolve().parents[1]
BUNDLED = ROOT / "sample_scenes" / "suturing"


def _files(d: Path) -> dict[str, bytes]:
    return {str(p.relative_to(d)): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("suturing")
    write_suturing(d)
    return d


@pytest.fixture(scope="module")
def world(built):
    from adfkit.runner import open_world

    w = open_world(load_scene(built / "launch.yaml", None, []))
    yield w
    w.close()


def test_build_is_deterministic(built, tmp_path):
    BUILDERS["suturing"](tmp_path)
    assert _files(tmp_path) == _files(built)
    assert len(_files(built)) == 28


def test_bundled_copy_equals_a_fresh_build(built):
    assert _files(BUNDLED) == _files(built), "run: adfkit build-scene suturing sample_scenes/suturing"


def test_validate_reports_no_errors_or_warnings(built, capsys):
    assert main(["validate", str(built / "launch.yaml")]) == 0
    out = capsys.readouterr()
    assert "0 error(s), 0 warning(s)" in out.out + out.err


def test_runner_builds_the_expected_objects(world):
    rep = world.report()
    assert rep["multibodies"] == 2
    assert sum(1 for b in world.bodies if b.body.name and b.body.name.startswith("Thread")) == 40
    assert rep["spring_joints"] == 39
    names = sorted(g.ghost.name for g in world.ghosts)
    assert names == sorted(
        [f"ghost{k}{i}" for k in ("Entry", "Exit") for i in range(1, 5)]
        + ["left_finger_ghost", "right_finger_ghost"] * 2
    )
    assert rep["actuators"] == 2 and rep["sensors"] == 2
    assert {"cameraL", "cameraR"} <= set(rep["cameras"])
    assert not world.diagnostics


def test_both_psms_calibrate_exactly(world):
    from adfkit.runner.psm import PSM

    for name in ("psm1", "psm2"):
        psm = PSM(world, name)
        assert psm.calibration_error < 1e-8
        # the DH base frame is where the layout put it
        assert np.allclose(psm.base_in_world(), layout.psm_base(name), atol=1e-7)


def test_ik_reaches_the_needle_and_every_hole_from_above():
    reach = layout.check_reach()
    assert len(reach) == 10
    assert all(r.q is not None for r in reach), [r.error for r in reach if r.q is None]
    from adfkit.runner.psm_kinematics import default

    kin = default()
    for r in reach:  # comfortably inside: every joint 0.07 (m or rad) or more from its limits
        margin = np.minimum(r.q - kin.lower_limits[:6], kin.upper_limits[:6] - r.q)
        assert margin.min() > 0.07, (r.name, r.label, r.q)


def test_needle_at_entry_puts_the_tip_in_the_hole_and_its_turn_reaches_the_exit():
    for k in range(1, 5):
        entry, exit_ = layout.hole_poses(k)
        n = layout.needle_at_entry(k)
        assert np.allclose(layout.arc_point(n, layout.NEEDLE_TIP_ANGLE), entry[:3, 3], atol=1e-9)
        # the tip enters along the hole's -z (into the tissue)
        assert np.dot(layout.arc_tangent(n, layout.NEEDLE_TIP_ANGLE), -entry[:3, 2]) > 0.999
        from adfkit.scenes.suturing.frames import rot_z

        turn = 2 * (np.pi / 2 - layout.entry_angle())
        assert np.allclose(layout.arc_point(n @ rot_z(-turn), layout.NEEDLE_TIP_ANGLE), exit_[:3, 3], atol=1e-9)


def test_a_short_play_is_stable(world):
    from adfkit.runner.psm import PSM

    psm = PSM(world, "psm1")
    q0 = psm.measured_jp()
    world.run(1.0)
    rep = world.report()
    assert not rep["nan"] and not rep["exploded"] and not rep["fell_through_floor"]
    assert rep["max_constraint_error_m"] < 1e-3
    assert np.allclose(psm.measured_jp(), q0, atol=1e-4)  # the arm holds its home pose
    # the thread holds together: every pair of neighbouring elements still meets at its pivots
    thread = {b.body.name: b for b in world.bodies if b.body.name and b.body.name.startswith("Thread")}
    p = layout.THREAD_PITCH
    for i in range(1, 40):
        a = thread["Thread" if i == 1 else f"Thread_{i - 1:03d}"].world_matrix()
        b = thread[f"Thread_{i:03d}"].world_matrix()
        gap = (a @ [0, 0, -p / 2, 1])[:3] - (b @ [0, 0, p / 2, 1])[:3]
        assert np.linalg.norm(gap) < 1e-3
    # the needle lies still and flat where the layout put it (its thread does not lift it)
    needle = world.body("Needle").world_matrix()
    assert np.linalg.norm(needle[:3, 3] - layout.needle_start()[:3, 3]) < 1e-3
    assert needle[2, 2] > np.cos(np.radians(2))


def test_psm1_picks_the_needle_up_from_above(built):
    """IK to the needle's start pose from above, jaws open, down, grasp through the actuator,
    lift 2 cm: the needle (not a thread element) comes along, held within a millimetre."""
    from adfkit.runner import open_world
    from adfkit.runner.psm import PSM

    world = open_world(load_scene(built / "launch.yaml", None, []))
    try:
        psm = PSM(world, "psm1")
        needle = world.body("Needle")
        start = needle.world_matrix()
        to_base = np.linalg.inv(psm.base_in_world())
        angle = layout.NEEDLE_GRASP_ANGLE
        grasp = to_base @ layout.grasp_ee_pose(start, angle, layout.shaft_direction("psm1", start, angle))
        above = grasp.copy()
        above[:3, 3] += to_base[:3, :3] @ np.array([0.0, 0.0, 0.02])
        psm.servo_jaw(0.8)
        psm.move_cp(above, 0.4)
        psm.move_cp(grasp, 0.3)
        world.step(10)
        assert np.linalg.norm(psm.measured_cp()[:3, 3] - grasp[:3, 3]) < 1e-4
        sensed = {b.key for s in world.sensors if "psm1" in s.key for b in s.sensed}
        assert needle.key in sensed
        held = np.linalg.inv(psm.base_in_world() @ psm.measured_cp()) @ needle.world_matrix()
        assert psm.grasp(True) is needle
        world.step(10)
        psm.move_cp(above, 0.4)
        world.step(10)
        now = np.linalg.inv(psm.base_in_world() @ psm.measured_cp()) @ needle.world_matrix()
        assert needle.world_matrix()[2, 3] - start[2, 3] > 0.018
        assert np.linalg.norm(now[:3, 3] - held[:3, 3]) < 1e-3
        # released: the closed jaws, which lay in the wire, do not collide with it while they
        # still do (they threw it out as they opened: 9 N in the suture's hand-overs), only once off it
        import pybullet as pb

        links = [b for b in world.bodies if b.articulation is psm.art]
        psm.grasp(False)
        inside_steps = 0
        for _ in range(50):
            inside = any(  # a jaw 0.2 mm or more into the wire: lying in it, not touching it
                c[8] < -2e-4
                for b in links
                for c in pb.getClosestPoints(b.uid, needle.uid, 0.0, b.link, -1, physicsClientId=world.cid)
            )
            world.step(1)
            pushed = [f for _, o, f, _ in world.contacts_among(links) if o is needle and f > 0]
            inside_steps += inside
            assert not (inside and pushed), pushed
        assert inside_steps >= 1  # the jaws did lie in the wire as they let go
        assert needle.world_matrix()[2, 3] - start[2, 3] < 0.01
        assert world._parting == []  # apart: they collide again
        # closed jaws come down onto the wire, 1 mm past the grasp pose (which leaves them within a
        # tenth of a millimetre of the wire, either side of it, as the released needle settles)
        pressed = grasp.copy()
        pressed[:3, 3] -= to_base[:3, :3] @ np.array([0.0, 0.0, 0.001])
        psm.move_cp(pressed, 0.4)
        touched = 0.0
        for _ in range(50):
            world.step(1)
            touched = max([touched] + [f for _, o, f, _ in world.contacts_among(links) if o is needle])
        assert touched > 0.1
    finally:
        world.close()


def test_help_does_not_import_the_scene_builders():
    import subprocess
    import sys

    code = (
        "import sys; from adfkit.cli import build_parser; build_parser(); "
        "print(any(m.startswith('adfkit.scenes.') for m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert out.stdout.strip() == "False"


def test_needle_hulls_cover_the_needle():
    import trimesh

    from adfkit.geometry.decompose import load_hulls
    from adfkit.scenes.suturing.needle import HULLS_FILE, needle_mesh

    v, f = needle_mesh()
    mesh = trimesh.Trimesh(v, f, process=False)
    assert mesh.is_watertight and mesh.volume > 0
    hulls = load_hulls(HULLS_FILE)
    assert 4 <= len(hulls) <= 16 and all(h.is_watertight and h.volume > 0 for h in hulls)
    from scipy.spatial import ConvexHull

    inside = np.zeros(len(v), bool)
    for h in hulls:
        eq = ConvexHull(h.vertices).equations  # outward normals: inside is <= 0
        inside |= (v @ eq[:, :3].T + eq[:, 3]).max(axis=1) < 2e-5
    assert inside.all()
    assert sum(h.volume for h in hulls) < 1.6 * mesh.volume  # tight: no hull spans the arc's chord


@pytest.mark.slow
def test_committed_needle_hulls_are_coacds_output(tmp_path, monkeypatch):
    from adfkit.scenes.suturing.needle import HULLS_FILE, needle_hulls_text

    monkeypatch.setenv("ADFKIT_CACHE", str(tmp_path))
    assert needle_hulls_text(refresh=True)[0] == HULLS_FILE.read_text()


def test_needle_matches_the_challenge_needle():
    """Radius and arc of the corpus Needle.OBJ (a circle fitted to its vertices) are the layout's."""
    import math

    import trimesh
    from conftest import CORPUS, require_corpus

    require_corpus()
    v = trimesh.load(CORPUS / "src/ADF/Phantoms/Simple/high_res/Needle.OBJ", force="mesh").vertices
    a = np.c_[2 * v[:, 0], 2 * v[:, 1], np.ones(len(v))]
    cx, cy, c = np.linalg.lstsq(a, v[:, 0] ** 2 + v[:, 1] ** 2, rcond=None)[0]
    radius = math.sqrt(c + cx * cx + cy * cy)
    assert abs(radius - layout.NEEDLE_RADIUS) < 3e-4
    ang = np.sort(np.arctan2(v[:, 1] - cy, v[:, 0] - cx) % (2 * math.pi))
    gaps = np.diff(np.concatenate([ang, ang[:1] + 2 * math.pi]))
    arc = 2 * math.pi - gaps.max()  # the circle minus its largest empty gap
    assert abs(arc - layout.NEEDLE_ARC) < math.radians(10)
    wire = (np.hypot(v[:, 0] - cx, v[:, 1] - cy).max() - np.hypot(v[:, 0] - cx, v[:, 1] - cy).min()) / 2
    assert abs(wire - layout.NEEDLE_WIRE) < 1.5e-4


def test_the_needle_turns_through_every_pair_without_touching(built):
    """The needle set (kinematically) along its arc from entry k to exit k keeps clear of the
    phantom, the ridge and the holes' capsule boundaries (at least 0.3 mm, its collision's
    margin included)."""
    import math

    import pybullet as pb

    from adfkit.runner import open_world
    from adfkit.runner.rotations import matrix_to_pq
    from adfkit.scenes.suturing.frames import rot_z

    world = open_world(load_scene(built / "launch.yaml", None, []))
    try:
        needle = world.body("Needle")
        statics = [b for b in world.bodies if b.static]
        turn = 2 * (math.pi / 2 - layout.entry_angle())
        for k in range(1, 5):
            for s in np.linspace(-0.1, 1.1, 13):
                pose = layout.needle_at_entry(k) @ rot_z(-s * turn)
                pb.resetBasePositionAndOrientation(
                    needle.uid, *matrix_to_pq(pose @ needle.com_in_body), physicsClientId=world.cid
                )
                near = [
                    b.key
                    for b in statics
                    if pb.getClosestPoints(needle.uid, b.uid, 0.0003, -1, b.link, physicsClientId=world.cid)
                ]
                assert not near, (k, s, near)
    finally:
        world.close()


def test_demo_plays_the_bundled_suturing_scene_by_default(tmp_path, capsys):
    assert main(["demo", "--seconds", "0.1", "--out", str(tmp_path / "demo")]) == 0
    out = capsys.readouterr().out
    assert f"scene: {BUNDLED / 'launch.yaml'}" in out
    assert (tmp_path / "demo" / "cameraL_rgb.png").is_file() and (tmp_path / "demo" / "cameraR_rgb.png").is_file()


@pytest.mark.slow
def test_ten_seconds_of_play_stay_still(built):
    """Left alone for 10 s the scene stays where it was built: arms at home, needle flat on
    the slab, the thread lying on it with its pivots together."""
    from adfkit.runner import Options, open_world

    world = open_world(load_scene(built / "launch.yaml", None, []), Options(visuals=False))
    try:
        needle = world.body("Needle")
        start = needle.world_matrix()
        world.run(10.0)
        rep = world.report()
        assert not rep["nan"] and not rep["exploded"] and not rep["fell_through_floor"]
        assert rep["max_constraint_error_m"] < 1e-3
        now = needle.world_matrix()
        assert np.linalg.norm(now[:3, 3] - start[:3, 3]) < 1e-3 and now[2, 2] > np.cos(np.radians(2))
        for art in world.articulations:
            assert np.allclose(art.joint_values(), art.targets, atol=1e-4)
    finally:
        world.close()
