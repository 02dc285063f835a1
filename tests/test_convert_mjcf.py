"""ADF ⇄ MJCF, checked in real MuJoCo: every converted file compiles; kinematics, masses and
world inertias agree at random configurations; round trips; exact losses; bad input."""

from __future__ import annotations

import random
from pathlib import Path

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco", reason="mujoco (sim extra) is not installed")

from conftest import CORPUS  # noqa: E402
from convert_checks import assert_located_error, assert_same_kinematics, close_pose, convert_cli, expected_losses  # noqa: E402

from adfkit.adf.reader import load  # noqa: E402
from adfkit.converters import mjcf, read, write  # noqa: E402
from adfkit.converters.inertia import world_tensor  # noqa: E402
from adfkit.converters.losses import loss_keys  # noqa: E402
from adfkit.model.pose import Pose, Quat, Vec3  # noqa: E402
from adfkit.model.semantics import inertial_offset, snapped_axis_tilt  # noqa: E402
from adfkit.model.tree import build_tree  # noqa: E402

ROBOTS = CORPUS / "ambf" / "ambf_models" / "descriptions" / "multi-bodies" / "robots"
needs_corpus = pytest.mark.skipif(not CORPUS.is_dir(), reason="../shared/corpus is absent (public ADF corpus)")
TOL = 1e-6
HINGE, SLIDE = int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)
FAST_SUITE = ["acrobot.xml", "cartpole.xml"]
SLOW_SUITE = [
    "reacher.xml",
    "finger.xml",
    "walker.xml",
    "pendulum.xml",
    "humanoid.xml",
    "manipulator.xml",
    "hopper.xml",
    "swimmer.xml",
    "fish.xml",
    "ball_in_cup.xml",
    "point_mass.xml",
    "quadruped.xml",
    "stacker.xml",
    "humanoid_CMU.xml",
    "dog.xml",
]


def _suite() -> Path:
    dm = pytest.importorskip("dm_control", reason="dm_control (test extra) ships the MJCF models used here")
    return Path(dm.__file__).parent / "suite"


def _compile(path: Path):
    m = mujoco.MjModel.from_xml_path(str(path))
    return m, mujoco.MjData(m)


def _hinges_and_slides(m) -> dict[str, int]:
    return {m.joint(j).name: j for j in range(m.njnt) if int(m.jnt_type[j]) in (HINGE, SLIDE) and m.joint(j).name}


def _random_value(m, j, rng) -> float:
    if m.jnt_limited[j]:
        return rng.uniform(*m.jnt_range[j])
    return rng.uniform(-np.pi, np.pi)


def _pose(pos, quat) -> Pose:
    return Pose(Vec3(*map(float, pos)), Quat(float(quat[1]), float(quat[2]), float(quat[3]), float(quat[0])))


def _state(m, d, values: dict[str, float]) -> dict:
    """What a joint configuration gives: per body COM, world inertia, mass; per joint anchor and axis."""
    d.qpos[:] = m.qpos0
    for name, v in values.items():
        d.qpos[m.jnt_qposadr[m.joint(name).id]] = v
    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    mujoco.mj_camlight(m, d)
    out = {"body": {}, "joint": {}, "camera": {}, "light": {}}
    for c in range(m.ncam):  # fixed cameras and lights: where they are, where they look, their optics
        if m.cam_mode[c] == 0:
            out["camera"][m.camera(c).name] = (
                d.cam_xpos[c].copy(),
                d.cam_xmat[c].copy(),
                np.array([m.cam_fovy[c], *m.cam_resolution[c], m.cam_projection[c]], dtype=float),
            )
    for i in range(m.nlight):
        if m.light_mode[i] == 0:
            out["light"][m.light(i).name] = (
                d.light_xpos[i].copy(),
                d.light_xdir[i].copy(),
                np.array(
                    [m.light_cutoff[i], m.light_exponent[i], *m.light_attenuation[i], m.light_castshadow[i]],
                    dtype=float,
                ),
            )
    for b in range(1, m.nbody):
        r = d.ximat[b].reshape(3, 3)
        out["body"][m.body(b).name] = (d.xipos[b].copy(), r @ np.diag(m.body_inertia[b]) @ r.T, float(m.body_mass[b]))
    for name in _hinges_and_slides(m):
        j = m.joint(name).id
        out["joint"][name] = (
            d.xanchor[j].copy(),
            d.xaxis[j].copy(),
            int(m.jnt_type[j]),
            tuple(m.jnt_range[j]) if m.jnt_limited[j] else None,
        )
    return out


