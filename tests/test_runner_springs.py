"""The six-dof-family springs the PyBullet runner applies as forces (runner/pybullet/joints.py)
are integrated implicitly over the control step: at small gains the file's -k·x - c·v, at any
gain never more than what stops the joint's relative motion within the step (the explicit
spring with clamped gains threw the springy PSM's 1 g tool links past 10 m/s)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pybullet")

from adfkit.runner.pybullet.joints import SpringSet  # noqa: E402


def _after(k, c, x, v, inertia, dt):
    den = 1.0 + (c * dt + k * dt**2) / inertia
    tau = SpringSet._spring(k, c, x, v, den, dt)
    return tau, v + tau * dt / inertia


def test_small_gains_are_the_files_spring_and_damper():
    tau, _ = _after(k=0.02, c=0.01, x=0.1, v=0.5, inertia=1.0, dt=0.004)
    assert tau == pytest.approx(-0.02 * 0.1 - 0.01 * 0.5, rel=1e-2)  # + k·dt·v: 0.6 %


@pytest.mark.parametrize("k", [0.0, 0.02, 0.2, 1e3, 1e9])
@pytest.mark.parametrize("c", [0.0, 0.01, 1.0, 1e6])
def test_any_gain_at_most_stops_the_motion(k, c):
    """A light pair (the corpus thread's inertia, shared as in a chain) spinning at 300 rad/s:
    the damper slows it and never turns it back; the spring alone, displaced, moves it toward
    its equilibrium no faster than the step would carry it there."""
    inertia, dt = 1.25e-5, 0.004
    _, v1 = _after(k, c, x=0.0, v=300.0, inertia=inertia, dt=dt)
    assert 0.0 <= v1 <= 300.0
    _, v2 = _after(k, c, x=0.5, v=0.0, inertia=inertia, dt=dt)
    assert v2 <= 0.0 and -v2 * dt <= 0.5 + 1e-12


def test_a_body_between_two_joints_shares_its_inertia(tmp_path):
    """A chain element between two spring joints gives each half of its inertia, so the two,
    acting in the same step, cannot turn it back twice as far as either would."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    body = """
BODY {n}:
  name: {n}
  mass: 0.03
  inertia: {{ix: 5.0e-05, iy: 5.0e-05, iz: 5.0e-05}}
  location: {{position: {{x: {x}, y: 0.0, z: 1.0}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
  collision shape: SPHERE
  collision geometry: {{radius: 0.001}}
"""
    joint = """
JOINT {a}-{b}:
  parent: BODY {a}
  child: BODY {b}
  parent pivot: {{x: 0.005, y: 0.0, z: 0.0}}
  child pivot: {{x: -0.005, y: 0.0, z: 0.0}}
  parent axis: {{x: 0.0, y: 0.0, z: 1.0}}
  child axis: {{x: 0.0, y: 0.0, z: 1.0}}
  type: six dof spring
  joint limits:
    linear: {{low: {{x: 0.0, y: 0.0, z: 0.0}}, high: {{x: 0.0, y: 0.0, z: 0.0}}}}
  stiffness: {{linear: {{x: 0.0, y: 0.0, z: 0.0}}, angular: {{x: 0.2, y: 0.2, z: 0.2}}}}
  damping: {{linear: {{x: 0.0, y: 0.0, z: 0.0}}, angular: {{x: 0.01, y: 0.01, z: 0.01}}}}
"""
    text = "bodies: [BODY a, BODY b, BODY c]\njoints: [JOINT a-b, JOINT b-c]\n"
    text += "".join(body.format(n=n, x=0.01 * i) for i, n in enumerate("abc"))
    text += joint.format(a="a", b="b") + joint.format(a="b", b="c")
    (tmp_path / "chain.yaml").write_text(text)
    world = open_world(load_scene(tmp_path / "chain.yaml", None, []), Options(ground=False, visuals=False))
    try:
        s = world.springs
        names = [b.key.split()[-1] for b in s.bodies]
        i_b = 1.0 / (2 / 5e-5 + 1 / 5e-5)  # b is on two joints, a and c on one each
        assert names == ["a", "b", "c"] and np.allclose(s.i_eff, [i_b, i_b])
    finally:
        world.close()
