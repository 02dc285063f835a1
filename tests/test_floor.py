"""AMBF's floor in both engines: a world whose `environment` is a floor written as AMBF's own
(`ambf_models/descriptions/world/checkered_floor.yaml`: `BODY Plane`, a static PLANE at
z = -1.5, a visual OBJ, `collision groups: []`), built here, holds the bodies AMBF's holds for
every collision-group setting a floor can have; real PyBullet and real MuJoCo, no mocks."""

from __future__ import annotations

import textwrap

import pytest

pytest.importorskip("mujoco")
pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.converters.mjcf_write import to_mjcf  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402

ENGINES = ["pybullet", "mujoco"]
FLOOR_Z = -1.5
BOXES = {"Bnone": None, "Bempty": "[]", "B1": "[1]", "B2": "[2]", "B13": "[1, 3]"}

#: which boxes the floor holds, by the floor's `collision groups` (None: the key absent). Measured
#: in AMBF 2.0 itself (ambf_simulator built from ../shared/ambf, -t true, 1 s, these files with
#: the floor as a model beside the boxes): the others fell to the next floor, 1.5 m lower. It is
#: what afFramework.cpp's buildCollisionGroups makes: bodies that both have groups collide only
#: when they share one; a body without groups (absent or []) collides with every body.
AMBF_HOLDS = {
    None: set(BOXES),
    "[]": set(BOXES),
    "[1]": set(BOXES) - {"B2"},
    "[3]": {"Bnone", "Bempty", "B13"},
    "[1, 2]": set(BOXES),
}


def _groups_line(groups: str | None) -> str:
    return "" if groups is None else f"  collision groups: {groups}\n"


def _floor(groups: str | None, *, name: str = "Plane", mass: float = 0.0) -> str:
    """checkered_floor.yaml's floor, its collision groups set to ``groups``."""
    return textwrap.dedent(
        f"""\
            bodies:
            - BODY {name}
            joints: []
            high resolution path: ../../meshes/world/checkered_floor/high_res/
            low resolution path: ../../meshes/world/checkered_floor/low_res/
            ignore inter-collision: false
            namespace: /ambf/env/
            BODY {name}:
              name: {name}
              mesh: Plane.OBJ
              mass: {mass}
              collision margin: 0.001
              scale: 1.0
              location:
                position: {{x: 0.0, y: 0.0, z: {FLOOR_Z}}}
                orientation: {{r: 0.0, p: -0.0, y: 0.0}}
              inertial offset:
                position: {{x: 0.0, y: 0.0, z: 0.0}}
                orientation: {{r: 0, p: 0, y: 0}}
              friction: {{rolling: 0.1, static: 0.9}}
              restitution: 0.1
              damping: {{angular: 0.1, linear: 0.5}}
              collision shape: PLANE
              collision geometry:
                normal: {{x: 0.0, y: 0.0, z: 1.0}}
                offset: 0.0
              color components:
                diffuse: {{b: 0.8, g: 0.8, r: 0.8}}
                transparency: 1.0
            """
    ) + _groups_line(groups)


def _boxes(z: float = FLOOR_Z + 0.15) -> str:
    text = f"bodies: [{', '.join('BODY ' + b for b in BOXES)}]\njoints: []\nnamespace: /ambf/env/\n"
    for i, (b, groups) in enumerate(BOXES.items()):
        text += (
            f"BODY {b}:\n  name: {b}\n  mass: 1.0\n  inertia: {{ix: 0.01, iy: 0.01, iz: 0.01}}\n"
            f"  location: {{position: {{x: {0.5 * i}, y: 0.0, z: {z}}}, orientation: {{r: 0, p: 0, y: 0}}}}\n"
            "  collision shape: BOX\n  collision geometry: {x: 0.2, y: 0.2, z: 0.2}\n" + _groups_line(groups)
        )
    return text


def _scene(tmp_path, floor_text: str, boxes_text: str | None = None):
    """AMBF's layout: descriptions/launch.yaml, world/world.yaml whose environment is the
    floor, the floor's mesh under meshes/world/checkered_floor/."""
    d = tmp_path / "descriptions"
    (d / "world").mkdir(parents=True)
    for res in ("high_res", "low_res"):
        mesh = tmp_path / "meshes" / "world" / "checkered_floor" / res
        mesh.mkdir(parents=True)
        (mesh / "Plane.OBJ").write_text("v -5 -5 0\nv 5 -5 0\nv 5 5 0\nv -5 5 0\nf 1 2 3\nf 1 3 4\n")
    (d / "world" / "checkered_floor.yaml").write_text(floor_text)
    (d / "world" / "world.yaml").write_text(
        'environment: "./checkered_floor.yaml"\nnamespace: /ambf/env/\ngravity: {x: 0.0, y: 0.0, z: -9.81}\n'
    )
    (d / "boxes.yaml").write_text(boxes_text if boxes_text is not None else _boxes())
    (d / "launch.yaml").write_text("world config: ./world/world.yaml\nmultibody configs:\n  - ./boxes.yaml\n")
    return load_scene(d / "launch.yaml", [0])