def _compare(a: dict, b: dict, skip_bodies=(), tilt=0.0, reach=0.0):
    reach_tol = TOL + tilt * reach  # what a snapped tilt of the axes moves over the model's reach
    for name, (com, inertia, mass) in a["body"].items():
        if name in skip_bodies:
            continue
        com2, inertia2, mass2 = b["body"][name]
        assert np.linalg.norm(com - com2) < reach_tol, name
        assert mass2 == pytest.approx(mass, rel=TOL, abs=1e-12), name
        # 1e-6 of its size (a tilt turns it: by 2·tilt of its size at most)
        assert np.abs(inertia - inertia2).max() <= max((TOL + 2 * tilt) * np.abs(inertia).max(), 1e-12), name
    for kind in ("camera", "light"):
        for name, (pos, frame, optics) in a[kind].items():
            pos2, frame2, optics2 = b[kind][name]
            assert np.linalg.norm(pos - pos2) < TOL and np.abs(frame - frame2).max() < TOL, name
            assert np.allclose(optics, optics2, rtol=1e-6, atol=1e-9), name
    assert set(a["joint"]) == set(b["joint"])
    for name, (anchor, axis, jtype, rng) in a["joint"].items():
        anchor2, axis2, jtype2, rng2 = b["joint"][name]
        assert jtype2 == jtype and rng2 == pytest.approx(rng) if rng else rng2 is None, name
        assert np.linalg.norm(axis - axis2) < TOL + tilt, name
        if jtype == HINGE:
            assert np.linalg.norm(anchor - anchor2) < reach_tol, name


def _mjcf_round_trip(src: Path, tmp_path, configs: int):
    model, losses = read(src)
    adf = tmp_path / (src.stem + ".yaml")
    write(model, adf)
    back, _ = read(adf)
    out = tmp_path / (src.stem + "_back.xml")
    written = write(back, out)
    ma, da = _compile(src)
    mb, db = _compile(out)
    # welded to the world (static in ADF), or below the writer's mass/inertia floor: reported apart
    welded = {l.element.removeprefix("BODY ") for l in losses + written if l.feature == "mass"}
    joints = _hinges_and_slides(ma)
    # a joint whose axes AMBF's shortest arcs snap (in the bodies' inertial frames) is reported and
    # tilts what hangs from it by at most that angle: positions then agree to the tilts times the reach
    tilt = _reported_tilt(model, losses)
    mujoco.mj_kinematics(ma, da)
    reach = 2.0 * float(np.abs(da.xpos).max()) + 1.0
    rng = random.Random(11)
    for _ in range(configs):
        values = {n: _random_value(ma, j, rng) for n, j in joints.items()}
        _compare(_state(ma, da, values), _state(mb, db, values), skip_bodies=welded, tilt=tilt, reach=reach)
    return losses


def _reported_tilt(model, losses) -> float:
    """The snapped tilts of the joints the reader reported as "axis tilt", summed (rad)."""
    bodies = {b.identifier: b for b in model.bodies}
    tilted = {l.element for l in losses if l.feature == "axis tilt"}
    return sum(
        snapped_axis_tilt(j, bodies.get(j.parent), bodies.get(j.child)) for j in model.joints if j.identifier in tilted
    )


@pytest.mark.parametrize("name", FAST_SUITE)
def test_dm_control_model_round_trip_through_adf(name, tmp_path):
    losses = _mjcf_round_trip(_suite() / name, tmp_path, configs=100)
    features = {l.feature for l in losses}
    assert "actuator" in features and not features & {"camera", "light"}  # cameras and lights are carried


@pytest.mark.slow
@pytest.mark.parametrize("name", SLOW_SUITE)
def test_dm_control_model_round_trip_through_adf_more(name, tmp_path):
    # several joints on one body come back as chains: every source body and joint matches
    _mjcf_round_trip(_suite() / name, tmp_path, configs=100)


