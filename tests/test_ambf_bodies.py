"""Bodies as AMBF's btRigidBodies (Options.bodies == "ambf", runner/ambf_bodies.py): AMBF's
estimated inertia for a body whose file gives none, and joints as fast as AMBF's bodies turn; and
the explicit joint controller AMBF plays (P·e + D·ė as an effort, once a 1 ms step), whose growth
the runner reproduces where D·dt/I is past 2."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pybullet")
import pybullet as pb  # noqa: E402
from conftest import CORPUS, SKIP_CORPUS  # noqa: E402

from adfkit.adf import load_scene  # noqa: E402
from adfkit.model.common import PID  # noqa: E402
from adfkit.model.pose import Pose, Vec3, rpy_to_quat  # noqa: E402
from adfkit.model.semantics import inertial_offset  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402
from adfkit.runner.ambf_bodies import box_inertia, estimated_inertia  # noqa: E402
from adfkit.runner.joint_commands import JointCommands  # noqa: E402
from adfkit.runner.rotations import pose_to_matrix  # noqa: E402

MESH_BODY = """\
bodies: [BODY post, BODY block]
joints: [JOINT post-block]
namespace: /ambf/env/
gravity: {{x: 0.0, y: 0.0, z: 0.0}}
BODY post:
  name: post
  mass: 0.0
  collision shape: BOX
  collision geometry: {{x: 0.05, y: 0.05, z: 0.05}}
  location: {{position: {{x: 0.0, y: 0.0, z: 0.5}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
BODY block:
  name: block
  mesh: block.stl
  mass: 2.0
  collision margin: {margin}
  location: {{position: {{x: 0.0, y: 0.0, z: 0.8}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
  inertial offset: {{position: {{x: 0.0, y: 0.0, z: 0.0}}, orientation: {{r: 0.0, p: 0.0, y: {yaw}}}}}
JOINT post-block:
  name: post-block
  parent: BODY post
  child: BODY block
  type: revolute
  parent pivot: {{x: 0.0, y: 0.0, z: 0.3}}
  parent axis: {{x: 0.0, y: 0.0, z: 1.0}}
  child pivot: {{x: 0.0, y: 0.0, z: 0.0}}
  child axis: {{x: 0.0, y: 0.0, z: 1.0}}
"""


def _block(tmp_path: Path, margin: float = 0.002, yaw: float = 0.0) -> Path:
    """A 2 kg 0.1 x 0.2 x 0.3 m box mesh (no `inertia`) on a revolute joint about z."""
    import trimesh

    trimesh.creation.box((0.1, 0.2, 0.3)).export(tmp_path / "block.stl")
    path = tmp_path / "block.yaml"
    path.write_text(MESH_BODY.format(margin=margin, yaw=yaw))
    return path


def _block_body(path: Path):
    scene = load_scene(path)
    (model,) = scene.all_models()
    return model, next(b for b in model.bodies if b.name == "block")


def test_a_mesh_bodys_inertia_is_the_box_of_its_bounds_grown_by_its_margin(tmp_path):
    # AMBF: each side 2 mm further out (the margin, once), mass/12·(ly² + lz², ...)
    model, body = _block_body(_block(tmp_path))
    expected = (2.0 / 12 * (0.204**2 + 0.304**2), 2.0 / 12 * (0.104**2 + 0.304**2), 2.0 / 12 * (0.104**2 + 0.204**2))
    assert estimated_inertia(model, body, np.eye(4)) == pytest.approx(expected, rel=1e-6)  # STL: float32
    assert box_inertia(2.0, (0.104, 0.204, 0.304)) == pytest.approx(expected, rel=1e-12)


#: this block's inertia in AMBF (the parity plugin's created record), by `collision mesh type`
AMBF_BLOCK = {
    "CONVEX_HULL": (0.03801866847467425, 0.030218668283939387, 0.019085333706855778),
    "CONVEX_MESH": (0.03801866847467425, 0.030218668283939387, 0.019085333706855778),
    "CONCAVE_MESH": (0.022336790488576626, 0.017204993019228808, 0.008736301415752244),
}


@pytest.mark.parametrize(
    "mesh_type, grow", [("CONVEX_HULL", 0.04 + 0.002), ("CONVEX_MESH", 0.04 + 0.002), ("CONCAVE_MESH", 0.002)]
)
def test_a_convex_shapes_bounds_keep_bullets_default_margin(tmp_path, mesh_type, grow):
    # AMBF's btConvexHullShape and btConvexTriangleMeshShape cache their bounds when made, with
    # Bullet's 0.04 m margin, and get the file's margin after: each side 42 mm further out; a
    # concave mesh's (GImpact) bounds hold the file's margin only
    model, body = _block_body(_block(tmp_path))
    body.collision_mesh_type = mesh_type
    lengths = np.array([0.1, 0.2, 0.3]) + 2 * grow
    assert estimated_inertia(model, body, np.eye(4)) == pytest.approx(box_inertia(2.0, lengths), rel=1e-6)
    # AMBF's GImpact bounds come 3e-4 short of the box grown by the margin (its own bounds' rounding)
    assert estimated_inertia(model, body, np.eye(4)) == pytest.approx(AMBF_BLOCK[mesh_type], rel=5e-4)


def test_the_corpus_needle_gets_the_inertia_ambf_gives_it():
    phantom = CORPUS / "src/ADF/Phantoms/Simple/phantom.yaml"
    if not phantom.is_file():
        pytest.skip(SKIP_CORPUS)
    (model,) = load_scene(phantom).all_models()
    needle = next(b for b in model.bodies if b.name == "Needle")  # nine hulls, 0.5 kg, no `inertia`
    com = pose_to_matrix(inertial_offset(needle))
    # measured in AMBF (the parity plugin's created record: btRigidBody::getLocalInertia)
    ambf = (6.140087690750581e-4, 6.649296550641597e-4, 7.29255000024469e-4)
    assert estimated_inertia(model, needle, com) == pytest.approx(ambf, rel=1e-6)


def test_a_turned_inertial_frame_turns_the_bounds(tmp_path):
    model, body = _block_body(_block(tmp_path, yaw=np.pi / 2))
    com = pose_to_matrix(Pose(Vec3(), rpy_to_quat(0.0, 0.0, np.pi / 2)))
    ix, iy, iz = estimated_inertia(model, body, com)
    plain = estimated_inertia(model, body, np.eye(4))
    assert (ix, iy, iz) == pytest.approx((plain[1], plain[0], plain[2]), rel=1e-9)


def test_a_given_inertia_or_no_mass_is_not_estimated(tmp_path):
    from adfkit.model.objects import Inertia

    model, body = _block_body(_block(tmp_path))
    body.inertia = Inertia(ix=1.0, iy=2.0, iz=3.0)
    assert estimated_inertia(model, body, np.eye(4)) is None
    body.inertia, body.mass = None, 0.0
    assert estimated_inertia(model, body, np.eye(4)) is None


def test_primitives_are_boxed_as_bullets_compound_boxes_them():
    from adfkit.model.common import Geometry
    from adfkit.model.objects import Body

    cylinder = Body(identifier="BODY c", name="c", mass=3.0, collision_shape="CYLINDER")
    cylinder.collision_geometry = Geometry(radius=0.05, height=0.4, axis="X")
    # its bounds 0.4 along x, 0.1 across: not the cylinder's own inertia (Bullet's box of the compound)
    assert estimated_inertia(None, cylinder, np.eye(4)) == pytest.approx(box_inertia(3.0, (0.4, 0.1, 0.1)))
    cone = Body(identifier="BODY k", name="k", mass=5.0, collision_margin=0.0001, collision_shape="CONE")
    cone.collision_geometry = Geometry(radius=0.01, height=0.02, axis="Z")
    # the corpus PSM's yaw link: AMBF's Bullet gives it 3.468e-4 kg m² about each axis (measured)
    assert estimated_inertia(None, cone, np.eye(4)) == pytest.approx((3.468e-4,) * 3, rel=1e-4)


@pytest.mark.parametrize("bodies", ["ambf", "pybullet"])
def test_the_runner_gives_a_link_ambfs_inertia_only_when_asked(tmp_path, bodies):
    path = _block(tmp_path)
    model, body = _block_body(path)
    w = open_world(load_scene(path), Options(visuals=False, ground=False, bodies=bodies))
    try:
        sb = next(sb for sb in w.bodies if sb.body.name == "block")
        got = pb.getDynamicsInfo(sb.uid, sb.link, physicsClientId=w.cid)[2]
        post = next(sb for sb in w.bodies if sb.body.name == "post")
        base_mass = pb.getDynamicsInfo(post.uid, -1, physicsClientId=w.cid)[0]
    finally:
        w.close()
    ambf = estimated_inertia(model, body, np.eye(4))
    assert base_mass == 0.0  # the static post keeps no mass (PyBullet moves a link's to the base
    # when its joint speed is given with them: they are given apart)
    if bodies == "ambf":
        assert got == pytest.approx(ambf, rel=1e-6)
    else:  # PyBullet's own estimate: its margin twice
        assert min(abs(g / a - 1) for g, a in zip(got, ambf)) > 0.01


def _arm(tmp_path, P: float, D: float, bodies: str):
    """The parity arm (a 0.5 kg bar on a revolute joint about z, 0.0237875 kg m² about it, limits
    ±2 rad) undamped, its joint under a `controller` P, D: an effort, as AMBF plays it."""
    from adfkit.model.common import VelocityDamping
    from adfkit.scenes.parity import write_parity

    scene = load_scene(write_parity(tmp_path), [1])
    for m in scene.all_models():
        for b in m.bodies:
            b.damping = VelocityDamping(linear=0.0, angular=0.0)
        for j in m.joints:
            j.controller = PID(P=P, I=0.0, D=D)
    return open_world(scene, Options(visuals=False, control_substeps=1, bodies=bodies))


ARM_JOINT = 0.0037875 + 0.5 * 0.2**2  # kg m²: the bar's own inertia about its centre + m·d²


def _play_position(w, target: float, steps: int) -> tuple[np.ndarray, np.ndarray]:
    commands = JointCommands(w)
    joint, _parent, child = next(r for r in w.joints_made if r[0].name == "base-arm")
    commands.command(joint, child, "position", target)
    dj = commands.joints[id(joint)]
    q, v = [], []
    for k in range(1, steps + 1):
        commands.apply(k * w.dt)  # as the parity player: the controller first runs 1 ms in
        w.step(1)
        s = w.joint_state(dj.art, [dj.index])
        q.append(float(s[0][0]))
        v.append(float(s[1][0]))
    return np.array(q), np.array(v)


def test_an_explicit_controller_grows_by_the_hand_computed_factor(tmp_path):
    """P·e + D·(e − e_prev)/dt applied once a step and integrated as Bullet does (v += τ·dt/I,
    q += v·dt) makes q_next = (2 − a − b)·q − (1 − b)·q_prev about the set-point, a = P·dt²/I,
    b = D·dt/I: with a = 1, b = 3 the roots are −1 ± √3, and the error grows 2.732 times a step,
    its sign flipping (the KUKA's link7 under P 2000, D 4: a = 1.9, b = 3.8, −4.4 a step).
    With AMBF's bodies the joint passes PyBullet's 100 rad/s cap, which held the KUKA still."""
    dt = 0.001
    a, b = 1.0, 3.0
    w = _arm(tmp_path, P=a * ARM_JOINT / dt**2, D=b * ARM_JOINT / dt, bodies="ambf")
    try:
        q, v = _play_position(w, 1e-6, 16)
    finally:
        w.close()
    growth = -1.0 - np.sqrt(3.0)
    assert max(np.roots([1, -(2 - a - b), 1 - b]), key=abs) == pytest.approx(growth)
    steps = np.diff(q)
    ratios = steps[5:10] / steps[4:9]
    assert ratios == pytest.approx([growth] * 5, rel=0.02)
    assert np.abs(v).max() > 300.0  # rad/s: past PyBullet's cap, within AMBF's π/4 a step (785 rad/s)


def test_pybullets_joint_cap_holds_the_ringing_joint(tmp_path):
    dt = 0.001
    w = _arm(tmp_path, P=ARM_JOINT / dt**2, D=3 * ARM_JOINT / dt, bodies="pybullet")
    try:
        _q, v = _play_position(w, 1e-6, 16)
    finally:
        w.close()
    assert np.abs(v).max() == pytest.approx(100.0, rel=1e-6)  # btMultiBody's maximum coordinate velocity


def test_an_explicit_controller_inside_its_bound_settles(tmp_path):
    """The control: a = 0.5, b = 1.5 (a + 2·b < 4): the roots ±0.707, the error dies away."""
    dt = 0.001
    w = _arm(tmp_path, P=0.5 * ARM_JOINT / dt**2, D=1.5 * ARM_JOINT / dt, bodies="ambf")
    try:
        q, _v = _play_position(w, 0.01, 200)
    finally:
        w.close()
    assert abs(q[-1] - 0.01) < 1e-6 and np.abs(q).max() < 0.05


@pytest.mark.parametrize("bodies", ["ambf", "pybullet"])
def test_mujoco_gives_a_body_ambfs_inertia_only_when_asked(tmp_path, bodies):
    """MuJoCo under AMBF's bodies: the block's inertia is AMBF's estimate, the box of its mesh's
    bounds grown by its 2 mm margin (mass/12·(0.204² + 0.304², ...)). Control: the MJCF writer's
    estimate, the bounds alone (0.2² + 0.3², ...). The corpus springy KUKA's link7, 1 kg: AMBF
    6.512e-4, 6.512e-4, 1.1206e-3 kg·m², MuJoCo 6.509e-4, 6.511e-4, 1.1204e-3 under AMBF's
    bodies, 6.13e-4, 6.13e-4, 1.066e-3 before."""
    import mujoco

    w = open_world(load_scene(_block(tmp_path)), Options(visuals=False, ground=False, bodies=bodies), engine="mujoco")
    try:
        got = w.model.body_inertia[mujoco.mj_name2id(w.model, mujoco.mjtObj.mjOBJ_BODY, "m0/block")]
    finally:
        w.close()
    grow = 0.004 if bodies == "ambf" else 0.0
    assert got == pytest.approx(box_inertia(2.0, (0.1 + grow, 0.2 + grow, 0.3 + grow)), rel=1e-5)


FROZEN_ARM = """\
bodies: [BODY post, BODY arm]
joints: [JOINT post-arm]
BODY post:
  name: post
  mass: 0.0
  collision shape: BOX
  collision geometry: {x: 0.02, y: 0.02, z: 0.02}
  location: {position: {x: 0.0, y: 0.0, z: 0.6}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY arm:
  name: arm
  mass: 0.2
  inertia: {ix: IX, iy: 0.0, iz: 0.0}
  collision shape: BOX
  collision geometry: {x: 0.2, y: 0.01, z: 0.01}
  location: {position: {x: 0.11, y: 0.0, z: 0.6}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
JOINT post-arm:
  name: post-arm
  parent: BODY post
  child: BODY arm
  type: revolute
  parent pivot: {x: 0.0, y: 0.0, z: 0.0}
  child pivot: {x: -0.11, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 1.0, z: 0.0}
  child axis: {x: 0.0, y: 1.0, z: 0.0}
"""


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_moment_of_inertia_of_zero_keeps_the_body_from_turning_as_in_ambf(tmp_path, engine):
    """Bullet inverts only the moments that are not 0: an arm whose `inertia` gives 0 about its
    hinge's axis (y) cannot turn about it, and hangs where its file puts it (AMBF 0.003 mm from
    adfkit's over 1.5 s, both engines); the engines turned it freely and it swung down 0.22 m."""
    path = tmp_path / "frozen.yaml"
    path.write_text(FROZEN_ARM.replace("IX", "1.0e-5"))
    w = open_world(load_scene(path), Options(visuals=False, ground=False, bodies="ambf"), engine=engine)
    try:
        w.run(1.0)
        assert abs(w.body("arm").world_matrix()[2, 3] - 0.6) < 1e-4
    finally:
        w.close()


def test_mujoco_plays_one_zero_moment_beside_two_others_and_says_so(tmp_path):
    # (0, 1e-3, 1e-3): frozen about x it is no inertia MuJoCo accepts (A + B >= C), and the MuJoCo
    # engine refused the whole scene ("inertia must satisfy A + B >= C"); it now plays the file's
    # moments, said with a located warning (AMBF's body turns NaN once a contact turns it)
    path = tmp_path / "one_zero.yaml"
    path.write_text(
        "bodies: [BODY a]\nBODY a:\n  name: a\n  mass: 1.0\n  inertia: {ix: 0, iy: 0.001, iz: 0.001}\n"
        "  collision shape: BOX\n  collision geometry: {x: 0.1, y: 0.1, z: 0.1}\n"
        "  location: {position: {x: 0, y: 0, z: 0.2}}\n"
    )
    w = open_world(load_scene(path), Options(visuals=False, ground=True, bodies="ambf"), engine="mujoco")
    try:
        said = [d for d in w.diagnostics if d.rule == "runner-inertia"]
        assert len(said) == 1 and said[0].location.line == 3
        w.run(0.3)
        assert np.isfinite(w.body("a").world_matrix()).all()
    finally:
        w.close()
