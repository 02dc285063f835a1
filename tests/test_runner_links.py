"""Where a multibody's links are and what they collide with, as AMBF places the bodies: real
PyBullet and real MuJoCo, no mocks."""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest

pb = pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402

# a free 4 cm cube with a 20 cm arm hinged about y at its +x face, the arm's pivot at its own end
# (10 cm from its centre), the arm turned 45 degrees down about the hinge
_C = math.sqrt(0.5) * 0.1
ARM = textwrap.dedent(
    f"""\
    bodies: [BODY base, BODY arm]
    joints: [JOINT base-arm]
    BODY base:
      name: base
      mass: 1.0
      inertia: {{ix: 1.0e-3, iy: 1.0e-3, iz: 1.0e-3}}
      location: {{position: {{x: 0.0, y: 0.0, z: 0.0}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
      collision shape: BOX
      collision geometry: {{x: 0.04, y: 0.04, z: 0.04}}
    BODY arm:
      name: arm
      mass: 0.1
      inertia: {{ix: 1.0e-4, iy: 1.0e-4, iz: 1.0e-4}}
      location: {{position: {{x: {0.02 + _C}, y: 0.0, z: {-_C}}}, orientation: {{r: 0.0, p: {math.pi / 4}, y: 0.0}}}}
      collision shape: BOX
      collision geometry: {{x: 0.2, y: 0.02, z: 0.02}}
    JOINT base-arm:
      name: base-arm
      parent: BODY base
      child: BODY arm
      type: revolute
      parent pivot: {{x: 0.02, y: 0.0, z: 0.0}}
      child pivot: {{x: -0.1, y: 0.0, z: 0.0}}
      parent axis: {{x: 0.0, y: 1.0, z: 0.0}}
      child axis: {{x: 0.0, y: 1.0, z: 0.0}}
    """
)


def _centre(world, name: str) -> np.ndarray:
    sb = world.body(name)
    lo, hi = pb.getAABB(sb.uid, sb.link, physicsClientId=world.cid)
    return (np.array(lo) + np.array(hi)) / 2


def test_a_links_shapes_sit_where_the_file_puts_its_body(tmp_path):
    """A link's frame is its joint's frame, 10 cm from the arm's centre here: its box is made in
    that frame and collides where the file puts the arm (the corpus gripper3's jaws collided
    0.1-0.3 m off, inside its base, and the gripper slid 337 mm over the floor and turned over),
    and the floor a model played alone gets is 1 mm under the arm's lowest corner. Control: the
    shapes made in the arm's centre-of-mass frame (Options.link_shapes "com", the tasks' default)
    sit on the hinge instead."""
    path = tmp_path / "arm.yaml"
    path.write_text(ARM)
    low = -_C - (0.1 * math.sqrt(0.5) + 0.01 * math.sqrt(0.5))  # the arm's lowest edge
    for shapes, off in (("body", 0.0), ("com", 0.1)):
        world = open_world(load_scene(path), Options(visuals=False, link_shapes=shapes))
        try:
            arm = world.body("BODY arm")
            assert arm.link >= 0  # a link of the cube's multibody
            gap = float(np.linalg.norm(_centre(world, "BODY arm") - np.array([0.02 + _C, 0.0, -_C])))
            assert gap == pytest.approx(off, abs=2e-3), shapes
            if shapes == "body":
                assert world.ground_z == pytest.approx(low - 1e-3, abs=2e-4)
            else:
                assert world.ground_z > low + 0.02  # the hinged box reaches no lower than the cube
        finally:
            world.close()


def _bar(name: str, x: float, z: float, pitch: float, size: str) -> str:
    return (
        f"BODY {name}:\n  name: {name}\n  mass: 0.1\n  inertia: {{ix: 1.0e-4, iy: 1.0e-4, iz: 1.0e-4}}\n"
        f"  location: {{position: {{x: {x}, y: 0.0, z: {z}}}, orientation: {{r: 0.0, p: {pitch}, y: 0.0}}}}\n"
        "  damping: {linear: 0.0, angular: 0.0}\n"
        f"  collision shape: BOX\n  collision geometry: {size}\n"
    )


