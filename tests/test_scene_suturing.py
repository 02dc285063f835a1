"""The project's own suturing scene (adfkit build-scene suturing): deterministic files, a
clean validation, the expected objects in the runner, PSMs that calibrate to the DH
kinematics and reach every hole from above, a stable short play, the bundled copy current."""
from __future__ import annotations

import filecmp
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
    from adfkit.runner.world import SimWorld
    w = SimWorld(load_scene(built / "launch.yaml", None, []))
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
    assert names == sorted([f"ghost{k}{i}" for k in ("Entry", "Exit") for i in range(1, 5)]
                           + ["left_finger_ghost", "right_finger_ghost"] * 2)
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
    for r in reach:   # jaws held along the shaft, which comes from above
        assert r.q[2] > 0.05


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
    assert np.allclose(psm.measured_jp(), q0, atol=1e-4)   # the arm holds its home pose
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
