"""A jointed body's turned `inertial offset`, as AMBF reads it: afJoint turns the joint's axes
and pivots into the bodies' inertial frames and builds its frames there (the shortest arc from
the reference axis taken in the inertial frame), so a turned inertial frame turns the joint's
zero about its axis. The runner (both engines), the validator and the converters follow it.

Measured in AMBF 2.0 on the bundled scene's former PSM files (links' inertial frames turned by
minus the joint offset about z): base-yaw read -pi/2 (yaw link turned -pi/2), yaw-pitch back
-pi (parent -pi/2, child +pi/2), tool roll-pitch +pi/2, the jaws 0.4 -/+ pi/2; the needle's
fixed joint to the thread (needle turned 112.5 degrees) held the thread turned -112.5 degrees."""

from __future__ import annotations

import math

import pytest

from adfkit.diagnostics import Severity
from adfkit.model import Body, Inertia, Joint, ModelFile, Pose, Quat, Vec3
from adfkit.model.semantics import body_joint_frames, inertial_joint_twist, joint_frames, snapped_axis_tilt
from adfkit.model.tree import build_tree

Z = Vec3(0.0, 0.0, 1.0)


def _turn(angle: float, axis=Z) -> Pose:
    return Pose(Vec3(0.01, 0.0, 0.0), Quat.from_axis_angle(axis, angle))


def _pair(parent_turn: Pose | None, child_turn: Pose | None, kind="revolute", mass=0.5):
    """Two bodies on a joint about z through the child's origin, placed at body-frame value 0."""
    p = Body(identifier="BODY p", name="p", mass=mass, location=Pose(), inertia=Inertia(ix=1e-3, iy=2e-3, iz=3e-3))
    c = Body(
        identifier="BODY c",
        name="c",
        mass=mass,
        location=Pose(Vec3(0.2, 0.0, 0.0)),
        inertia=Inertia(ix=1e-3, iy=2e-3, iz=3e-3),
    )
    p.inertial_offset, c.inertial_offset = parent_turn, child_turn
    j = Joint(
        identifier="JOINT p-c",
        name="p-c",
        parent="BODY p",
        child="BODY c",
        type=kind,
        parent_pivot=Vec3(0.2, 0.0, 0.0),
        parent_axis=Z,
        child_pivot=Vec3(),
        child_axis=Z,
    )
    return ModelFile(namespace="/ambf/env/t/", bodies=[p, c], joints=[j]), p, c, j


def _ambf_value(model) -> float:
    (link,) = [lk for lk in build_tree(model).ordered() if lk.joint is not None]
    return link.q0


@pytest.mark.parametrize(
    "parent, child, value",
    [
        (0.0, -math.pi / 2, -math.pi / 2),  # the former PSM's base-yaw, read so by AMBF
        (-math.pi / 2, math.pi / 2, math.pi),  # yaw-pitch back: AMBF read -pi
        (0.0, math.pi / 2, math.pi / 2),  # tool roll-pitch
        (0.0, 0.0, 0.0),
    ],
)
def test_a_turned_inertial_frame_turns_the_joints_zero_as_in_ambf(parent, child, value):
    m, p, c, j = _pair(_turn(parent), _turn(child))
    twist = inertial_joint_twist(j, p, c)
    assert math.remainder(twist - value, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)
    assert math.remainder(_ambf_value(m) - value, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)
    # frames in the body frames still coincide where AMBF's value puts the child, and turn only
    # about the axis: the axis itself is unchanged
    a, b = body_joint_frames(j, p, c)
    assert (a.orientation.rotate(Z) - Z).norm() < 1e-12 and (b.orientation.rotate(Z) - Z).norm() < 1e-12
    # the inertial offset's position alone changes nothing
    m2, p2, c2, j2 = _pair(Pose(Vec3(0.0, 0.05, 0.0)), Pose(Vec3(0.0, 0.0, 0.03)))
    assert inertial_joint_twist(j2, p2, c2) == 0.0 and _ambf_value(m2) == pytest.approx(0.0, abs=1e-12)


def test_an_inertial_offset_without_mass_is_ignored_as_ambf_ignores_it():
    m, p, c, j = _pair(None, _turn(1.0), mass=None)
    assert inertial_joint_twist(j, p, c) == 0.0
    assert body_joint_frames(j, p, c) == joint_frames(j)


