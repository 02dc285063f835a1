"""AMBF's limit rows on spring and prismatic joints of the PyBullet runner's multibodies
(runner/pybullet/limit_rows.py). A limited torsion spring is AMBF's btGeneric6DofSpring2Constraint,
whose limit rows are there whenever low < high: a joint moves toward a limit at a gap g at most
erp·g/dt, not at all where it would cross it within the step, and is driven back at erp·|g|/dt
from past it (erp the joint's, 0.1). A prismatic joint is AMBF's btSliderConstraint, whose row
drives a joint past its limit back at the world's erp (0.2)·depth/dt. PyBullet's own limit stops a
joint on a limit it reaches and leaves one that starts past it where it is. The slow tests measure
both rows with AMBF."""

from __future__ import annotations

import pytest

from adfkit.adf import load_scene
from adfkit.runner import Options, open_world

#: the parity arm (write_parity): its mass, its centre of mass from the joint, its inertia about the joint
MASS, REACH = 0.5, 0.2
ARM_JOINT = 0.0037875 + MASS * REACH**2
#: (joint type, axis): about y, gravity turns the level arm + ; along the level x axis, gravity across it
SPRING = ("torsion spring", "{x: 0.0, y: 1.0, z: 0.0}")
SLIDER = ("prismatic", "{x: 1.0, y: 0.0, z: 0.0}")
LIMITS = "{low: -0.2, high: 0.2}"


def _arm_as(tmp_path, kind: str, axis: str, limits: str = LIMITS, at_x: float = 0.2):
    """The parity scene's arm (write_parity) with its joint made a ``kind`` about or along ``axis``
    with ``limits``, the arm's centre at ``at_x`` (0.2: the joint at 0)."""
    from adfkit.scenes.parity import write_parity

    write_parity(tmp_path)
    text = (tmp_path / "arm.yaml").read_text()
    for old, new in (
        ("type: revolute", f"type: {kind}"),
        ("parent axis: {x: 0.0, y: 0.0, z: 1.0}", f"parent axis: {axis}"),
        ("child axis: {x: 0.0, y: 0.0, z: 1.0}", f"child axis: {axis}"),
        ("joint limits: {low: -2.0, high: 2.0}", f"joint limits: {limits}"),
        ("position: {x: 0.2, y: 0.0, z: 0.5}", f"position: {{x: {at_x}, y: 0.0, z: 0.5}}"),
    ):
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / f"arm_{kind.replace(' ', '_')}.yaml"
    path.write_text(text)
    return path


def _world(tmp_path, joint, springs: str = "ambf"):
    world = open_world(
        load_scene(_arm_as(tmp_path, *joint)),
        Options(visuals=False, ground=False, springs=springs, control_substeps=1),
    )
    (_j, _parent, child) = world.joints_made[0]
    return world, child.articulation, child.link


def _after_a_step(tmp_path, joint, q0: float, v0: float, springs: str = "ambf") -> tuple[float, float]:
    """The joint's (position, velocity) one 1 ms step after it was put at ``q0`` moving at ``v0``."""
    world, art, index = _world(tmp_path, joint, springs)
    try:
        world.reset_joints(art, [index], [q0], [v0])
        world.step(1)
        q, v = world.joint_state(art, [index])
        return float(q[0]), float(v[0])
    finally:
        world.close()


def test_a_spring_nearing_its_limit_is_slowed_to_erp_times_the_gap(tmp_path):
    """0.05 rad from its upper limit at 10 rad/s (0.01 rad a step: not crossing it): the rows let
    it on at 0.1·0.05/1 ms = 5 rad/s. Control: the implicit springs (no rows), it goes on at
    10 rad/s and a little more (gravity: m·g·L·cos θ/I·dt = 0.04 rad/s in the step)."""
    _q, v = _after_a_step(tmp_path, SPRING, 0.15, 10.0)
    assert v == pytest.approx(5.0, rel=1e-3)
    (tmp_path / "control").mkdir()
    _q, v = _after_a_step(tmp_path / "control", SPRING, 0.15, 10.0, springs="implicit")
    assert v == pytest.approx(10.0 + MASS * 9.81 * REACH * 0.989 / ARM_JOINT * 1e-3, abs=2e-3)


def test_a_spring_that_would_cross_its_limit_within_the_step_stops_short_of_it(tmp_path):
    """5 mrad from the limit at 10 rad/s (10 mrad a step): the rows stop it where it is. Control:
    PyBullet's own limit lets it through, 5 mrad past the limit after the step (measured 0.2051 rad)."""
    q, v = _after_a_step(tmp_path, SPRING, 0.195, 10.0)
    assert q == pytest.approx(0.195, abs=1e-5) and v == pytest.approx(0.0, abs=1e-3)
    (tmp_path / "control").mkdir()
    q, _v = _after_a_step(tmp_path / "control", SPRING, 0.195, 10.0, springs="implicit")
    assert q == pytest.approx(0.205, abs=1e-3)