def test_several_joints_on_one_body_become_a_chain(tmp_path):
    """cheetah's torso slides along x and z and turns about y, all on one body: ADF gets two
    added bodies between the world and the torso, and every body and joint of the source
    matches the written MJCF at 100 random configurations."""
    losses = _mjcf_round_trip(_suite() / "cheetah.xml", tmp_path, configs=100)
    chained = [l for l in losses if l.feature == "joints"]
    assert [(l.element, l.reason) for l in chained] == [
        (
            "BODY torso",
            "3 joints on one body; ADF joins two bodies by one joint: built as a chain through "
            "torso_rootx, torso_rootz (1 % of the body's mass and inertia each)",
        )
    ]
    model, _ = read(_suite() / "cheetah.xml")
    by_name = {b.name: b for b in model.bodies}
    torso, rootx, rootz = by_name["torso"], by_name["torso_rootx"], by_name["torso_rootz"]
    assert rootx.mass == rootz.mass == pytest.approx(0.01 * torso.mass)
    assert not rootx.collision_shape and not rootx.compound_collision_shape
    chain = [(j.parent, j.child, j.type) for j in model.joints if "root" in j.name]
    assert chain == [
        ("BODY world", "BODY torso_rootx", "prismatic"),
        ("BODY torso_rootx", "BODY torso_rootz", "prismatic"),
        ("BODY torso_rootz", "BODY torso", "revolute"),
    ]


def test_cartpole_read_losses_are_exact():
    _m, losses = read(_suite() / "cartpole.xml")
    assert loss_keys(losses) == [
        ("BODY world", "collision plane"),
        ("CAMERA lookatcart", "camera mode"),
        ("slide", "actuator"),
    ]


# --- ADF -> MJCF against the ADF model's own kinematics ----------------------------------------


def _adf_to_mjcf(name: str, tmp_path, configs: int):
    src = ROBOTS / name
    model = load(src)
    out = tmp_path / (src.stem + ".xml")
    losses = write(model, out)
    m, d = _compile(out)
    tree = build_tree(model)
    links = {lk.body.name: lk for lk in tree.ordered()}
    joints = _hinges_and_slides(m)
    assert len(joints) == sum(
        1 for lk in tree.ordered() if lk.joint is not None and lk.kind.value in ("revolute", "prismatic")
    )
    rng = random.Random(5)
    by_joint = {lk.joint.name: lk for lk in tree.ordered() if lk.joint is not None}
    for _ in range(configs):
        values = {n: _random_value(m, j, rng) for n, j in joints.items()}
        d.qpos[:] = m.qpos0
        for n, v in values.items():
            d.qpos[m.jnt_qposadr[joints[n]]] = v
        mujoco.mj_kinematics(m, d)
        expected = tree.fk({by_joint[n].joint.identifier: v for n, v in values.items()})
        for b in range(1, m.nbody):
            lk = links[m.body(b).name]
            body_world = _pose(d.xpos[b], d.xquat[b]) * lk.frame_in_body.inverse()
            assert close_pose(body_world, expected[lk.body.identifier], TOL), (name, lk.body.identifier)
            if (lk.body.mass or 0) > 0:  # a static body has no inertial to place
                com = (expected[lk.body.identifier] * inertial_offset(lk.body)).position
                assert np.linalg.norm(d.xipos[b] - np.asarray(com)) < TOL
    d.qpos[:] = m.qpos0
    mujoco.mj_kinematics(m, d)
    for b in range(1, m.nbody):
        body = links[m.body(b).name].body
        if body.inertia is not None and (body.mass or 0) > 0:
            assert m.body_mass[b] == pytest.approx(body.mass, rel=TOL)
            r = d.ximat[b].reshape(3, 3)
            got = r @ np.diag(m.body_inertia[b]) @ r.T
            want = world_tensor(
                (body.inertia.ix, body.inertia.iy, body.inertia.iz), (body.location * inertial_offset(body)).orientation
            )
            assert np.allclose(got, want, rtol=1e-6, atol=1e-9), body.identifier
    # qpos0 reproduces the file's locations (to the file's rounding)
    for b in range(1, m.nbody):
        body = links[m.body(b).name].body
        at = _pose(d.xpos[b], d.xquat[b]) * links[body.name].frame_in_body.inverse()
        assert (at.position - body.location.position).norm() < 2e-3, body.identifier
    return model, losses


@needs_corpus
def test_kuka_to_mjcf_matches_adf_kinematics(tmp_path):
    _adf_to_mjcf("blender-kuka.yaml", tmp_path, configs=100)


@needs_corpus
@pytest.mark.slow
@pytest.mark.parametrize("name", ["blender-psm.yaml", "blender-ecm.yaml", "blender-mtm.yaml"])
def test_corpus_robot_to_mjcf_matches_adf_kinematics(name, tmp_path):
    _adf_to_mjcf(name, tmp_path, configs=100)