def _hinge(parent: str, child: str, pp, cp, limits: str = "", kind: str = "revolute") -> str:
    v = lambda p: f"{{x: {p[0]}, y: 0.0, z: {p[1]}}}"  # noqa: E731
    return (
        f"JOINT {parent}-{child}:\n  name: {parent}-{child}\n  parent: BODY {parent}\n  child: BODY {child}\n"
        f"  type: {kind}\n  parent pivot: {v(pp)}\n  child pivot: {v(cp)}\n"
        "  parent axis: {x: 0.0, y: 1.0, z: 0.0}\n  child axis: {x: 0.0, y: 1.0, z: 0.0}\n" + limits
    )


def four_bar(open_m: float = 0.0, limits: str = "", last_limits: str = "") -> str:
    """A parallelogram hung from a static top bar l1: sides l2 and l4 (10 cm, 0.1 kg, 1e-4 kg m²)
    45 degrees from hanging straight down, the bottom bar l3; l1-l4 closes the loop. ``open_m``
    moves l3's pivot for l4 that far along it, so the bodies where the file puts them leave the
    loop that far open, as a file's rounding does; ``limits`` goes to l2-l3 and l3-l4,
    ``last_limits`` to l1-l4."""
    s = math.sqrt(0.5) * 0.1
    bar, side = "{x: 0.2, y: 0.01, z: 0.01}", "{x: 0.01, y: 0.01, z: 0.1}"
    return (
        "bodies: [BODY world, BODY l1, BODY l2, BODY l3, BODY l4]\n"
        "joints: [JOINT world-l1, JOINT l1-l2, JOINT l2-l3, JOINT l3-l4, JOINT l1-l4]\n"
        "ignore inter-collision: true\n"
        "BODY world:\n  name: world\n  mass: 0.0\n"
        "  location: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}\n"
        + _bar("l1", 0.1, 1.0, 0.0, bar).replace("mass: 0.1", "mass: 0.0")
        + _bar("l2", -s / 2, 1.0 - s / 2, math.pi / 4, side)
        + _bar("l3", 0.1 - s, 1.0 - s, 0.0, bar)
        + _bar("l4", 0.2 - s / 2, 1.0 - s / 2, math.pi / 4, side)
        + _hinge("world", "l1", (0.1, 1.0), (0.0, 0.0), kind="fixed")
        + _hinge("l1", "l2", (-0.1, 0.0), (0.0, 0.05))
        + _hinge("l2", "l3", (0.0, -0.05), (-0.1, 0.0), limits)
        + _hinge("l3", "l4", (0.1 + open_m, 0.0), (0.0, -0.05), limits)
        + _hinge("l1", "l4", (0.1, 0.0), (0.0, 0.05), last_limits)
    )


def _pendulum(t_end: float, theta0: float, dt: float = 1e-4) -> list[float]:
    """The parallelogram's side angle from hanging straight down, by hand: the two sides (0.1 kg,
    1e-4 kg m² about their centres, pivots 5 cm off) swing about their top pivots and the bottom
    bar (0.1 kg) goes round with their ends, unturned: I = 2 (1e-4 + 0.1·0.05²) + 0.1·0.1² =
    1.7e-3 kg m², the gravity torque g (2·0.1·0.05 + 0.1·0.1) sin θ; RK4, sampled every 20 ms."""
    k = 9.81 * (2 * 0.1 * 0.05 + 0.1 * 0.1) / (2 * (1e-4 + 0.1 * 0.05**2) + 0.1 * 0.1**2)
    f = lambda y: np.array([y[1], -k * math.sin(y[0])])  # noqa: E731
    y, out = np.array([theta0, 0.0]), []
    for n in range(int(round(t_end / dt)) + 1):
        if n % int(round(0.02 / dt)) == 0:
            out.append(float(y[0]))
        k1 = f(y)
        k2 = f(y + dt / 2 * k1)
        k3 = f(y + dt / 2 * k2)
        k4 = f(y + dt * k3)
        y = y + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return out


def _side_angle(world) -> float:
    """l2's angle from hanging straight down (about y; positive: its lower end towards -x, its
    frame's z axis up along it)."""
    z = world.body("BODY l2").world_matrix()[:3, 2]
    return math.atan2(z[0], z[2])


