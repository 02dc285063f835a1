"""A `cone twist` joint's limits as AMBF's Bullet plays them (runner/cone_twist.py): the swing held
by an ellipse of the `z` and `y` limits, the twist about frame x by the `x` limit apart. Limiting
each Euler angle instead, a rod falling diagonally into a cone of 0.3 x 0.8 rad was 80 mm
(PyBullet) and 66 mm (MuJoCo) from AMBF's over 2 s (`adfkit parity`)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from parity_scene import body, launch_with, parity

from adfkit.adf import load_scene
from adfkit.parity import ambf
from adfkit.runner import Options, open_world
from adfkit.runner.cone_twist import chain_impulses, cone_rows, sequential_impulses, swing_limit

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)
AMBFS = dict(bodies="ambf", springs="ambf", ghosts="ambf", link_shapes="body")


def _turn(axis, angle: float) -> np.ndarray:
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * kx + (1 - math.cos(angle)) * kx @ kx


def test_the_swing_limit_is_the_ellipse_of_the_z_and_y_limits():
    """Spans (z 0.8, y 0.3): 0.8 about frame z, 0.3 about frame y, and 1/√(½/0.8² + ½/0.3²) =
    0.3973 rad about the axis halfway between them (where per-axis limits allow 0.8 and 0.3 at once)."""
    span = np.array([[0.8, 0.3, 0.5]] * 3)
    axes = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [0.0, math.sqrt(0.5), math.sqrt(0.5)]])
    assert swing_limit(axes, span) == pytest.approx([0.8, 0.3, 0.39725], abs=1e-5)


def test_a_swing_and_a_twist_past_their_limits_give_one_row_each():
    """Frame B turned 0.5 rad about the diagonal of frame A's y and z: swing past the ellipse by
    0.5 - 0.3973 rad, the row turning the child back along the ellipse's normal (more about y,
    the narrow axis, than the diagonal). Turned 0.7 rad about x: twist past 0.5 by 0.2 rad."""
    span = np.array([[0.8, 0.3, 0.5]])
    diagonal = [0.0, math.sqrt(0.5), math.sqrt(0.5)]
    axes, err = cone_rows(np.eye(3)[None], _turn(diagonal, 0.5)[None], span)
    assert err[0] == pytest.approx([0.5 - 0.39725, 0.0], abs=1e-5)
    back = axes[0, 0]
    assert back @ diagonal < -0.8  # turns the child back
    assert abs(back[1]) > 2 * abs(back[2])  # along the ellipse's normal: mostly about y
    axes, err = cone_rows(np.eye(3)[None], _turn([1.0, 0.0, 0.0], 0.7)[None], span)
    assert err[0] == pytest.approx([0.0, 0.2], abs=1e-9)
    assert axes[0, 1] @ [1.0, 0.0, 0.0] == pytest.approx(-1.0)


def test_the_solve_of_a_chain_is_the_solve_of_one_joint_where_there_is_one():
    """A rod on a static post, swinging at 8 rad/s 2 mm rad past its swing limit: the chain's
    solve (projected Gauss-Seidel by triangular solves) gives the row's impulse that the joint's
    own solve (its five rows one after another, ten sweeps) gives, 0.0248 N·s·m: 8% short of the
    converged 0.0270 (the rod's inertia about the pivot times 8.15 + 0.3·0.002/dt rad/s)."""
    w = np.array([[0.0, 8.15, 0.0]])
    r = np.array([[0.107, 0.0, -0.0246]])  # pivot to centre of mass
    inv_i = np.diag(1 / np.array([3.33e-6, 6.68e-4, 6.68e-4]))[None]
    zero = np.zeros((1, 3))
    axes, err = np.array([[[0.0, -1.0, 0.0], [1.0, 0.0, 0.0]]]), np.array([[0.002, 0.0]])
    post, rod = (np.zeros(1), np.zeros((1, 3, 3)), zero, zero, zero), (np.array([5.0]), inv_i, np.cross(w, r), w, -r)
    alone = sequential_impulses((post, rod), zero, axes, err, 0.001)
    bodies = (np.array([0.0, 5.0]), np.concatenate([np.zeros((1, 3, 3)), inv_i]), np.vstack([zero, np.cross(w, r)]))
    chain = chain_impulses(
        (*bodies, np.vstack([zero, w])), (np.array([0]), np.array([1]), zero, -r, zero), axes, err, 0.001
    )
    assert alone[0] == pytest.approx([0.0248, 0.0], abs=5e-4)
    assert chain == pytest.approx(alone, rel=1e-9)


def _rod(n: int, x: float, axis, limits, pivot=(-0.11, 0.0, 0.0), size=(0.2, 0.01, 0.01)) -> str:
    ax = "{" + ", ".join(f"{k}: {v}" for k, v in zip("xyz", axis)) + "}"
    lim = "{" + ", ".join(f"{k}: {v}" for k, v in zip("xyz", limits)) + "}"
    return f"""BODY post{n}:
  name: post{n}
  mass: 0.0
  collision shape: Box
  collision geometry: {{x: 0.02, y: 0.02, z: 0.02}}
  location: {{position: {{x: {x}, y: 0.0, z: 0.5}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
BODY rod{n}:
  name: rod{n}
  mass: 0.2
  collision shape: Box
  collision geometry: {{x: {size[0]}, y: {size[1]}, z: {size[2]}}}
  location: {{position: {{x: {x - pivot[0]}, y: {-pivot[1]}, z: {0.5 - pivot[2]}}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
JOINT j{n}:
  name: j{n}
  parent: BODY post{n}
  child: BODY rod{n}
  type: cone twist
  parent pivot: {{x: 0.0, y: 0.0, z: 0.0}}
  child pivot: {{x: {pivot[0]}, y: {pivot[1]}, z: {pivot[2]}}}
  parent axis: {ax}
  child axis: {ax}
  joint limits: {lim}
"""


def _model(rods) -> str:
    return (
        "bodies: [" + ", ".join(f"BODY post{r[0]}, BODY rod{r[0]}" for r in rods) + "]\n"
        "joints: [" + ", ".join(f"JOINT j{r[0]}" for r in rods) + "]\nnamespace: /ambf/env/\n"
        "" + "".join(_rod(*r) for r in rods)
    )


DIAGONAL = (1, 0.8, (0.0, 0.6, 0.8), (0.5, 0.3, 0.8))  # falls about world y: 0.6 of frame z, 0.8 of y


def _swing_over_limit(world, frame_a: np.ndarray) -> float:
    """The rod's swing over Bullet's ellipse limit in its direction (1: on the cone)."""
    d = frame_a.T @ world.body("BODY rod1").world_matrix()[:3, 0]  # the rod's direction in frame A
    swing = math.acos(max(-1.0, min(1.0, d[0])))
    about_y, about_z = d[2] / math.sin(swing), -d[1] / math.sin(swing)
    return swing * math.sqrt(about_y**2 / 0.3**2 + about_z**2 / 0.8**2)


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_rod_falling_diagonally_is_held_on_bullets_ellipse(tmp_path, engine):
    """Released level on an axis (0, 0.6, 0.8) with limits {x 0.5, y 0.3, z 0.8}, the rod falls
    diagonally into its cone and slides along it: its swing reaches the ellipse's limit in its
    direction (0.98-1.01 of it over 2 s, both engines) and never passes it by 2 %. The Euler
    angles' limits (Options' defaults) let it out to 2.5 (MuJoCo) and 7.8 times (PyBullet)."""
    pytest.importorskip(engine)
    (tmp_path / "m.yaml").write_text(_model([DIAGONAL]))
    frame_a = _turn([-1.0, 0.0, 0.0], math.asin(0.6))  # z onto the axis by the shortest arc (AMBF's frame A)
    assert frame_a @ [0, 0, 1] == pytest.approx([0.0, 0.6, 0.8])
    worst = {}
    for name, opt in (
        ("ambf", Options(visuals=False, ground=False, **AMBFS)),
        ("euler", Options(visuals=False, ground=False)),
    ):
        world = open_world(load_scene(tmp_path / "m.yaml", None, []), opt, engine=engine)
        try:
            ratios, opening = [], 0.0
            for _ in range(200):
                world.run(0.01)
                ratios.append(_swing_over_limit(world, frame_a))
                opening = max(opening, world.constraint_error())
        finally:
            world.close()
        worst[name] = max(ratios)
        if name == "ambf":  # the pivot held (in PyBullet by Bullet's pivot rows, played as forces)
            assert opening < 2e-4, opening
    assert 0.98 < worst["ambf"] < 1.02, worst
    assert worst["euler"] > 1.2, worst  # the check can fail: per-axis limits leave the ellipse


RODS = [
    DIAGONAL,
    (2, 0.4, (0.0, -0.6, 0.8), (0.5, 0.3, 0.8)),
    (3, 0.0, (0.0, 0.5, 0.8660254), (0.5, 0.6, 0.4)),
    (4, -0.4, (0.0, 0.0, 1.0), (0.2, 0.5, 0.5), (-0.11, 0.04, 0.0), (0.2, 0.1, 0.01)),  # twisted by its weight
]


@needs_ambf
def test_cone_twists_swing_and_twist_into_their_limits_as_in_ambf(tmp_path, capsys):
    """Rods falling diagonally into elliptic cones and a plate hung off its twist axis (its weight
    twists it into its 0.2 rad limit) follow AMBF's over 2 s: in PyBullet, where the bodies move
    freely under Bullet's rows as in AMBF, the plate and the rod into the 0.6 x 0.4 rad cone within
    0.03 mm, the two rods chattering on their 0.3 x 0.8 rad cones 1.00 mm at most (a bounce a
    step apart; 0.05 mm between bounces); MuJoCo 0.12-0.82 mm. 13-80 (PyBullet) and 15-66 mm
    (MuJoCo) with each Euler angle limited."""
    launch = launch_with(tmp_path, {"m.yaml": _model(RODS)})
    for doc in parity(capsys, launch, 2.0, "both"):
        for n, *_ in RODS:
            row = body(doc, f"rod{n}")
            exact = doc["engine"] == "pybullet" and n in (3, 4)
            assert row["max_position_gap_m"] < (1e-4 if exact else 1.5e-3), (doc["engine"], row)
            assert row["max_angle_gap_deg"] < 1.0, (doc["engine"], row)


CHAIN = """bodies: [BODY post, BODY a, BODY b]
joints: [JOINT j, JOINT k]
namespace: /ambf/env/
BODY post:
  name: post
  mass: 0.0
  collision shape: Box
  collision geometry: {x: 0.02, y: 0.02, z: 0.02}
  location: {position: {x: 0.0, y: 0.0, z: 0.6}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY a:
  name: a
  mass: 0.2
  collision shape: Box
  collision geometry: {x: 0.2, y: 0.01, z: 0.01}
  location: {position: {x: 0.11, y: 0.0, z: 0.6}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY b:
  name: b
  mass: 0.1
  collision shape: Box
  collision geometry: {x: 0.15, y: 0.01, z: 0.01}
  location: {position: {x: 0.305, y: 0.0, z: 0.6}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
JOINT j:
  name: j
  parent: BODY post
  child: BODY a
  type: cone twist
  parent pivot: {x: 0.0, y: 0.0, z: 0.0}
  child pivot: {x: -0.11, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 0.6, z: 0.8}
  child axis: {x: 0.0, y: 0.6, z: 0.8}
  joint limits: {x: 0.5, y: 0.3, z: 0.8}
JOINT k:
  name: k
  parent: BODY a
  child: BODY b
  type: cone twist
  parent pivot: {x: 0.11, y: 0.0, z: 0.0}
  child pivot: {x: -0.085, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 1.0, z: 0.0}
  child axis: {x: 0.0, y: 1.0, z: 0.0}
  joint limits: {x: 0.4, y: 0.4, z: 0.6}
"""


@needs_ambf
def test_a_chain_of_cone_twists_falls_into_its_limits_as_in_ambf(tmp_path, capsys):
    """Two rods on cone twists, one hanging from the other, released level: both joints reach
    their limits within 0.2 s, where PyBullet follows AMBF within 1 mm (0.65 and 0.94 mm; 64 and
    77 mm with the Euler angles limited, 55 and 70 mm with each joint's rows sized alone). AMBF's
    chain then bounces violently off its limits and neither side can follow the other after."""
    launch = launch_with(tmp_path, {"m.yaml": CHAIN})
    (doc,) = parity(capsys, launch, 0.2, "pybullet")
    for name in ("a", "b"):
        assert body(doc, name)["max_position_gap_m"] < 1e-3, body(doc, name)
