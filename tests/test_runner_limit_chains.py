"""A free multibody's stops played through AMBF's own solver step (runner/free_stops.py, played
by runner/pybullet/limit_chains.py and runner/mujoco/limit_chains.py).

The scene: a 0.2 kg, 0.2 m rod hinged at one end on a static post, released level, falling
into its +1 rad stop at 10.8 rad/s. Measured with `adfkit parity` on AMBF 2.0 (1 ms samples):
AMBF's rod comes back off the stop to 0.99415 rad (its centre of mass about the pivot), 5.9 mrad
inside the stop, 18 ms after it, then rests on it. The joint's own row (limit_rows.py: the
hinge's limit row on the joint alone, 0.3 of the speed back) threw it back to 0.864 rad (136 mrad;
the rod 14.6 mm from AMBF's at most); MuJoCo's limit (at Bullet's rate, mujoco/limits.py) stopped
it dead on the stop (1.00014 rad, no turn back). The slow test plays the scene against AMBF."""

from __future__ import annotations

from pathlib import Path

import pytest

from adfkit.adf import load_scene
from adfkit.parity import ambf
from adfkit.runner import Options, open_world

ROD = """bodies: [BODY post, BODY rod]
joints: [JOINT hinge]
namespace: /ambf/env/
BODY post:
  name: post
  mass: 0.0
  collision shape: Box
  collision geometry: {x: 0.02, y: 0.02, z: 0.02}
  location: {position: {x: 0.0, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY rod:
  name: rod
  mass: 0.2
  collision shape: Box
  collision geometry: {x: 0.2, y: 0.01, z: 0.01}
  location: {position: {x: 0.11, y: 0.0, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
JOINT hinge:
  name: hinge
  parent: BODY post
  child: BODY rod
  type: revolute
  parent pivot: {x: 0.0, y: 0.0, z: 0.0}
  child pivot: {x: -0.11, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 1.0, z: 0.0}
  child axis: {x: 0.0, y: 1.0, z: 0.0}
  joint limits: {low: -1.0, high: 1.0}
"""
BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)

#: AMBF's rod: where it turns back to after the stop (rad), measured
AMBF_TURNS_BACK_TO = 0.99415


def _world(tmp_path: Path, bodies: str = "ambf", text: str = ROD, engine: str = "pybullet"):
    path = tmp_path / "rod.yaml"
    path.write_text(text)
    opt = Options(visuals=False, ground=False, renderer="tiny")  # adfkit run's 4 ms control step
    opt.bodies, opt.springs, opt.ghosts, opt.link_shapes = bodies, "ambf", "ambf", "body"
    return open_world(load_scene(path), opt, engine=engine)


def _swing(world, seconds: float) -> list[float]:
    """The hinge's angle after each control step."""
    (_j, _parent, child) = world.joints_made[0]
    art = child.articulation
    n = _index(art, child)
    out = []
    for _ in range(int(round(seconds / (world.dt * world.opt.control_substeps)))):
        world.step(1)
        out.append(float(world.joint_state(art, [n])[0][0]))
    return out


def _index(art, child) -> int:
    """The record index of the joint ``child`` hangs from in ``art`` (either engine)."""
    return next(n for n, rec in enumerate(art.records) if rec[3] is child)


ENGINES = ("pybullet", "mujoco")


@pytest.mark.parametrize("engine", ENGINES)
def test_a_rod_falling_into_its_stop_turns_back_as_far_as_ambf_s(tmp_path, engine):
    world = _world(tmp_path, engine=engine)
    try:
        assert world.limit_chains  # a free multibody with a limited hinge, under AMBF's bodies
        q = _swing(world, 0.4)
        hit = next(k for k, x in enumerate(q) if x >= 1.0)
        back = min(q[hit:])
        # 0.99346 in PyBullet, 0.99351 in MuJoCo (4 ms control steps), AMBF's 0.99415 (the
        # joint's own row in PyBullet: 0.864; MuJoCo's limit: 1.00014, no turn back)
        assert back == pytest.approx(AMBF_TURNS_BACK_TO, abs=1e-3)
        assert q[-1] == pytest.approx(1.0, abs=0.5e-3)  # resting on the stop
        assert not world.limit_chains.engaged  # at rest: the stop is the joint's own row's again
    finally:
        world.close()


def test_without_ambf_s_bodies_the_joint_s_own_row_stops_it(tmp_path):
    """Control: PyBullet's bodies (Options' default) leave the stop to PyBullet's limit and the
    joint's own row, nothing handed to the chain step."""
    world = _world(tmp_path, bodies="pybullet")
    try:
        assert not world.limit_chains
        q = _swing(world, 0.4)
        hit = next(k for k, x in enumerate(q) if x >= 1.0 - 1e-3)
        assert min(q[hit:]) < 0.9  # 0.864
    finally:
        world.close()


def test_in_mujoco_without_ambf_s_bodies_its_own_limit_stops_it(tmp_path):
    """Control: MuJoCo's bodies (Options' default) leave the stop to MuJoCo's soft limit, which
    stops the rod dead on it, nothing handed to the chain step."""
    world = _world(tmp_path, bodies="pybullet", engine="mujoco")
    try:
        assert not world.limit_chains
        q = _swing(world, 0.4)
        hit = next(k for k, x in enumerate(q) if x >= 1.0 - 1e-3)
        assert min(q[hit:]) > 0.999  # 1.0008: no turn back
    finally:
        world.close()