def test_a_closed_four_bar_swings_as_a_pendulum_from_a_loop_closed_at_the_start(tmp_path):
    """A parallelogram whose file puts a pivot 0.3 mm off where its bodies meet (a file's
    rounding): PyBullet plays it as one multibody whose loop joint is a constraint between two
    of its links. The runner moves its joint values until the loop's pivots meet (AMBF's bodies
    start where the file puts them and its constraints pull them together) and leaves its joints
    free, as AMBF does: it swings as the pendulum worked out by hand (0.3 s, past the bottom and
    up the other side), its loop closed throughout. Controls: the loop left open by the file's
    0.3 mm (the runner's closing step skipped) starts 0.3 mm apart; a multibody held at its
    start (as the runner held every looped one) does not swing."""
    from adfkit.runner.pybullet import assemble

    path = tmp_path / "four_bar.yaml"
    path.write_text(four_bar(open_m=3e-4))
    expected = _pendulum(0.3, math.pi / 4)
    world = open_world(load_scene(path), Options(visuals=False, ground=False))
    try:
        assert world.constraint_error() < 1e-8
        (art,) = world.articulations
        assert not art.held
        played = []
        for _ in range(15):  # every 20 ms (five control steps)
            played.append(_side_angle(world))
            world.run(0.02)
        played.append(_side_angle(world))
        assert played[0] == pytest.approx(math.pi / 4, abs=5e-3)
        assert np.abs(np.array(played) - np.array(expected)).max() < math.radians(2.0)
        assert min(played) < -0.6  # up the other side
        assert world.report()["max_constraint_error_m"] < 1e-4
    finally:
        world.close()
    world = open_world(load_scene(path), Options(visuals=False, ground=False))
    try:  # control: its joints held where they start, it stays
        world.articulations[0].drive()
        start = _side_angle(world)
        world.run(0.1)
        assert _side_angle(world) == pytest.approx(start, abs=1e-3)
    finally:
        world.close()
    mp = pytest.MonkeyPatch()
    mp.setattr(assemble, "close_loops", lambda w: {})
    try:
        world = open_world(load_scene(path), Options(visuals=False, ground=False))
        try:
            assert world.constraint_error() == pytest.approx(3e-4, rel=0.2)
        finally:
            world.close()
    finally:
        mp.undo()


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_loop_is_closed_by_its_joint_without_limits(tmp_path, engine):
    """A four-bar whose loop can be closed by a limited joint (l3-l4) or by one without limits
    (l1-l4, as the corpus parallel structure's continuous one): the one without limits closes it,
    as a constraint, which plays none, and l3-l4's limits are the tree joint's. Control: all four
    limited, the tree takes the one it meets first (l1-l4) and l3-l4 closes the loop."""
    from adfkit.model.tree import build_tree

    lim = "  joint limits: {low: -0.5, high: 0.5}\n"
    for last, closes in (("", "JOINT l1-l4"), (lim, "JOINT l3-l4")):
        path = tmp_path / f"four_bar{len(last)}.yaml"
        path.write_text(four_bar(limits=lim, last_limits=last))
        scene = load_scene(path)
        (model,) = scene.all_models()
        assert [j.identifier for j, *_ in build_tree(model).loops] == [closes]
        world = open_world(scene, Options(visuals=False, ground=False), engine=engine)
        try:
            # (PyBullet holds l1's weld to the static world by constraints too)
            assert {n for n, *_ in world.constraints} - {"JOINT world-l1"} == {closes}
        finally:
            world.close()


