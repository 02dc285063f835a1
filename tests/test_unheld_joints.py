"""A joint whose parent is a static body (mass 0) with no collision shape and no `inertia`: AMBF
2.0 prints "COLLISION TYPE NOT UNDERSTOOD" for the parent, keeps the joint, and a hinge, slider,
fixed or p2p joint there holds nothing: the child falls freely, unturned. Measured in AMBF
(`adfkit parity`, a 0.5 kg bar hinged to such a post 1 m up): the bar 3.8389 m below its start
after 1 s, 19.0871 m after 2 s, its x unchanged; both engines held it swinging (19.06 m apart at
2 s). Now neither engine makes the joint (`runner-joint-static`; `adfkit parity` lists it on both
sides) and the bar falls as AMBF's: PyBullet 0.000 mm over 2 s, MuJoCo 1.9 mm (its free fall).
With a `collision shape` or an `inertia` on the post the joint holds in AMBF (the hinged bar
swings within 0.75 mm of adfkit's with the shape; with the inertia AMBF's bar stays 4.83 m above
a free one's after 1 s), and adfkit makes it."""

from __future__ import annotations

import numpy as np
import pytest

from adfkit.adf import load_scene
from adfkit.runner import Options, open_world

POST = """bodies: [BODY post, BODY bar]
joints: [JOINT hinge]
namespace: /ambf/env/damp/
BODY post:
  name: post
  mass: 0
  shape: BOX
  geometry: {x: 0.04, y: 0.4, z: 0.04}
  location: {position: {x: 0, y: 0, z: 1.0}, orientation: {r: 0, p: 0, y: 0}}
BODY bar:
  name: bar
  mass: 0.5
  shape: BOX
  geometry: {x: 0.25, y: 0.03, z: 0.03}
  collision shape: BOX
  collision geometry: {x: 0.25, y: 0.03, z: 0.03}
  location: {position: {x: 0.15, y: 0.1, z: 1.0}, orientation: {r: 0, p: 0, y: 0}}
JOINT hinge:
  name: hinge
  parent: BODY post
  child: BODY bar
  type: revolute
  parent pivot: {x: 0.02, y: 0.1, z: 0}
  child pivot: {x: -0.13, y: 0, z: 0}
  parent axis: {x: 0, y: 1, z: 0}
  child axis: {x: 0, y: 1, z: 0}
"""

#: AMBF's bar after 1 s (adfkit parity's sample of AMBF's run)
AMBF_BAR_1S = (0.15, 0.1, -3.8389)


@pytest.mark.parametrize("engine,tol_m", [("pybullet", 1e-4), ("mujoco", 2.5e-3)])
def test_a_hinge_on_a_static_body_without_collision_shape_holds_nothing(tmp_path, engine, tol_m):
    pytest.importorskip(engine)
    (tmp_path / "m.yaml").write_text(POST)
    world = open_world(load_scene(tmp_path / "m.yaml", None, []), Options(visuals=False, ground=False), engine=engine)
    try:
        assert any(d.rule == "runner-joint-static" for d in world.diagnostics)
        assert [j.identifier for j, _p, _c in world.inert_joints()] == ["JOINT hinge"]
        world.run(1.0)
        m = world.body("BODY bar").world_matrix()
    finally:
        world.close()
    assert np.allclose(m[:3, 3], AMBF_BAR_1S, atol=tol_m)
    assert np.allclose(m[:3, :3], np.eye(3), atol=1e-6)  # unturned, as in AMBF


@pytest.mark.parametrize(
    "given",
    [
        "  collision shape: BOX\n  collision geometry: {x: 0.04, y: 0.4, z: 0.04}\n",
        "  inertia: {ix: 0.001, iy: 0.001, iz: 0.001}\n",
    ],
)
def test_with_a_collision_shape_or_an_inertia_the_post_holds_it(tmp_path, given):
    """The same post given a `collision shape` or an `inertia`: AMBF's joint holds, and adfkit
    makes it: the bar swings down on its hinge."""
    pytest.importorskip("pybullet")
    held = POST.replace(
        "  geometry: {x: 0.04, y: 0.4, z: 0.04}\n", "  geometry: {x: 0.04, y: 0.4, z: 0.04}\n" + given, 1
    )
    (tmp_path / "m.yaml").write_text(held)
    world = open_world(load_scene(tmp_path / "m.yaml", None, []), Options(visuals=False, ground=False))
    try:
        assert not any(d.rule == "runner-joint-static" for d in world.diagnostics)
        world.run(1.0)
        z = world.body("BODY bar").world_matrix()[2, 3]
    finally:
        world.close()
    assert 0.8 < z < 1.01  # on its hinge, 0.13 m from the pivot at 1.0 m


@pytest.mark.parametrize(
    "kind,warned",
    [
        ("revolute", True),
        ("prismatic", True),
        ("torsion spring", True),
        ("linear spring", True),
        ("fixed", True),
        ("p2p", True),
        ("cone twist", False),
    ],
)
def test_validate_warns_at_the_joints_parent(tmp_path, kind, warned):
    """`adfkit validate` said nothing. Measured in AMBF for a hinge, a slider (a lift carriage
    fell), a fixed and a p2p joint (the bar fell 4.84 m in 1 s) and both springs (a torsion
    spring's flap fell, turning to its 0.9 rad equilibrium past its ±0.5 rad limits; a linear
    spring's shuttle fell, oscillating about its equilibrium); a cone twist was not measured."""
    from adfkit.validator import validate_file

    f = tmp_path / "m.yaml"
    f.write_text(POST.replace("type: revolute", f"type: {kind}"))
    found = [d for d in validate_file(f).diagnostics if d.rule == "joint-static-parent"]
    assert [(d.location.line, d.severity.name) for d in found] == (
        [(20, "WARNING")] if warned else []
    )  # `parent: BODY post`


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_fixed_joint_there_holds_nothing_either(tmp_path, engine):
    """AMBF's bar on a fixed joint to the shapeless post: 4.8389 m below its start after 1 s,
    unturned (measured; both engines held it, 4838.9 mm apart)."""
    pytest.importorskip(engine)
    (tmp_path / "m.yaml").write_text(POST.replace("type: revolute", "type: fixed"))
    world = open_world(load_scene(tmp_path / "m.yaml", None, []), Options(visuals=False, ground=False), engine=engine)
    try:
        world.run(1.0)
        m = world.body("BODY bar").world_matrix()
    finally:
        world.close()
    assert m[2, 3] == pytest.approx(AMBF_BAR_1S[2], abs=2.5e-3)
