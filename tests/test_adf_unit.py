"""Unit tests of the spine: pose maths, joint frames, writer details, the sample scene."""

from __future__ import annotations

import math
import os
import random

import numpy as np
import pytest
import yaml

from adfkit.adf import dumps, load_scene, read_file, write_file
from adfkit.model import Body, Joint, ModelFile, Pose, Quat, Vec3, quat_to_rpy, rpy_to_quat
from adfkit.model.compare import differences
from adfkit.model.semantics import JointKind, ShapeKind, joint_frames, joint_kind, shape_kind
from adfkit.scenes import SuturingPadParams, build_suturing_pad, write_suturing_pad
from adfkit.summary import scene_summary


def _rpy_matrix(r, p, y):
    rx = np.array([[1, 0, 0], [0, math.cos(r), -math.sin(r)], [0, math.sin(r), math.cos(r)]])
    ry = np.array([[math.cos(p), 0, math.sin(p)], [0, 1, 0], [-math.sin(p), 0, math.cos(p)]])
    rz = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]])
    return rz @ ry @ rx


def test_rpy_is_fixed_axis_xyz():
    rng = random.Random(1)
    for _ in range(200):
        r, p, y = (rng.uniform(-math.pi, math.pi) for _ in range(3))
        q = rpy_to_quat(r, p, y)
        assert np.allclose(np.array(q.matrix()), _rpy_matrix(r, p, y), atol=1e-12)
        r2, p2, y2 = quat_to_rpy(q)
        assert np.allclose(_rpy_matrix(r2, p2, y2), _rpy_matrix(r, p, y), atol=1e-12)


def test_quat_to_rpy_at_gimbal_lock_keeps_the_rotation():
    for p in (math.pi / 2, -math.pi / 2):
        q = rpy_to_quat(0.3, p, -1.1)
        assert q.angle_to(rpy_to_quat(*quat_to_rpy(q))) < 1e-9


def test_pose_compose_and_inverse():
    a = Pose(Vec3(1, 2, 3), rpy_to_quat(0.1, 0.2, 0.3))
    b = Pose(Vec3(-1, 0.5, 0), rpy_to_quat(-0.4, 0.0, 1.0))
    ab = a * b
    assert np.allclose(ab.transform((0.1, 0.2, 0.3)), a.transform(b.transform((0.1, 0.2, 0.3))))
    ident = a * a.inverse()
    assert np.allclose(ident.position, (0, 0, 0), atol=1e-12) and ident.orientation.angle_to(Quat()) < 1e-9


def test_joint_frames_child_orientation_follows_section_8_2():
    # At zero the child's orientation relative to the parent is Rot(a, offset)·Rmin(b→a).
    j = Joint(
        type="revolute",
        parent_axis=Vec3(0, 0, 1),
        child_axis=Vec3(1, 0, 0),
        parent_pivot=Vec3(0.1, 0, 0),
        child_pivot=Vec3(0, 0.2, 0),
        offset=0.5,
    )
    fa, fb = joint_frames(j)
    rel = fa.orientation * fb.orientation.inverse()
    # Rmin(x→z) is +90° about -y; then 0.5 rad about z
    expected = Quat.from_axis_angle((0, 0, 1), 0.5) * Quat.from_axis_angle((0, -1, 0), math.pi / 2)
    assert rel.angle_to(expected) < 1e-12
    assert fa.position == Vec3(0.1, 0, 0) and fb.position == Vec3(0, 0.2, 0)
    # Prismatic joints use x as the reference axis: frame A maps x onto the parent axis.
    fa, _ = joint_frames(Joint(type="prismatic", parent_axis=Vec3(0, 1, 0), child_axis=Vec3(0, 1, 0)))
    assert np.allclose(fa.orientation.rotate((1, 0, 0)), (0, 1, 0), atol=1e-12)


def test_spelling_tables():
    assert joint_kind("continuous") is JointKind.REVOLUTE
    assert joint_kind("angular spring") is JointKind.TORSION_SPRING
    assert joint_kind("Revolute") is None  # matching is exact and case-sensitive
    assert shape_kind("BOX") is ShapeKind.BOX and shape_kind("bOx") is None


def test_pose_half_and_text_scalar_normalisations(tmp_path):
    f = tmp_path / "m.yaml"
    f.write_text(
        "bodies: [BODY a]\nBODY a:\n  name: 12\n  mass: '0.5'\n  location:\n    position: {x: 1, y: 2, z: 3}\n"
    )
    doc, diags = read_file(f)
    assert diags == []
    body = doc.bodies[0]
    assert body.name == "12" and body.mass == 0.5 and body.location == Pose(Vec3(1, 2, 3), Quat())
    written = yaml.safe_load(dumps(doc))["BODY a"]
    assert written["name"] == "12" and written["mass"] == 0.5
    assert written["location"] == {
        "position": {"x": 1.0, "y": 2.0, "z": 3.0},
        "orientation": {"r": 0.0, "p": 0.0, "y": 0.0},
    }