def slider_crank() -> str:
    """A slider-crank in the x-z plane: a crank l2 (10 cm) hinged at (0, 1) on a static l1, 45°
    up; a coupler l4 (20 cm) from the crank's tip to a block l3 that slides along x (a prismatic
    joint from l5, a static rail fixed to l1) at z = 1. Two joints go into the block: the
    prismatic from the rail and the revolute from the coupler, which a depth-first tree meets
    first, all limited, so without a rule the slider closes the loop."""
    c = math.sqrt(0.5) * 0.1
    bx = c + math.sqrt(0.2**2 - c**2)
    coupler = math.asin(c / 0.2)
    bar = "{x: 0.1, y: 0.01, z: 0.01}"
    rail_joint = (
        "JOINT l5-l3:\n  name: l5-l3\n  parent: BODY l5\n  child: BODY l3\n  type: prismatic\n"
        f"  parent pivot: {{x: {bx}, y: 0.0, z: 0.0}}\n  child pivot: {{x: 0.0, y: 0.0, z: 0.0}}\n"
        "  parent axis: {x: 1.0, y: 0.0, z: 0.0}\n  child axis: {x: 1.0, y: 0.0, z: 0.0}\n"
        "  joint limits: {low: -0.3, high: 0.3}\n"
    )
    return (
        "bodies: [BODY l1, BODY l5, BODY l2, BODY l4, BODY l3]\n"
        "joints: [JOINT l1-l5, JOINT l1-l2, JOINT l2-l4, JOINT l4-l3, JOINT l5-l3]\n"
        "ignore inter-collision: true\n"
        + _bar("l1", 0.0, 1.0, 0.0, bar).replace("mass: 0.1", "mass: 0.0")
        + _bar("l5", 0.0, 1.0, 0.0, bar).replace("mass: 0.1", "mass: 0.0")
        + _bar("l2", c / 2, 1.0 + c / 2, -math.pi / 4, bar)
        + _bar("l4", c + (bx - c) / 2, 1.0 + c / 2, coupler, "{x: 0.2, y: 0.01, z: 0.01}")
        + _bar("l3", bx, 1.0, 0.0, "{x: 0.02, y: 0.02, z: 0.02}")
        + _hinge("l1", "l5", (0.0, 0.0), (0.0, 0.0), kind="fixed")
        + _hinge("l1", "l2", (0.0, 0.0), (-0.05, 0.0))
        + _hinge("l2", "l4", (0.05, 0.0), (-0.1, 0.0))
        + _hinge("l4", "l3", (0.1, 0.0), (0.0, 0.0), "  joint limits: {low: -1.5, high: 1.5}\n")
        + rail_joint
    )


def test_mujoco_keeps_a_slide_in_the_tree_and_closes_the_loop_at_a_hinge(tmp_path, monkeypatch):
    """MuJoCo closes a loop by a point (connect) or a weld: a prismatic joint closing one would
    be locked (the corpus gripper3's slider between its jaws, which slide 117 mm in AMBF). The
    MuJoCo runner's tree keeps the slider and the coupler's hinge closes the loop: in 0.3 s the
    crank falls and the block slides (80 mm) where the loop puts it, |block - crank tip| = 20 cm within
    1 mm. Control: the tree as other formats build it, the slider closing the loop: the block
    stays (0.1 mm)."""
    from adfkit.converters import mjcf_write
    from adfkit.model.tree import build_tree

    path = tmp_path / "slider_crank.yaml"
    path.write_text(slider_crank())
    (model,) = load_scene(path).all_models()
    assert [j.identifier for j, *_ in build_tree(model).loops] == ["JOINT l5-l3"]
    assert [j.identifier for j, *_ in build_tree(model, slides_first=True).loops] == ["JOINT l4-l3"]
    for rule in (True, False):
        if not rule:
            monkeypatch.setattr(
                mjcf_write, "build_tree", lambda m, kinds=None, _s=False, _b=False, **_kw: build_tree(m, kinds)
            )
        world = open_world(load_scene(path), Options(visuals=False, ground=False), engine="mujoco")
        try:
            block, crank = world.body("BODY l3"), world.body("BODY l2")
            x0 = block.world_matrix()[0, 3]
            world.run(0.3)
            moved = block.world_matrix()[0, 3] - x0
            tip = crank.world_matrix() @ np.array([0.05, 0.0, 0.0, 1.0])
            if rule:
                assert abs(moved) > 0.02, moved
                assert np.linalg.norm(block.world_matrix()[:3, 3] - tip[:3]) == pytest.approx(0.2, abs=1e-3)
                assert block.world_matrix()[2, 3] == pytest.approx(1.0, abs=1e-3)
            else:
                assert abs(moved) < 1e-3, moved
        finally:
            world.close()
