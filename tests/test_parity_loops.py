"""Grippers and closed loops at rest, measured against AMBF itself (slow; each skips without an
AMBF build or the corpus): real AMBF, real PyBullet and MuJoCo, no mocks."""

from __future__ import annotations

from dataclasses import replace

import pytest
from conftest import CORPUS, require_corpus

from adfkit.adf import load_scene
from adfkit.parity import ambf

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)
MODELS = "ambf/ambf_models/descriptions/multi-bodies/"


def _largest_gaps(path, engines=("pybullet",), **kw) -> dict[str, float]:
    from adfkit.parity import session

    req = replace(session.Request(path, None, BUILD, seconds=1.0, every=0.02, engines=engines), **kw)
    return {c.adfkit.side: max(g.max_position for g in c.bodies) for c in session.run(req, progress=False).comparisons}


@pytest.mark.slow
@needs_ambf
def test_the_parallel_structure_swings_down_as_in_ambf(monkeypatch):
    """The corpus parallel structure, a four-bar hung from a static body whose loop AMBF closes
    by a continuous joint (l1-l4), swings down under gravity in AMBF until l3-l4 meets its
    -1.047 rad limit. adfkit closes the loop by the joint without limits (l3-l4's limit is then
    a tree joint's) and starts it closed and free: 8.8 mm from AMBF at most in PyBullet, 31 mm
    in MuJoCo (measured; 755 and 126 mm before), under 1.5 mm at the end. Control: the multibody
    held where it starts, as the runner held every looped one, stays while AMBF's swings."""
    from adfkit.runner.pybullet import assemble

    require_corpus()
    path = CORPUS / MODELS / "puzzles/parallel_structure.yaml"
    gaps = _largest_gaps(path, ("pybullet", "mujoco"))
    assert gaps["pybullet"] < 0.015 and gaps["mujoco"] < 0.05, gaps
    monkeypatch.setattr(assemble, "close_loops", lambda w: [a.drive() for a in w.articulations])
    assert _largest_gaps(path)["pybullet"] > 0.5


@pytest.mark.slow
@needs_ambf
def test_a_gripper_resting_on_the_floor_stays_as_in_ambf():
    """The corpus resistive gripper B (a free base, two jointed jaws whose tips a prismatic joint
    joins) dropped 1 mm onto the floor: within 3 mm of AMBF's in 1 s in both engines (measured
    2.7 mm PyBullet, 1.2 mm MuJoCo). Control: the links' shapes made in their centre-of-mass
    frames (Options.link_shapes "com"), which sat the jaws inside the base (49 mm)."""
    require_corpus()
    path = CORPUS / MODELS / "grippers/resistive/gripper1/gripperB.yaml"
    gaps = _largest_gaps(path, ("pybullet", "mujoco"))
    assert gaps["pybullet"] < 4e-3 and gaps["mujoco"] < 4e-3, gaps
    assert _largest_gaps(path, link_shapes="com")["pybullet"] > 0.02


@pytest.mark.slow
@needs_ambf
def test_gripper3_s_jaw_loop_keeps_what_its_file_leaves_open_in_mujoco(monkeypatch):
    """Corpus gripper 3: two jaws hinged on a base, their tips joined by a slider, the loop 0.37 mm
    open where the file places them, across its plane, where no joint of MuJoCo's tree can close
    it. MuJoCo's connect closing it keeps that opening: 7.98 mm from AMBF at most over 1 s
    (measured). Control: the connect held at the file's pivot (cross_joints.file_anchors without
    its same-tree exception), which twisted the jaws: 19.6 mm."""
    from adfkit.runner.mujoco import assemble

    require_corpus()
    path = CORPUS / MODELS / "grippers/resistive/gripper3/gripper.yaml"
    assert _largest_gaps(path, ("mujoco",))["mujoco"] < 0.010
    real = assemble.file_anchors

    def everywhere(m, loops):
        roots = m.body_rootid.copy()
        m.body_rootid[:] = range(m.nbody)  # every body a root of its own: no loop within one tree
        try:
            real(m, loops)
        finally:
            m.body_rootid[:] = roots

    monkeypatch.setattr(assemble, "file_anchors", everywhere)
    assert _largest_gaps(path, ("mujoco",))["mujoco"] > 0.015