def test_a_spring_falling_onto_its_limit_is_slowed_onto_it(tmp_path):
    """Released level, the arm falls (+) onto its upper limit (0.2 rad) at ~0.5 rad/s: the rows
    slow it from ten steps' travel out (its gap shrinking by 1 - erp a step) and it never goes
    past the limit by more than one step of gravity that the rows did not see (the row reads the
    velocity at the step's start, Bullet's after gravity: m·g·L·cos θ/I·dt² = 0.040 mrad).
    Control: PyBullet's own limit (the implicit springs, no rows) lets it 3.3 mrad through
    (measured 0.20331 rad) and brings it back."""
    tops = []
    for springs in ("ambf", "implicit"):
        (tmp_path / springs).mkdir()
        world, art, index = _world(tmp_path / springs, SPRING, springs)
        try:
            top = 0.0
            for _ in range(500):
                world.step(1)
                top = max(top, float(world.joint_state(art, [index])[0][0]))
            end = float(world.joint_state(art, [index])[0][0])
        finally:
            world.close()
        tops.append(top)
        assert end == pytest.approx(0.2, abs=1e-6)
    rows, plain = tops
    assert rows - 0.2 == pytest.approx(MASS * 9.81 * REACH * 0.980 / ARM_JOINT * 1e-6, rel=0.05)
    assert plain - 0.2 > 3e-3


@pytest.mark.parametrize("joint, back", [(SPRING, 0.1 * 0.1 / 1e-3), (SLIDER, 0.2 * 0.1 / 1e-3)])
def test_a_joint_starting_past_its_limit_is_driven_back_by_its_row(tmp_path, joint, back):
    """0.1 (rad, m) past the upper limit at rest: the spring's rows drive it back at its erp (0.1)
    ·0.1/dt = 10 rad/s, the slider's at the world's (0.2): 20 m/s. Control: without AMBF's
    springs a spring has no rows and PyBullet's limit leaves it where it started."""
    q, v = _after_a_step(tmp_path, joint, 0.3, 0.0)
    assert v == pytest.approx(-back, rel=1e-3)
    if joint is SPRING:
        (tmp_path / "control").mkdir()
        q, v = _after_a_step(tmp_path / "control", joint, 0.3, 0.0, springs="implicit")
        assert q == pytest.approx(0.3, abs=1e-3) and abs(v) < 0.2


def test_a_slider_inside_its_limits_is_left_alone(tmp_path):
    """Control for the slider's row: 0.1 m inside its upper limit at rest, gravity across its
    axis, it stays put (the row is there only past a limit)."""
    q, v = _after_a_step(tmp_path, SLIDER, 0.1, 0.0)
    assert q == pytest.approx(0.1, abs=1e-6) and v == pytest.approx(0.0, abs=1e-6)


def _ambf_gap(path, seconds: float, springs: str = "ambf") -> float:
    from adfkit.parity import ambf, session

    build, why = ambf.available()
    if build is None:
        pytest.skip(why)
    req = session.Request(path, None, build, seconds=seconds, every=0.004, springs=springs, ground=False)
    (c,) = session.run(req, progress=False).comparisons
    return max(g.max_position for g in c.bodies)


@pytest.mark.slow
def test_the_arm_on_a_torsion_spring_falls_onto_its_limit_as_in_ambf(tmp_path):
    """The parity arm on a torsion spring about y without stiffness, released level, falls onto
    its 0.2 rad limit. In AMBF it is slowed onto it (0.1893, 0.1989, 0.1997 rad at 0.10, 0.12,
    0.13 s; adfkit's rows 0.1889, 0.1986, 0.1995): measured 0.42 mm from AMBF at most. Control:
    PyBullet's own limit (the implicit springs, no rows) lets it 3.3 mrad through and back: 2.7 mm."""
    path = _arm_as(tmp_path, "torsion spring", "{x: 0.0, y: 1.0, z: 0.0}", "{low: -0.2, high: 0.2}")
    assert _ambf_gap(path, 0.5) < 1e-3
    assert _ambf_gap(path, 0.5, springs="implicit") > 2e-3


@pytest.mark.slow
def test_a_prismatic_joint_past_its_limit_is_driven_back_as_in_ambf(tmp_path, monkeypatch):
    """The parity arm on a prismatic joint along x, started 0.05 m past its upper limit (0.05):
    AMBF's slider drives it back at 0.2·0.05/1 ms = 10 m/s (0.09, 0.08, 0.07 m on its first
    steps, the rows' to 10 nm with 1 ms control steps) and it bounces between its limits:
    measured 4.6 mm from AMBF at most over 0.2 s at adfkit's 4 ms control step. Control: without
    the slider's row PyBullet leaves it where it started: 160 mm."""
    from adfkit.runner.pybullet import limit_rows

    path = _arm_as(tmp_path, "prismatic", "{x: 1.0, y: 0.0, z: 0.0}", "{low: -0.05, high: 0.05}", at_x=0.3)
    assert _ambf_gap(path, 0.2) < 0.01
    monkeypatch.setattr(limit_rows, "slider_row_velocity", lambda *a, **k: None)
    assert _ambf_gap(path, 0.2) > 0.1