def test_the_child_offset_takes_the_twist_back():
    m, p, c, j = _pair(None, _turn(0.7))
    assert _ambf_value(m) == pytest.approx(0.7)
    j.offset = inertial_joint_twist(j, p, c)
    assert _ambf_value(m) == pytest.approx(0.0, abs=1e-12)


def _written(tmp_path, model) -> str:
    from adfkit.adf.writer import dumps

    path = tmp_path / "turned.yaml"
    path.write_text(dumps(model))
    return str(path)


def test_the_validator_says_where_ambf_turns_a_joint(tmp_path):
    from adfkit.validator import validate_file

    m, p, c, j = _pair(None, _turn(-math.pi / 2))
    res = validate_file(_written(tmp_path, m))
    found = [d for d in res.diagnostics if d.rule == "inertial-frame-turns-joint"]
    assert len(found) == 1, [str(d) for d in res.diagnostics]
    d = found[0]
    assert "'JOINT p-c'" in d.message and "'BODY c'" in d.message and "-90.0°" in d.message
    # a revolute joint's turned zero is a note (adfkit reads it as AMBF does); `joint-pose`
    # warns where the file's pose then reads outside the limits
    assert d.severity == Severity.INFO
    assert d.hint and "unturned" in d.hint
    text = (tmp_path / "turned.yaml").read_text().splitlines()
    # located at the child's inertial offset
    above = text[: d.location.line]
    assert "inertial offset" in "".join(above[-2:]) and "BODY c:" in "\n".join(above)
    # negative controls: unturned, or turned but without a mass (AMBF ignores it), or a p2p joint
    for model in (_pair(_turn(0.0), _turn(0.0))[0], _pair(None, _turn(1.0), mass=None)[0]):
        res = validate_file(_written(tmp_path, model))
        assert not [d for d in res.diagnostics if d.rule == "inertial-frame-turns-joint"]
    res = validate_file(_written(tmp_path, _pair(None, _turn(1.0), kind="p2p")[0]))
    assert not [d for d in res.diagnostics if d.rule == "inertial-frame-turns-joint"]


def test_a_fixed_joint_holds_its_child_turned(tmp_path):
    from adfkit.validator import validate_file

    m, p, c, j = _pair(_turn(math.radians(112.5)), None, kind="fixed")
    assert math.degrees(inertial_joint_twist(j, p, c)) == pytest.approx(-112.5)
    found = [d for d in validate_file(_written(tmp_path, m)).diagnostics if d.rule == "inertial-frame-turns-joint"]
    assert len(found) == 1 and "holds the child turned -112.5°" in found[0].message
    assert found[0].severity == Severity.WARNING
    assert "112.5° from where the file places it" in found[0].message
    # an `offset` that takes the turn back: AMBF holds the child where the file places it
    j.offset = inertial_joint_twist(j, p, c)
    found = [d for d in validate_file(_written(tmp_path, m)).diagnostics if d.rule == "inertial-frame-turns-joint"]
    assert found == []


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_the_runner_reads_the_joint_as_ambf_does(engine, tmp_path):
    pytest.importorskip(engine)
    from adfkit.adf import load_scene
    from adfkit.parity.traces import AdfkitPlayer
    from adfkit.runner import Options, open_world

    m, p, c, j = _pair(None, _turn(-math.pi / 2))
    m.gravity = Vec3(0.0, 0.0, 0.0)
    c.location = Pose(Vec3(0.2, 0.0, 0.0))
    path = _written(tmp_path, m)
    w = open_world(load_scene(path), Options(visuals=False, ground=False), engine=engine)
    try:
        tr = AdfkitPlayer(w).play(0.04, 0.02)
    finally:
        w.close()
    (k,) = [i for i, n in enumerate(tr.joint_names) if n.endswith("p-c")]
    assert tr.joints[0, k] == pytest.approx(-math.pi / 2, abs=1e-6)
    # and the child starts where the file puts it (the multibody's links start on their joints)
    (ci,) = [i for i, n in enumerate(tr.body_names) if n.endswith("/c")]
    assert tr.poses[0, ci, :3] == pytest.approx([0.2, 0.0, 0.0], abs=1e-6)


