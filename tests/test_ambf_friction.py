"""bench/ambf_friction.py's program: a scene of primitive bodies in AMBF's own Bullet, made as AMBF
makes it, plays as AMBF plays it; given the second friction direction PyBullet's world solves, it
plays the parity cone as adfkit's PyBullet does (docs/parity.md, "Friction in AMBF's Bullet").
Skips, with the reason, without an AMBF build or g++."""

from __future__ import annotations

import importlib.util
import shutil
from pathlib import Path

import pytest

pytest.importorskip("pybullet")

from adfkit.parity import ambf  # noqa: E402

BUILD, WHY = ambf.available()
pytestmark = [
    pytest.mark.skipif(BUILD is None, reason=WHY),
    pytest.mark.skipif(shutil.which("g++") is None, reason="g++ is not installed"),
]
BENCH = Path(__file__).resolve().parent.parent / "bench" / "ambf_friction.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("ambf_friction", BENCH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _gaps(comparison) -> dict[str, float]:
    return {g.name.rsplit("/", 1)[-1]: g.max_position * 1e3 for g in comparison.bodies}


def test_ambfs_bullet_plays_the_cone_as_ambf_and_with_two_friction_directions_as_pybullet(bench, tmp_path):
    from adfkit.adf import load_scene
    from adfkit.parity.compare import compare
    from adfkit.parity.traces import AdfkitPlayer, from_ambf
    from adfkit.runner import Options, open_world
    from adfkit.scenes.parity import write_parity

    launch = write_parity(tmp_path)
    opt = Options(control_substeps=4, visuals=False, renderer="tiny")
    opt.ghosts, opt.springs, opt.link_shapes, opt.bodies = "ambf", "ambf", "body", "ambf"
    world = open_world(load_scene(launch, [7], []), opt, engine="pybullet")
    try:
        text = bench.scene_text(world, 0.5)
        exe = bench.program(BUILD)
        one, two = bench.lab_trace(exe, text, world), bench.lab_trace(exe, text, world, "two")
        pybullet = AdfkitPlayer(world).play(0.5, 0.02)
    finally:
        world.close()
    stage = ambf.Stage(launch, [7])
    real = from_ambf(ambf.run(BUILD, stage, 0.5, 0.02), stage.staged_bodies)
    as_ambf = _gaps(compare(real, one))
    assert set(as_ambf) == {"Floor", "ball", "cylinder", "capsule", "cone"}
    assert max(as_ambf.values()) < 0.1  # measured 0.03 mm (the capsule)
    # the control: the second friction direction alone takes the cone 59 mm from AMBF's ...
    assert _gaps(compare(real, two))["cone"] > 40.0
    # ... to within a millimetre of PyBullet's (measured 0.8 mm; AMBF's is 59.6 mm from it)
    assert _gaps(compare(two, pybullet))["cone"] < 2.0
    assert _gaps(compare(real, pybullet))["cone"] > 40.0


SLIDING = """\
bodies: [BODY ground, BODY grav, BODY brick]
BODY ground:
  name: ground
  mass: 0.0
  collision shape: Box
  collision geometry: {x: 3, y: 3, z: 0.05}
  location: {position: {x: 0.0, y: 0.0, z: -0.025}}
BODY grav:
  name: grav
  mass: 0.2
  gravity: {x: 0.0, y: 2.0, z: -5.0}
  collision shape: CYLINDER
  collision geometry: {radius: 0.03, height: 0.05, axis: Z}
  location: {position: {x: 0.4, y: 0.0, z: 0.03}}
BODY brick:
  name: brick
  mass: 0.2
  gravity: {x: 1.5, y: 1.0, z: -5.0}
  collision shape: BOX
  collision geometry: {x: 0.06, y: 0.04, z: 0.03}
  location: {position: {x: -0.4, y: 0.0, z: 0.02}}
"""


def test_bodies_sliding_flat_under_their_own_gravity_part_by_ambfs_friction_rows(bench, tmp_path):
    # a cylinder and a brick sliding on their faces under sideways `gravity` of their own (a
    # hand-made scene): AMBF's turn and drift where adfkit's slide straight (57 mm over 2 s). The
    # program, given each body's gravity, plays them as AMBF does; with two friction directions
    # started from zero, as adfkit's PyBullet does: AMBF's friction rows are the whole gap
    from adfkit.adf import load_scene
    from adfkit.parity.compare import compare
    from adfkit.parity.traces import AdfkitPlayer, from_ambf
    from adfkit.runner import Options, open_world

    (tmp_path / "slide.yaml").write_text(SLIDING)
    for name, text in {
        "world.yaml": "environment: floor.yaml\n",
        "floor.yaml": "bodies: []\n",
        "input.yaml": "input devices: []\n",
        "colors.yaml": "red: {r: 1, g: 0, b: 0, a: 1}\n",
        "launch.yaml": "world config: world.yaml\ncolor config: colors.yaml\ninput devices config: input.yaml\n"
        "multibody configs: [slide.yaml]\n",
    }.items():
        (tmp_path / name).write_text(text)
    launch = tmp_path / "launch.yaml"
    opt = Options(control_substeps=4, visuals=False, renderer="tiny", ground=False)
    opt.ghosts, opt.springs, opt.link_shapes, opt.bodies = "ambf", "ambf", "body", "ambf"
    world = open_world(load_scene(launch, [0], []), opt, engine="pybullet")
    try:
        text = bench.scene_text(world, 1.0)
        exe = bench.program(BUILD)
        one, both = bench.lab_trace(exe, text, world), bench.lab_trace(exe, text, world, "two", "fresh")
        pybullet = AdfkitPlayer(world).play(1.0, 0.02)
    finally:
        world.close()
    stage = ambf.Stage(launch, [0])
    real = from_ambf(ambf.run(BUILD, stage, 1.0, 0.02), stage.staged_bodies)
    assert max(_gaps(compare(real, one)).values()) < 1.0  # measured 0.26 mm
    assert max(_gaps(compare(both, pybullet)).values()) < 1.0  # measured 0.38 mm
    assert max(_gaps(compare(real, pybullet)).values()) > 10.0  # measured 29.3 mm