def test_a_command_on_a_joint_closing_a_loop_is_a_located_error(tmp_path):
    """AMBF drives every hinge's motor; adfkit plays the joint that closes a loop as a
    constraint without one. A command file that drives it is a located error before anything is
    played (it raised a traceback from inside the player: the corpus ECM's and MTM's joint
    programs), and the programs `parity` writes leave such a joint out. In this four-bar, none of
    whose joints has limits, l3-l4 closes the loop. Control: the loop's tree joint l1-l2 is
    driven and is in the program."""
    from test_runner_links import four_bar

    from adfkit.diagnostics import AdfError
    from adfkit.parity import programs, session
    from adfkit.runner import Options, open_world

    path = tmp_path / "four_bar.yaml"
    path.write_text(four_bar())
    cmds = tmp_path / "cmds.txt"
    cmds.write_text("0.0, velocity, l1-l2, 0.1\n0.0, velocity, l3-l4, 0.1\n")
    nowhere = ambf.AmbfBuild(tmp_path / "no-ambf")  # never reached: the check comes first
    req = session.Request(path, None, nowhere, seconds=0.1, commands=cmds)
    with pytest.raises(AdfError) as e:
        session.run(req, progress=False)
    (d,) = e.value.diagnostics
    assert d.rule == "command-target" and "l3-l4" in d.message and "closes a kinematic loop" in d.message
    assert (d.location.line, d.location.column) == (2, 1)
    world = open_world(load_scene(path), Options(visuals=False, ground=False))
    try:
        names = [n.rsplit("/", 1)[-1] for n, _j, _k in programs.driven_joints(world)]
    finally:
        world.close()
    assert "l1-l2" in names and "l3-l4" not in names


def _program_gap(tmp_path, robot: str, kind: str, **kw) -> float:
    from adfkit.parity import programs

    require_corpus()
    path = CORPUS / MODELS / f"robots/{robot}.yaml"
    cmds = programs.write_program(path, None, kind, 1.0, tmp_path / f"{robot}_{kind}.txt")
    return _largest_gaps(path, commands=cmds, **kw)["pybullet"]


@pytest.mark.slow
@needs_ambf
def test_loop_robots_under_joint_programs_move_as_in_ambf(tmp_path, monkeypatch):
    """The corpus MTM (its arm a parallelogram closed by a hinge) and ECM (its pitch
    parallelogram closed by two hinges, its remote centre by a p2p joint to its base) under the
    velocity and position programs `parity` writes, 1 s in AMBF and PyBullet: the chain step
    solves the hinges and the point joint closing the loops with the tree's rows, as AMBF's
    solver does. Measured: MTM velocity 0.40 mm, position 1.41 mm; ECM velocity 2.00 mm without
    the floor, 8.1 mm on it (its yaw link meets the floor a little later than AMBF's: the last
    step's contact forces are the chain's pushes). Controls: the loops left out of the chain
    step, the MTM's position program 8.1 mm off; the contacts left out, the ECM on the floor
    20.8 mm."""
    from adfkit.runner.pybullet import chain

    assert _program_gap(tmp_path, "blender-mtm", "velocity") < 1e-3
    assert _program_gap(tmp_path, "blender-mtm", "position") < 2.5e-3
    assert _program_gap(tmp_path, "blender-ecm", "velocity", ground=False) < 2.5e-3
    assert _program_gap(tmp_path, "blender-ecm", "velocity") < 0.012
    with monkeypatch.context() as m:
        m.setattr(chain, "find_loops", lambda world, art: [])
        assert _program_gap(tmp_path, "blender-mtm", "position") > 6e-3
    monkeypatch.setattr(chain, "_contact_pushes", lambda uid, cid: [])
    assert _program_gap(tmp_path, "blender-ecm", "velocity") > 0.015