def test_angles_read_from_a_file_are_written_back_as_written(tmp_path):
    """A triple outside quat_to_rpy's ranges (pitch 2.41, as AMBF's add-on wrote the challenge's
    PSM) is the same rotation as a canonical one; written back, it is the triple of the file. A
    rotation changed since is written from the quaternion."""
    f = tmp_path / "m.yaml"
    f.write_text(
        "bodies: [BODY a]\nBODY a:\n  mass: 1\n  location:\n    position: {x: 0, y: 0, z: 0}\n"
        "    orientation: {r: 0.8426372409, p: 2.4132249355, y: 1.0389281511}\n"
    )
    doc, _ = read_file(f)
    q = doc.bodies[0].location.orientation
    canonical = quat_to_rpy(q)
    assert canonical[1] == pytest.approx(math.pi - 2.4132249355, abs=1e-9)  # the same rotation, another triple
    assert yaml.safe_load(dumps(doc))["BODY a"]["location"]["orientation"] == {
        "r": 0.8426372409,
        "p": 2.4132249355,
        "y": 1.0389281511,
    }
    turned = Pose(Vec3(), q * rpy_to_quat(0.0, 0.0, 0.1))
    doc.bodies[0].location = turned
    written = yaml.safe_load(dumps(doc))["BODY a"]["location"]["orientation"]
    assert written["p"] == pytest.approx(quat_to_rpy(turned.orientation)[1], abs=1e-10) and written["p"] < math.pi / 2


def test_unknown_keys_survive_a_round_trip(tmp_path):
    f = tmp_path / "m.yaml"
    f.write_text(
        "bodies: [BODY a]\ncontroller: &c {linear: {P: 1, D: 0}}\n"
        "BODY a:\n  mass: 1\n  my note: keep me\n  compound collision shape:\n"
        "  - {name: s, shape: Box, geometry: {x: 1, y: 1, z: 1}}\n"
    )
    doc, _ = read_file(f)
    assert doc.extras == {"controller": {"linear": {"P": 1, "D": 0}}}
    assert doc.bodies[0].extras == {"my note": "keep me"}
    assert doc.bodies[0].compound_collision_shape[0].extras == {"name": "s"}
    again = yaml.safe_load(dumps(doc))
    assert again["BODY a"]["my note"] == "keep me" and again["controller"]["linear"]["P"] == 1


def test_atomic_write_keeps_the_old_file_on_failure(tmp_path, monkeypatch):
    target = tmp_path / "m.yaml"
    target.write_text("old content\n")
    doc = ModelFile(bodies=[Body(identifier="BODY a", mass=1.0)])

    def boom(*a, **k):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", boom)
    with pytest.raises(OSError):
        write_file(doc, target)
    assert target.read_text() == "old content\n"
    assert [p.name for p in tmp_path.iterdir()] == ["m.yaml"]  # no temp file left behind


def test_atomic_write_gives_new_files_the_umask_mode_and_keeps_an_existing_mode(tmp_path):
    doc = ModelFile(bodies=[Body(identifier="BODY a", mass=1.0)])
    old = os.umask(0o022)
    try:
        write_file(doc, tmp_path / "new.yaml")
        assert (tmp_path / "new.yaml").stat().st_mode & 0o777 == 0o644  # not mkstemp's private 0600
        kept = tmp_path / "kept.yaml"
        kept.write_text("x\n")
        kept.chmod(0o640)
        write_file(doc, kept)
        assert kept.stat().st_mode & 0o777 == 0o640
    finally:
        os.umask(old)


def test_suturing_pad_scene_round_trips_and_counts(tmp_path):
    p = SuturingPadParams(thread_elements=40)
    launch = write_suturing_pad(tmp_path, p)
    scene = load_scene(launch, [0])
    s = scene_summary(scene)
    assert s["totals"]["bodies"] == 1 + 2 * 4 + 1 + 40
    assert s["totals"]["joints"] == 8 + 1 + 39
    assert s["totals"]["ghost objects"] == 8
    assert scene.world.cameras[0].identifier == "cameraL" and len(scene.world.cameras) == 2
    pad = scene.models[0]
    assert differences(pad, build_suturing_pad(p), tol=1e-12, quat_tol=1e-9) == []
    kinds = {j.type for j in pad.joints}
    assert kinds == {"fixed", "six dof spring"}


def test_bundled_sample_scene_is_current(tmp_path):
    """sample_scenes/ is generated: regenerating it gives the same files byte for byte."""
    from pathlib import Path

    bundled = Path(__file__).resolve().parent.parent / "sample_scenes" / "suturing_pad"
    write_suturing_pad(tmp_path)
    for f in sorted(tmp_path.iterdir()):
        assert (bundled / f.name).read_text() == f.read_text(), (
            f"regenerate with: adfkit build-scene suturing-pad {bundled}"
        )