def _play(scene, engine: str, seconds: float = 0.4):
    world = open_world(scene, Options(visuals=False), engine=engine)
    try:
        world.run(seconds)
        z = {sb.name: float(sb.world_matrix()[2, 3]) for sb in world.bodies if not sb.static}
        return z, world.report(), [d for d in world.diagnostics]
    finally:
        world.close()


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("groups", list(AMBF_HOLDS), ids=lambda g: f"floor-groups-{g}")
def test_ambf_floor_holds_the_bodies_ambf_holds(tmp_path, engine, groups):
    z, report, diags = _play(_scene(tmp_path, _floor(groups)), engine)
    held = {b for b, h in z.items() if h == pytest.approx(FLOOR_Z + 0.1, abs=2e-3)}
    assert held == AMBF_HOLDS[groups], z
    fell = set(BOXES) - held
    assert all(z[b] < FLOOR_Z - 0.3 for b in fell), z  # through the floor, not stuck in it
    assert sorted(k.rsplit(" ", 1)[1] for k in report["fell_through_floor"]) == sorted(fell)
    assert report["exploded"] == report["nan"] == report["not_played"] == []
    named = [d for d in diags if d.rule == "runner-floor-groups"]
    if fell:  # the floor's groups, where they are written, with every body they let through
        (d,) = named
        line = _floor(groups).splitlines().index(f"  collision groups: {groups}") + 1
        assert d.location.file.endswith("checkered_floor.yaml") and d.location.line == line
        assert all(f"BODY {b}" in d.message for b in fell) and "as in AMBF" in d.message
    else:
        assert named == []
    assert [d for d in diags if d.rule not in ("runner-floor-groups",)] == []


@pytest.mark.parametrize("engine", ENGINES)
def test_a_world_body_plane_meets_every_group(tmp_path, engine):
    """A floor that is ADF's world stand-in (BODY world: its shapes are MJCF's worldbody) meets
    bodies of every group; the MuJoCo engine gave the worldbody's shapes MuJoCo's default bit,
    which met one group only."""
    floor = _floor(None, name="world").replace(f"z: {FLOOR_Z}}}", "z: 0.0}")
    boxes = _boxes(z=0.15)
    z, _, diags = _play(_scene(tmp_path, floor, boxes), engine)
    assert z == pytest.approx(dict.fromkeys(BOXES, 0.1), abs=2e-3)
    assert diags == []


@pytest.mark.parametrize("engine", ENGINES)
def test_a_plane_on_a_dynamic_body_is_made_static_in_both_engines(tmp_path, engine):
    z, _, diags = _play(_scene(tmp_path, _floor("[]", mass=2.0)), engine)
    assert z == pytest.approx(dict.fromkeys(BOXES, FLOOR_Z + 0.1), abs=2e-3)
    (d,) = diags
    assert d.rule == "runner-plane" and "BODY Plane" in d.message and "made static" in d.message
    assert d.location.file.endswith("checkered_floor.yaml")


def test_mujoco_names_a_plane_it_cannot_collide_with(tmp_path):
    """A PLANE on a body that moves on a joint: MuJoCo collides planes only on static bodies,
    so the engine plays the body without it, says so where the shape is written and lists it
    as not played (the PyBullet runner plays it)."""
    model = """\
bodies: [BODY base, BODY arm]
joints: [JOINT base-arm]
BODY base:
  name: base
  mass: 0.0
  location: {position: {x: 0, y: 0, z: 0}, orientation: {r: 0, p: 0, y: 0}}
  collision shape: BOX
  collision geometry: {x: 0.1, y: 0.1, z: 0.1}
BODY arm:
  name: arm
  mass: 1.0
  inertia: {ix: 0.01, iy: 0.01, iz: 0.01}
  location: {position: {x: 0, y: 0, z: 0.5}, orientation: {r: 0, p: 0, y: 0}}
  collision shape: PLANE
  collision geometry: {normal: {x: 0, y: 0, z: 1}, offset: 0}
JOINT base-arm:
  name: base-arm
  parent: BODY base
  child: BODY arm
  type: revolute
  parent pivot: {x: 0, y: 0, z: 0.5}
  child pivot: {x: 0, y: 0, z: 0}
  parent axis: {x: 0, y: 1, z: 0}
  child axis: {x: 0, y: 1, z: 0}
"""
    p = tmp_path / "arm.yaml"
    p.write_text(model)
    world = open_world(load_scene(p), Options(visuals=False), engine="mujoco")
    try:
        world.run(0.05)
        report = world.report()
        diags = [d for d in world.diagnostics if d.rule == "runner-shape-left-out"]
    finally:
        world.close()
    (d,) = diags
    assert "BODY arm" in d.message and "plane" in d.message and d.location.line == 14
    assert report["not_played"] == [
        {
            "object": "BODY arm",
            "what": "collision plane",
            "why": "MuJoCo collides a plane only on a static body: left out",
        }
    ]