def test_a_joint_one_engine_cannot_drive_is_a_located_error_naming_it(tmp_path):
    """The corpus gripper3's jaws are joined by a slider; PyBullet closes that loop at the slider,
    MuJoCo at the revolute joint into the right jaw (a connect at a slider would lock the slide):
    with both engines, a command on that revolute joint, which PyBullet drives and MuJoCo plays as
    the loop's constraint, is an error at its line that names MuJoCo, before anything is played.
    Control: the left jaw's joint, which both drive, is not."""
    from adfkit.diagnostics import AdfError
    from adfkit.parity import session

    require_corpus()
    path = CORPUS / MODELS / "grippers/resistive/gripper3/gripper.yaml"
    cmds = tmp_path / "cmds.txt"
    cmds.write_text(
        "0.0, velocity, /ambf/env/gripper/LeftL1-LeftL2, 0.1\n0.0, velocity, /ambf/env/gripper/RightL1-RightL2, 0.1\n"
    )
    nowhere = ambf.AmbfBuild(tmp_path / "no-ambf")  # never reached: the check comes first
    req = session.Request(path, None, nowhere, seconds=0.1, commands=cmds, engines=("pybullet", "mujoco"))
    with pytest.raises(AdfError) as e:
        session.run(req, progress=False)
    (d,) = e.value.diagnostics
    assert d.rule == "command-target" and "RightL1-RightL2' in mujoco" in d.message
    assert (d.location.line, d.location.column) == (2, 1)


def test_both_engines_close_a_robots_loops_at_the_same_joints():
    """MuJoCo's tree is the PyBullet runner's (breadth first from the root): the corpus ECM's,
    PSM's and MTM's loops are closed at the same joints in both engines, so joint programs drive
    the same joints in each (MuJoCo's tree was depth first: the ECM's and PSM's parallelograms
    closed at the pitch back link instead). Control: the MJCF writer's own tree, depth first."""
    from adfkit.model.tree import build_tree
    from adfkit.runner import Options, open_world

    require_corpus()
    for robot, expected in (
        (
            "blender-ecm",
            {"base link-pitch end link", "pitch front link-pitch bottom link", "pitch top link-pitch end link"},
        ),
        (
            "blender-psm",
            {"pitch front link-pitch bottom link", "pitch top link-pitch end link", "yaw link-pitch end link"},
        ),
        ("blender-mtm", {"ArmFront-BottomArm"}),
    ):
        scene = load_scene(CORPUS / MODELS / f"robots/{robot}.yaml", None)
        for engine in ("pybullet", "mujoco"):
            w = open_world(scene, Options(visuals=False), engine=engine)
            try:
                assert {c[0].removeprefix("JOINT ") for c in w.constraints} == expected, (robot, engine)
            finally:
                w.close()
    ecm = load_scene(CORPUS / MODELS / "robots/blender-ecm.yaml", None).all_models()[0]
    assert "pitch back link-pitch bottom link" in {r[0].name for r in build_tree(ecm, slides_first=True).loops}


@pytest.mark.slow
@needs_ambf
def test_mujoco_moves_the_mtm_with_its_loop_as_ambf(tmp_path, monkeypatch):
    """MuJoCo closes the corpus MTM's parallelogram at the same hinge as PyBullet (a connect
    equality); the chain step solves that hinge with the arm's rows, its pivots where MuJoCo's
    connect holds the two links. On one floor (``--engine both``: PyBullet's, which AMBF gets
    too) the position program is 3.5 mm from AMBF in MuJoCo (PyBullet 2.5 mm), the velocity
    program 2.1 mm (1.3 mm). Control: the loop not read, the arm's rows settled instead, the
    position program 12.4 mm."""
    from adfkit.parity import programs
    from adfkit.runner.mujoco import chain

    require_corpus()
    path = CORPUS / MODELS / "robots/blender-mtm.yaml"

    def gaps(kind):
        cmds = programs.write_program(path, None, kind, 1.0, tmp_path / f"mtm_{kind}.txt")
        return _largest_gaps(path, ("pybullet", "mujoco"), commands=cmds)

    assert gaps("velocity")["mujoco"] < 3e-3
    position = gaps("position")
    assert position["mujoco"] < 5e-3 and position["pybullet"] < 3.5e-3, position
    monkeypatch.setattr(chain, "_loops", lambda world, bodies, index: None)
    assert gaps("position")["mujoco"] > 8e-3
