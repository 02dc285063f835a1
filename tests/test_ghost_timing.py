"""AMBF's ghost rule timed as AMBF times it (runner/pybullet/ghost_steps.py): a ghost acts with the
contact points of the physics step before, a physics step at a time on a free body near it, in
both engines' worlds under ``adfkit parity``'s options. The expected figure is AMBF's, measured
with ``adfkit parity`` on the parity scenes' cube dropped into a ghost slab (`-l 3`): the cube
stops with its centre at z = 0.247761 m (AMBF 2.0, 1 ms steps). Each engine plays a control step
of a free body moving near a ghost a physics step at a time (the engines' ghost_steps.py)."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")

#: m, where AMBF's cube stops in the slab (adfkit parity, 1 ms samples)
AMBF_CUBE_Z = 0.247761
#: m, where it stopped when the rule acted once a 4 ms control step on the points of the moment
MOMENT_CUBE_Z = 0.249044


@pytest.fixture(scope="module")
def ghost_scene(tmp_path_factory):
    from adfkit.adf import load_scene
    from adfkit.scenes.parity import write_parity

    launch = write_parity(tmp_path_factory.mktemp("parity"))
    return lambda: load_scene(launch, [3], [])


def cube_rests_at(scene, engine: str, substeps: int, seconds: float = 0.3) -> float:
    from adfkit.runner import Options, open_world

    opt = Options(control_substeps=substeps, ground=True, visuals=False, renderer="tiny")
    opt.ghosts, opt.springs, opt.bodies = "ambf", "ambf", "ambf"
    world = open_world(scene, opt, engine=engine)
    try:
        world.step(int(round(seconds / (world.dt * substeps))))
        (cube,) = [sb for sb in world.bodies if sb.key.endswith("cube")]
        return float(cube.state()[0][2])
    finally:
        world.close()


@pytest.mark.parametrize("substeps", [4, 1])
def test_a_cube_stops_in_a_ghost_where_ambfs_does_in_pybullet(ghost_scene, substeps):
    assert cube_rests_at(ghost_scene(), "pybullet", substeps) == pytest.approx(AMBF_CUBE_Z, abs=1e-6)


@pytest.mark.parametrize("substeps", [4, 1])
def test_the_ghost_acts_on_the_points_of_the_step_before_in_mujoco(ghost_scene, substeps):
    pytest.importorskip("mujoco")
    # measured 0.8 um (1 ms) and 2.2 um (4 ms, a physics step at a time: runner/mujoco/ghost_steps.py) off
    assert cube_rests_at(ghost_scene(), "mujoco", substeps) == pytest.approx(AMBF_CUBE_Z, abs=3e-6)


def test_without_the_physics_steps_the_cube_stops_short(ghost_scene, monkeypatch):
    """Control: the rule once a control step, on the points of the moment, stops the cube 1.28 mm
    short of AMBF's."""
    from adfkit.runner.pybullet.ghost_steps import GhostSteps

    def at_the_control_step(self, poses):
        self.ghosts, self.fine = [], False
        return []

    monkeypatch.setattr(GhostSteps, "decide", at_the_control_step)
    z = cube_rests_at(ghost_scene(), "pybullet", 4)
    assert z == pytest.approx(MOMENT_CUBE_Z, abs=2e-6) and z - AMBF_CUBE_Z > 1e-3


CARRIED = """\
bodies: [BODY carrier, BODY rider]
ghost objects: [GHOST cage]
BODY carrier:
  name: carrier
  mass: 0.5
  inertia: {ix: 1.0e-4, iy: 1.0e-4, iz: 1.0e-4}
  collision shape: BOX
  collision geometry: {x: 0.05, y: 0.05, z: 0.01}
  location: {position: {x: 0.0, y: 0.0, z: 0.5}, orientation: {r: 0.2, p: 0.1, y: 0.0}}
BODY rider:
  name: rider
  mass: 0.1
  inertia: {ix: 1.0e-5, iy: 1.0e-5, iz: 1.0e-5}
  collision shape: SPHERE
  collision geometry: {radius: 0.01}
  location: {position: {x: 0.0, y: 0.0, z: 0.56}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
GHOST cage:
  name: cage
  parent: BODY carrier
  shape: BOX
  geometry: {x: 0.2, y: 0.2, z: 0.1}
  collision shape: BOX
  collision geometry: {x: 0.2, y: 0.2, z: 0.1}
  location: {position: {x: 0.0, y: 0.0, z: 0.05}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
"""
#: m, where AMBF's carrier stands after 1 s (adfkit parity): two physics steps of gravity, then
#: weightless at 2·g·dt = 19.6 mm/s
AMBF_CARRIER_Z = 0.480804


def carrier_after(tmp_path, engine: str, substeps: int) -> float:
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    (tmp_path / "carried.yaml").write_text(CARRIED)
    opt = Options(control_substeps=substeps, ground=False, visuals=False, renderer="tiny")
    opt.ghosts, opt.springs, opt.bodies = "ambf", "ambf", "ambf"
    world = open_world(load_scene(tmp_path / "carried.yaml"), opt, engine=engine)
    try:
        world.run(1.0)
        return float(world.body("carrier").com_position()[2])
    finally:
        world.close()


@pytest.mark.parametrize("engine,substeps", [("pybullet", 4), ("pybullet", 1), ("mujoco", 4), ("mujoco", 1)])
def test_a_ghost_on_a_body_acts_from_the_second_physics_step(tmp_path, engine, substeps):
    """A ghost hung on a falling body, made around it and a body resting in it: AMBF places a
    ghost in Bullet after each physics step, so in the first step's pass it stands off its parent
    and finds nothing; both bodies fall two steps, then drift weightless (AMBF: 480.804 mm after
    1 s). Control: acting on the first step's points (before it), they drift at half that."""
    if engine == "mujoco":
        pytest.importorskip("mujoco")
    assert carrier_after(tmp_path, engine, substeps) == pytest.approx(AMBF_CARRIER_Z, abs=5e-6)


def test_acting_on_the_first_steps_points_drifts_half_as_far(tmp_path, monkeypatch):
    from adfkit.runner.pybullet import ghost_steps

    monkeypatch.setattr(ghost_steps, "first_points", lambda world, g: g.points)
    z = carrier_after(tmp_path, "pybullet", 4)
    assert z == pytest.approx(0.490397, abs=5e-6) and z - AMBF_CARRIER_Z > 9e-3