def test_mjcf_writes_ambf_floor_as_a_plane(tmp_path):
    """checkered_floor.yaml converts to a static MJCF plane where the file puts it (a plane
    tilted by its normal and moved by its offset too), no 'no such primitive' loss."""
    scene = _scene(tmp_path, _floor("[]"))
    text, losses = to_mjcf(scene.environment, tmp_path, "floor")
    assert 'type="plane"' in text and "freejoint" not in text
    assert not [loss for loss in losses if loss.feature == "collision plane"]
    import mujoco

    tilted = _floor("[]").replace("normal: {x: 0.0, y: 0.0, z: 1.0}", "normal: {x: 0.0, y: 1.0, z: 1.0}")
    tilted = tilted.replace("offset: 0.0", "offset: 0.5")
    (tmp_path / "descriptions" / "world" / "checkered_floor.yaml").write_text(tilted)
    m = load_scene(tmp_path / "descriptions" / "world" / "checkered_floor.yaml").models[0]
    out = tmp_path / "descriptions" / "world" / "tilted.xml"
    out.write_text(to_mjcf(m, out.parent, "tilted")[0])
    model = mujoco.MjModel.from_xml_path(str(out))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    g = next(i for i in range(model.ngeom) if model.geom_type[i] == mujoco.mjtGeom.mjGEOM_PLANE)
    normal = data.geom_xmat[g].reshape(3, 3)[:, 2]
    assert normal == pytest.approx([0.0, 2**-0.5, 2**-0.5], abs=1e-9)
    # the plane's point nearest the body origin is `offset` along the normal
    assert data.geom_xpos[g] == pytest.approx([0.0, 0.5 * 2**-0.5, FLOOR_Z + 0.5 * 2**-0.5], abs=1e-9)


@pytest.mark.parametrize("engine", ENGINES)
def test_more_collision_groups_than_bits_is_named(tmp_path, engine):
    names = [f"B{i}" for i in range(33)]
    text = f"bodies: [{', '.join('BODY ' + n for n in names)}]\n"
    for i, n in enumerate(names):
        text += (
            f"BODY {n}:\n  name: {n}\n  mass: 0.0\n"
            f"  location: {{position: {{x: {i}, y: 0, z: 0}}, orientation: {{r: 0, p: 0, y: 0}}}}\n"
            f"  collision shape: SPHERE\n  collision geometry: {{radius: 0.1}}\n  collision groups: [{i}]\n"
        )
    p = tmp_path / "many.yaml"
    p.write_text(text)
    world = open_world(load_scene(p), Options(visuals=False, ground=False), engine=engine)
    try:
        (d,) = [d for d in world.diagnostics if d.rule == "runner-groups"]
    finally:
        world.close()
    assert "33 collision groups" in d.message and "group 31 shares a bit with group 0" in d.message
    assert d.location.line == 3 + 7 * 31  # BODY B31 (its mapping), the first body of a group past the bits


@pytest.mark.parametrize("engine", ENGINES)
def test_a_cone_rests_on_the_floor_in_both_engines(tmp_path, engine):
    """MuJoCo has no cone: the MJCF writer gives it the 24-sided hull PyBullet collides, so
    it rests on its base (centre h/2 above the floor) instead of falling through."""
    cone = _boxes().split("BODY Bempty:")[0].replace("collision shape: BOX", "collision shape: CONE")
    cone = cone.replace(
        "collision geometry: {x: 0.2, y: 0.2, z: 0.2}", "collision geometry: {radius: 0.1, height: 0.3, axis: z}"
    )
    cone = cone.replace(", BODY Bempty, BODY B1, BODY B2, BODY B13", "")
    z, _, diags = _play(_scene(tmp_path, _floor("[]"), cone), engine, seconds=0.6)
    assert z == pytest.approx({"Bnone": FLOOR_Z + 0.15}, abs=2e-3)
    assert diags == []
