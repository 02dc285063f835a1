"""Torsion springs as AMBF builds them (afJoint::createFromAttribs): a btGeneric6DofSpring2Constraint
with five axes locked and its z axis limited to the joint's limits, its spring and damper about z;
without limits all six axes are locked. The PyBullet runner plays a limited one as a revolute joint of
the multibody with the spring as a torque, MuJoCo as a hinge with stiffness; one closing a loop is a
point constraint at its pivot in MuJoCo (it was left out)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from test_runner import _model

from adfkit.runner import Options, open_world

MASS, REACH, K, C = 0.1, 0.1, 0.3, 0.05  # kg, m (the rod's centre of mass from the pivot), N·m/rad, N·m·s/rad


def _pendulum(limits: str) -> str:
    """A rod on a torsion spring about y, level at the spring's equilibrium (0): gravity turns it
    down (+ about y) until the spring holds its weight."""
    return (
        "bodies: [BODY mount, BODY rod]\njoints: [JOINT mount-rod]\n"
        "BODY mount:\n  name: mount\n  mass: 0.0\n"
        "  location: {position: {x: 0.0, y: 0.0, z: 1.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}\n"
        f"BODY rod:\n  name: rod\n  mass: {MASS}\n  inertia: {{ix: 1.0e-6, iy: 1.0e-6, iz: 1.0e-6}}\n"
        "  collision shape: SPHERE\n  collision geometry: {radius: 0.005}\n"
        f"  location: {{position: {{x: {REACH}, y: 0.0, z: 1.0}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}\n"
        "JOINT mount-rod:\n  name: mount-rod\n  parent: BODY mount\n  child: BODY rod\n  type: torsion spring\n"
        f"  parent pivot: {{x: 0.0, y: 0.0, z: 0.0}}\n  child pivot: {{x: {-REACH}, y: 0.0, z: 0.0}}\n"
        "  parent axis: {x: 0.0, y: 1.0, z: 0.0}\n  child axis: {x: 0.0, y: 1.0, z: 0.0}\n"
        f"  stiffness: {K}\n  damping: {C}\n  equilibrium point: 0.0\n{limits}"
    )


def _settled(tmp_path, limits: str, engine: str, springs: str) -> tuple[float, float, float]:
    """(the rod's turn about the axis, its largest turn off the axis, its pivot's distance from
    the mount's) after 1.5 s."""
    world = open_world(
        _model(tmp_path, _pendulum(limits)), Options(visuals=False, ground=False, springs=springs), engine=engine
    )
    try:
        world.run(1.5)
        m = world.body("BODY rod").world_matrix()
        turn = math.atan2(-m[2, 0], m[0, 0])
        off = max(abs(math.asin(max(-1.0, min(1.0, m[2, 1])))), abs(math.atan2(m[1, 0], m[0, 0])))
        pivot = m[:3, :3] @ np.array([-REACH, 0.0, 0.0]) + m[:3, 3]
        return turn, off, float(np.linalg.norm(pivot - [0.0, 0.0, 1.0]))
    finally:
        world.close()


#: PyBullet with AMBF's springs (Options.springs "ambf", adfkit run's and parity's); the implicit form
#: (the suture's) damps over the control step and holds a load short of its balance by (1 + (c·dt +
#: k·dt²)/I): 0.367 rad here
CASES = [("pybullet", "ambf"), ("mujoco", "ambf")]


@pytest.mark.parametrize("engine, springs", CASES)
def test_a_limited_torsion_spring_holds_its_rod_where_the_spring_takes_its_weight(tmp_path, engine, springs):
    """Settled, the spring's torque K·θ carries the rod's weight m·g·L·cos θ: θ = 0.311 rad, solved
    by hand. The joint is exact: no turn off its axis, the pivot where the mount's is (the runner
    locked the other axes with torques before, and they gave)."""
    g = 9.81
    theta = brentq(lambda t: K * t - MASS * g * REACH * math.cos(t), 0.0, 1.0)
    turn, off, gap = _settled(tmp_path, "  joint limits: {low: -1.0, high: 1.0}\n", engine, springs)
    assert turn == pytest.approx(theta, abs=0.01)
    assert off < 1e-4 and gap < 1e-4, (off, gap)


@pytest.mark.parametrize("engine, springs", CASES)
def test_a_torsion_springs_limit_stops_it_short_of_its_balance(tmp_path, engine, springs):
    """The balance (0.311 rad) past the upper limit (0.2 rad): the rod rests on the limit, the
    limit read as the joint's own (AMBF gives Bullet's constraint [-high, -low], whose angle is
    the negative of the joint's). Control: with no limits at all AMBF locks every axis, the
    spring's too, and the rod stays level."""
    turn, _, _ = _settled(tmp_path, "  joint limits: {low: -0.2, high: 0.2}\n", engine, springs)
    assert turn == pytest.approx(0.2, abs=0.01)
    (tmp_path / "locked").mkdir()
    turn, _, _ = _settled(tmp_path / "locked", "", engine, springs)
    assert abs(turn) < 0.01


def _four_bar_with_a_torsion_spring(tmp_path, joint: str):
    """test_runner_links' four-bar, l2-l3, l3-l4 and l1-l4 limited, ``joint`` a torsion spring."""
    from test_runner_links import four_bar

    from adfkit.adf import load_scene

    lim = "  joint limits: {low: -0.5, high: 0.5}\n"
    plain = four_bar(limits=lim, last_limits=lim)
    cut = plain.index(f"JOINT {joint}:\n")
    text = plain[:cut] + plain[cut:].replace("type: revolute", "type: torsion spring", 1)
    assert text.count("type: torsion spring") == 1
    path = tmp_path / "four_bar.yaml"
    path.write_text(text)
    return load_scene(path)


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_torsion_spring_closing_a_loop_holds_the_loop(tmp_path, engine):
    """The four-bar's joints all limited, l3-l4 a torsion spring: the tree takes l1-l4, met first,
    and the spring closes the loop. The sides swing down and the bottom bar stays level, as a
    parallelogram's does (MuJoCo left a torsion spring closing a loop out, with its runner-loop
    warning, and the open chain folded: the bar turned)."""
    scene = _four_bar_with_a_torsion_spring(tmp_path, "l3-l4")
    world = open_world(scene, Options(visuals=False, ground=False), engine=engine)
    try:
        assert not [d for d in world.diagnostics if d.rule == "runner-loop"]
        assert {n for n, *_ in world.constraints} - {"JOINT world-l1"} == {"JOINT l3-l4"}
        l3 = world.body("BODY l3")
        z0 = l3.com_position()[2]
        world.run(0.1)
        assert l3.com_position()[2] < z0 - 0.015  # the sides swung down
        assert abs(l3.world_matrix()[2, 0]) < 5e-3  # the bottom bar level
    finally:
        world.close()


def test_mujocos_floor_under_a_model_played_alone_is_1_mm_under_its_lowest_corner(tmp_path):
    """The floor under a model played alone is 1 mm under its lowest point: a turned tetrahedron's
    lowest corner, computed by hand. MuJoCo's took the lowest corner of the mesh's bounding box in
    its principal frame turned into the world: 39 mm lower here, and 2.5 cm lower than PyBullet's
    under the corpus springy MTM, whose arm then fell further in MuJoCo than in AMBF (which gets
    PyBullet's floor)."""
    from scipy.spatial.transform import Rotation

    verts = np.array([[0.05, 0.05, 0.05], [-0.05, -0.05, 0.05], [-0.05, 0.05, -0.05], [0.05, -0.05, -0.05]])
    (tmp_path / "tet.obj").write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in verts) + "f 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n"
    )
    rpy = (2.5, 0.4, 0.0)
    model = (
        "bodies: [BODY tet]\njoints: []\nhigh resolution path: ./\nlow resolution path: ./\n"
        "BODY tet:\n  name: tet\n  mass: 0.1\n  mesh: tet.obj\n"
        f"  location: {{position: {{x: 0.0, y: 0.0, z: 1.0}}, orientation: {{r: {rpy[0]}, p: {rpy[1]}, y: {rpy[2]}}}}}\n"
    )
    lowest = 1.0 + float(np.min(Rotation.from_euler("xyz", rpy).apply(verts)[:, 2]))  # AMBF's rpy: extrinsic x, y, z
    world = open_world(_model(tmp_path, model), Options(visuals=False), engine="mujoco")
    try:
        assert world.ground_z == pytest.approx(lowest - 1e-3, abs=1e-6)
    finally:
        world.close()


