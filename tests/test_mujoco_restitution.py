"""The MuJoCo engine plays Bullet's restitution under AMBF's bodies (runner/mujoco/restitution.py):
a ball of restitution 0.9 dropped from 0.4 m onto a floor of 0.8 bounces to AMBF's apex, where
MuJoCo's soft contacts stopped it dead on the floor (`adfkit parity` on this scene, 2 s: 225.8 mm
from AMBF; now 89.0 mm, 2.65 mm after the first bounce)."""

from __future__ import annotations

import pytest
from parity_scene import body, launch_with, parity
from test_compound_contacts import BALL

from adfkit.parity import ambf

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)


def _scene(tmp_path, floor_restitution: float = 0.8):
    launch = launch_with(tmp_path, {"ball.yaml": BALL}, "ball_launch.yaml")
    floor = tmp_path / "floor.yaml"
    floor.write_text(floor.read_text().replace("restitution: 0.0", f"restitution: {floor_restitution}"))
    return launch


def _heights(launch, bodies: str, steps: int = 600) -> list[float]:
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    opt = Options(visuals=False, control_substeps=1)
    opt.bodies = bodies
    world = open_world(load_scene(launch), opt, engine="mujoco")
    try:
        ball = world.body("ball")
        z = []
        for _ in range(steps):
            world.step(1)
            z.append(ball.world_matrix()[2, 3])
    finally:
        world.close()
    return z


def _first_apex(z: list[float]) -> float:
    landed = next(k for k in range(1, len(z)) if z[k] > z[k - 1])  # the first step up
    return max(z[landed:])


def test_a_ball_bounces_to_ambf_s_apex_in_mujoco(tmp_path):
    z = _heights(_scene(tmp_path), "ambf")
    # AMBF's (and PyBullet's) first apex, measured at 1 ms: 0.72 × the landing speed plus
    # Bullet's contact push, 0.2 × the 0.9 mm overlap per step
    assert _first_apex(z) == pytest.approx(0.25627, abs=1e-3)


def test_no_bounce_where_the_product_of_restitutions_is_zero(tmp_path):
    z = _heights(_scene(tmp_path, 0.0), "ambf")
    # MuJoCo's stiff contact alone: a 1.8 mm hop (Bullet's push out of the overlap gives 1.7 mm)
    assert _first_apex(z) < 0.035


def test_mujoco_s_own_bodies_keep_their_soft_contacts(tmp_path):
    z = _heights(_scene(tmp_path), "pybullet")
    assert _first_apex(z) < 0.035


@needs_ambf
def test_the_first_bounce_is_ambf_s(tmp_path, capsys):
    (doc,) = parity(capsys, _scene(tmp_path), 0.6, "mujoco")
    assert body(doc, "ball")["max_position_gap_m"] < 4e-3