@pytest.mark.parametrize("bodies", ["rod", "tip"])
def test_both_engines_play_the_two_links_bounce_alike(tmp_path, bodies):
    """The same chain step in both engines: the rod falling into its stop with a free link
    hinged on its end, each engine's joint angles over the first 0.6 s (the bounce and the
    swing after it) within a few mrad of the other's (measured: 0.23 mrad the rod's, 1.3 mrad
    the free link's; under each engine's own bodies and limits 0.37 and 6.9 rad)."""
    qs = []
    for engine in ENGINES:
        (tmp_path / engine).mkdir()
        world = _world(tmp_path / engine, text=TWO_LINKS, engine=engine)
        try:
            (_h, _p, rod), (_w, _r, tip) = world.joints_made
            art = rod.articulation
            n = _index(art, rod if bodies == "rod" else tip)
            q = []
            for _ in range(150):
                world.step(1)
                q.append(float(world.joint_state(art, [n])[0][0]))
            qs.append(q)
        finally:
            world.close()
    gap = max(abs(a - b) for a, b in zip(*qs))
    assert gap < 5e-3, gap


TWO_LINKS = (
    ROD.replace("bodies: [BODY post, BODY rod]", "bodies: [BODY post, BODY rod, BODY tip]").replace(
        "joints: [JOINT hinge]", "joints: [JOINT hinge, JOINT wrist]"
    )
    + """BODY tip:
  name: tip
  mass: 0.1
  collision shape: Box
  collision geometry: {x: 0.1, y: 0.01, z: 0.01}
  location: {position: {x: 0.27, y: 0.03, z: 0.5}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
JOINT wrist:
  name: wrist
  parent: BODY rod
  child: BODY tip
  type: revolute
  parent pivot: {x: 0.11, y: 0.03, z: 0.0}
  child pivot: {x: -0.05, y: 0.0, z: 0.0}
  parent axis: {x: 0.0, y: 1.0, z: 0.0}
  child axis: {x: 0.0, y: 1.0, z: 0.0}
"""
)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_command_mid_bounce_leaves_the_other_joints_free(tmp_path, engine):
    """A command on the hinge while the chain step plays the bounce: the chain step gives the
    multibody back and the wrist, which nothing commands, swings on under gravity, not held at
    the velocity the chain step last gave it."""
    from adfkit.runner.joint_commands import JointCommands

    world = _world(tmp_path, text=TWO_LINKS, engine=engine)
    try:
        (hinge, _p, rod), (_w, _r, tip) = world.joints_made
        art = rod.articulation
        for _ in range(200):
            world.step(1)
            if world.limit_chains.engaged:
                break
        assert world.limit_chains.engaged  # the rod came into its stop
        drives = JointCommands(world)
        drives.command(hinge, rod, "position", 0.9)
        speeds = []
        for _ in range(50):
            drives.apply(world.sim_time)
            world.step(1)
            speeds.append(float(world.joint_state(art, [_index(art, tip)])[1][0]))
        assert not world.limit_chains.engaged
        # the wrist's speed changes from step to step (gravity, the rod's motion): no motor holds it
        assert max(abs(b - a) for a, b in zip(speeds, speeds[1:])) > 1e-3
    finally:
        world.close()


def test_a_snapshot_restored_mid_bounce_plays_the_fall_again(tmp_path):
    """Restored to its start while the chain step plays a bounce, the rod falls and bounces as it
    did the first time (the chain step's motors and opened limits are the motion's it left)."""
    world = _world(tmp_path)
    try:
        snap = world.save_state()
        first = _swing(world, 0.2)
        while not world.limit_chains.engaged:
            world.step(1)
        world.restore_state(snap)
        again = _swing(world, 0.2)
        assert max(abs(a - b) for a, b in zip(first, again)) < 1e-6
    finally:
        world.close()


@pytest.mark.slow
@needs_ambf
@pytest.mark.parametrize("engine", ENGINES)
def test_the_rod_against_ambf(tmp_path, engine):
    """`adfkit parity` on the rod (4 ms, 1 s): within 0.1 mm and 0.1° of AMBF's (measured
    PyBullet 0.066 mm, 0.09°, the joint's own row 14.6 mm, 7.6°; MuJoCo 0.069 mm, 0.09°, its
    own limit 0.54 mm, 0.34°)."""
    from adfkit.parity import session
    from adfkit.scenes.parity import write_parity

    write_parity(tmp_path)  # world, colours, input devices
    (tmp_path / "rod.yaml").write_text(ROD)
    launch = tmp_path / "launch.yaml"
    text = launch.read_text()
    launch.write_text(text[: text.index("multibody configs:")] + "multibody configs:\n- rod.yaml\n")
    req = session.Request(launch, None, BUILD, seconds=1.0, every=0.02, engines=(engine,))
    (c,) = session.run(req, progress=False).comparisons
    rod = next(g for g in c.bodies if g.name.endswith("/rod"))
    assert rod.max_position < 1e-4 and rod.max_angle < 0.1, (rod.max_position, rod.max_angle)


def test_in_mujoco_a_held_multibody_is_not_watched(tmp_path):
    """MuJoCo steps a control step's physics steps in one call where no multibody is free to
    bounce (a drive holds the rod: the corpus PSMs at rest cost 0.15 -> 0.24 s of the rest of
    world.step per 10 s even so, bench/mujoco_run_speed.py), and looks at each physics step once
    it is free again: held at its start, the rod stays; freed, it falls and turns back off its stop."""
    world = _world(tmp_path, engine="mujoco")
    try:
        (_j, _parent, rod) = world.joints_made[0]
        art = rod.articulation
        art.drive()
        assert art.held and not world.limit_chains.watching()
        q = _swing(world, 0.1)
        assert abs(q[-1]) < 1e-3  # the drive holds it where it was built
        art.free()
        assert world.limit_chains.watching()
        q = _swing(world, 0.4)
        hit = next(k for k, x in enumerate(q) if x >= 1.0)
        assert min(q[hit:]) < 0.998  # AMBF's turn back (MuJoCo's limit alone: none)
    finally:
        world.close()