def _at_rest(name: str, engine: str, rel: str = "robots/blender-{}.yaml") -> float:
    """The largest position gap (m) of the corpus robot ``name`` (a file under the corpus's
    multi-bodies, ``rel``) from AMBF's over 1 s at rest."""
    from conftest import CORPUS, require_corpus

    from adfkit.parity import ambf, session

    require_corpus()
    build, why = ambf.available()
    if build is None:
        pytest.skip(why)
    model = CORPUS / "ambf/ambf_models/descriptions/multi-bodies" / rel.format(name)
    req = session.Request(model, None, build, seconds=1.0, every=0.02, engines=(engine,), springs="ambf")
    (c,) = session.run(req, progress=False).comparisons
    return max(g.max_position for g in c.bodies)


@pytest.mark.slow
def test_the_springy_kuka_folds_under_gravity_as_in_ambf(monkeypatch):
    """The corpus springy KUKA: seven torsion springs without stiffness (their limits alone) fold
    under gravity, its links up to 0.75 m from where they start in 1 s in AMBF, two joints onto
    their limits (120°). Measured 4.7 mm from AMBF at most (PyBullet, AMBF's spring limit rows
    played). Control: its springs as the joints between free bodies PyBullet played them as before
    (a point constraint, the other axes held by torques), which let link5-link6 through its limit:
    137 mm."""
    from adfkit.runner.pybullet import articulation

    assert _at_rest("kuka-springy", "pybullet") < 15e-3
    springs = (articulation.JointKind.TORSION_SPRING, articulation.JointKind.LINEAR_SPRING)
    was = articulation.tree_kind
    monkeypatch.setattr(articulation, "tree_kind", lambda r: None if r[1] in springs else was(r))
    assert _at_rest("kuka-springy", "pybullet") > 0.1