def test_converters_carry_ambfs_reading(tmp_path):
    """A URDF link whose inertial frame is turned: the ADF keeps the inertia's frame and its
    joint's offset takes AMBF's twist back, so AMBF reads the joint as the URDF does."""
    from adfkit.converters import read

    urdf = tmp_path / "turned.urdf"
    urdf.write_text(
        """<robot name="t">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0.1 0 0" rpy="0 0 0.9"/><mass value="0.5"/>
    <inertia ixx="1e-4" iyy="3e-3" izz="3e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.5"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="0" velocity="0"/></joint>
</robot>
"""
    )
    model, _losses = read(urdf)
    (j,) = model.joints
    arm = model.body(j.child)
    # the inertial frame is kept turned, so AMBF turns the joint: the offset takes it back
    assert inertial_joint_twist(j, model.body(j.parent), arm) == pytest.approx(0.9)
    assert j.offset == pytest.approx(0.9)
    assert _ambf_value(model) == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("kind", ["revolute", "prismatic", "fixed"])
def test_offsets_for_body_frames_make_ambf_build_the_body_frames(kind):
    import random
    from dataclasses import replace

    from adfkit.model.semantics import offsets_for_body_frames

    rng = random.Random(7)

    def turn():
        axis = Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1))
        return Pose(Vec3(0.01, 0.0, 0.0), Quat.from_axis_angle(axis, rng.uniform(-3.0, 3.0)))

    for _ in range(50):
        m, p, c, j = _pair(turn(), turn(), kind=kind)
        j.parent_axis = Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1))
        j.child_axis = Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1))
        j.joint_offset, j.offset = rng.uniform(-3, 3), rng.uniform(-3, 3)
        jo, off = offsets_for_body_frames(j, p, c)
        a0, b0 = joint_frames(j)
        a1, b1 = body_joint_frames(replace(j, joint_offset=jo, offset=off), p, c)
        assert a1.orientation.angle_to(a0.orientation) < 1e-9 and b1.orientation.angle_to(b0.orientation) < 1e-9
        # negative control: the same offsets unchanged leave AMBF's frames turned
        a2, b2 = body_joint_frames(j, p, c)
        assert max(a2.orientation.angle_to(a0.orientation), b2.orientation.angle_to(b0.orientation)) > 1e-6


def test_the_bundled_scene_reads_in_ambf_as_its_builder_placed_it():
    """The builder keeps the PSM links' and the needle's inertial frames turned (PyBullet's
    link frames on them) and writes the joints' offsets for AMBF's reading: AMBF reads the
    arms at their home values at the files' poses and holds the thread where it lies."""
    from pathlib import Path

    from adfkit.adf.reader import load
    from adfkit.validator.semantic import _held_off

    root = Path(__file__).resolve().parent.parent / "sample_scenes" / "suturing"
    psm = load(root / "psm" / "psm1.yaml")
    values = {lk.joint.identifier: lk.q0 for lk in build_tree(psm).ordered() if lk.joint is not None}
    assert any(inertial_joint_twist(j, psm.body(j.parent), psm.body(j.child)) != 0.0 for j in psm.joints)
    assert values["JOINT base link-yaw link"] == pytest.approx(0.0, abs=1e-9)
    assert values["JOINT yaw link-pitch back link"] == pytest.approx(0.0, abs=1e-9)
    assert values["JOINT tool roll link-tool pitch link"] == pytest.approx(0.0, abs=1e-9)
    assert values["JOINT pitch end link-main insertion link"] == pytest.approx(0.1, abs=1e-9)
    assert values["JOINT tool yaw link-tool gripper1 link"] == pytest.approx(0.4, abs=1e-9)
    phantom = load(root / "phantom" / "phantom.yaml")
    (j,) = [j for j in phantom.joints if j.identifier == "JOINT Needle-Thread"]
    assert _held_off(j, phantom.body(j.parent), phantom.body(j.child)) < 1e-6


def test_a_slightly_turned_inertial_frame_tilts_the_joint_by_the_arc_ambf_snaps():
    """AMBF's shortest arcs are the identity below 1e-3 rad, and it takes them in the bodies'
    inertial frames: a child's inertial frame tilted 2e-4 rad off the joint's axis makes an arc
    AMBF drops, so the child hangs that much tilted (what the URDF and MJCF readers report as an
    "axis tilt"). Controls: turned about the axis itself (a twist the offset takes back), tilted
    past 1e-3 rad (an arc AMBF keeps) and no inertial frame: nothing snapped."""
    x = Vec3(1.0, 0.0, 0.0)
    for turn, tilt in (
        (_turn(2e-4, x), 2e-4),
        (_turn(0.3), 0.0),
        (_turn(0.01, x), 0.0),
        (None, 0.0),
    ):
        _, p, c, j = _pair(None, turn)
        assert snapped_axis_tilt(j, p, c) == pytest.approx(tilt, rel=1e-6, abs=1e-15)