@needs_corpus
def test_kuka_adf_mjcf_adf_round_trip_and_exact_losses(tmp_path):
    orig = load(ROBOTS / "blender-kuka.yaml")
    out = tmp_path / "kuka.xml"
    losses = write(orig, out)
    expected = expected_losses(orig, ("collision groups", "collision margin", "damping", "friction"), ("controller",))
    # MuJoCo collides with hulls; links 1-5, moving concave meshes filling 70-76 % of their hulls,
    # with their convex parts (geometry.concave), as the runner's engines do
    parts = {f"BODY link{n}" for n in range(1, 6)}
    expected += [
        (b.identifier, "concave collision mesh" if b.identifier in parts else "collision mesh")
        for b in orig.bodies
        if b.mesh
    ]
    assert loss_keys(losses) == sorted(expected)
    assert len(losses) == 54
    back, read_losses = read(out)
    # a link collided as parts is several mesh geoms, of which ADF keeps one (said)
    assert loss_keys(read_losses) == sorted((b, "collision mesh") for b in parts)
    assert_same_kinematics(orig, back, set())


@needs_corpus
def test_psm_adf_mjcf_adf_round_trip_and_exact_losses(tmp_path):
    orig = load(ROBOTS / "blender-psm.yaml")
    out = tmp_path / "psm.xml"
    losses = write(orig, out)
    _compile(out)
    keys = loss_keys(losses)
    structural = [k for k in keys if k[1] in ("joint", "joint axis", "body")]
    assert structural == sorted(
        [
            ("JOINT pitch back link-pitch bottom link", "joint axis"),  # loop: equality/connect
            ("JOINT pitch top link-pitch end link", "joint axis"),  # loop: equality/connect
        ]
    )
    # loop joints, the p2p included, are kept as equality constraints
    xml = out.read_text()
    assert xml.count("<connect ") == 3
    per_body = {
        "collision groups",
        "collision margin",
        "damping",
        "friction",
        "passive",
        "inertia",
        "collision mesh",
        "concave collision mesh",
        "mass",
        "restitution",
    }
    assert {k[1] for k in keys} <= per_body | {"controller", "max motor impulse", "joint axis"}
    # every mesh collides as its hull or, a moving link's concave mesh, as its convex parts
    meshes = {k[0] for k in keys if k[1] in ("collision mesh", "concave collision mesh")}
    assert meshes == {
        b.identifier for b in orig.bodies if b.mesh and not b.collision_shape and not b.compound_collision_shape
    }
    parts = {k[0] for k in keys if k[1] == "concave collision mesh"}
    assert parts and all(orig.body(b).mass for b in parts)
    back, read_losses = read(out)
    # the file's own sub-mrad tilts between joint axes, which AMBF ignores, are reported, and
    # each link played as parts keeps one of its mesh geoms
    assert {k for k in loss_keys(read_losses) if k[1] != "axis tilt"} == {(b, "collision mesh") for b in parts}
    lost = {
        "JOINT pitch back link-pitch bottom link",
        "JOINT pitch top link-pitch end link",
        "JOINT yaw link-pitch end link",
    }
    # target_fk/target_ik float (free joints) and come back as free bodies: compare them too
    assert_same_kinematics(orig, back, lost)


# --- bad input and the command line ------------------------------------------------------------

BAD = {
    "entity bomb": ('<?xml version="1.0"?>\n<!DOCTYPE m [<!ENTITY a "aaaa">]>\n<mujoco/>\n', "xml-unsafe", 2),
    "not xml": ("<mujoco>\n  <worldbody>\n</mujoco>\n", "xml-syntax", 3),
    "compile error": (
        '<mujoco>\n  <worldbody>\n    <body name="a">\n      <geom type="box" size="1 1"/>\n'
        '      <joint type="hinge" bogus="1"/>\n    </body>\n  </worldbody>\n</mujoco>\n',
        "mjcf-compile",
        5,
    ),
    "wrong root": ('<robot name="r"/>\n', "mjcf-root", 1),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_mjcf_is_a_located_diagnostic(case, tmp_path):
    text, rule, line = BAD[case]
    assert_located_error(mjcf.read, tmp_path / "bad.xml", text, rule, line)


@needs_corpus
def test_convert_command_adf_to_mjcf(tmp_path):
    res = convert_cli(ROBOTS / "blender-kuka.yaml", tmp_path / "kuka.xml", "--json")
    assert res.returncode == 0, res.stderr
    assert '"to": "mjcf"' in res.stdout
    _compile(tmp_path / "kuka.xml")
    assert convert_cli(ROBOTS / "blender-kuka.yaml", tmp_path / "k2.xml", "--fail-on-loss").returncode == 1
    bad = tmp_path / "bad.xml"
    bad.write_text(BAD["compile error"][0])
    res = convert_cli(bad, tmp_path / "bad.yaml")
    assert res.returncode == 2 and "mjcf-compile" in res.stderr