@pytest.mark.slow
def test_the_springy_ecms_loops_are_closed_by_its_joints_without_limits(monkeypatch):
    """The corpus springy ECM's pitch parallelogram has continuous joints and limited torsion
    springs into the same links: the continuous ones close its loops (their constraints play no
    limits) and the springs keep theirs in the tree. Measured 31.4 mm from AMBF at most (PyBullet;
    its arm falls onto its pitch limits). Control: springs not counted as limited joints, the
    tree took the joint it met first and a spring closed a loop without its limits: 59 mm."""
    from adfkit.model import tree

    assert _at_rest("ecm-springy", "pybullet") < 45e-3
    monkeypatch.setattr(tree, "LIMITED_KINDS", tree.ONE_DOF)
    assert _at_rest("ecm-springy", "pybullet") > 50e-3


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_loop_is_closed_by_its_joint_without_limits_not_by_a_limited_spring(tmp_path, engine):
    """The four-bar with l3-l4 a limited torsion spring and l1-l4 without limits: l1-l4 closes
    the loop, as a constraint, which plays no limits, and the spring's limits are the tree
    joint's (the rule counted only revolute and prismatic joints as limited: the tree took l1-l4,
    met first, and the spring closed the loop without its limits)."""
    from test_runner_links import four_bar

    from adfkit.adf import load_scene

    lim = "  joint limits: {low: -0.5, high: 0.5}\n"
    plain = four_bar(limits=lim)
    text = plain.replace("child: BODY l4\n  type: revolute", "child: BODY l4\n  type: torsion spring", 1)
    assert text != plain and "type: torsion spring" in text.split("JOINT l3-l4:")[1].split("JOINT l1-l4:")[0]
    path = tmp_path / "four_bar.yaml"
    path.write_text(text)
    world = open_world(load_scene(path), Options(visuals=False, ground=False), engine=engine)
    try:
        assert {n for n, *_ in world.constraints} - {"JOINT world-l1"} == {"JOINT l1-l4"}
    finally:
        world.close()


@pytest.mark.slow
def test_the_springy_psm_falls_onto_its_pitch_limits_in_mujoco_as_in_ambf(monkeypatch):
    """The corpus springy PSM's tool shaft lands on the floor at once (its tool roll link's mesh
    reaches 187 mm below the wrist); AMBF's arm pitches over it 47° onto its limits, the shaft
    sliding on the floor (Bullet's friction: 0.5 × 0.5). MuJoCo under AMBF's bodies gives the
    floor's pairs that product: measured 208 mm from AMBF at most (the fall trails AMBF's by
    about 0.1 s). Control: MuJoCo's own friction rule, the lower of the two (0.5): the shaft
    sticks, the pitch stops at 7°: 356 mm."""
    from adfkit.runner.mujoco import assemble

    assert _at_rest("psm-springy", "mujoco") < 0.25
    monkeypatch.setattr(assemble, "ground_pairs", lambda *a: None)
    assert _at_rest("psm-springy", "mujoco") > 0.3


@pytest.mark.slow
def test_gripper3s_jaws_slide_in_mujoco_as_in_ambf(monkeypatch):
    """The corpus gripper3 starts its fingers 0.12 rad past their limits; AMBF's hinge limit
    rows kick them in, the slider between its jaws slides 117 mm and the gripper slides over
    the floor. MuJoCo (its tree keeping the slider, AMBF's limit rows): measured 11.2 mm from
    AMBF at most. Control: the slider closing the loop as a point (locked), 60.5 mm."""
    from adfkit.converters import mjcf_write
    from adfkit.model.tree import build_tree

    rel = "grippers/resistive/gripper3/{}.yaml"
    assert _at_rest("gripper", "mujoco", rel) < 0.02
    monkeypatch.setattr(
        mjcf_write, "build_tree", lambda m, kinds=None, _s=False, _bf=False, **_kw: build_tree(m, kinds)
    )
    assert _at_rest("gripper", "mujoco", rel) > 0.05


@pytest.mark.slow
def test_the_springy_kuka_folds_in_mujoco_as_in_ambf(monkeypatch):
    """The corpus springy KUKA in MuJoCo under AMBF's bodies: its links' inertia AMBF's estimate
    (their meshes' bounds grown by the collision margin; the file gives none) and its limits
    AMBF's rows: measured 6.7 mm from AMBF at most. Control: the MJCF writer's inertia (the
    bounds alone, 6 % less on link7): its joints fold 3-4 % ahead of AMBF's, 11.2 mm."""
    from adfkit.runner.mujoco import build

    assert _at_rest("kuka-springy", "mujoco") < 9e-3
    monkeypatch.setattr(build, "ambf_inertia", lambda *a: None)
    assert _at_rest("kuka-springy", "mujoco") > 10e-3
