"""`adfkit run` and `validate` on odd input (issue 14): garbage and empty meshes are located
warnings (never a pybullet.error), a spring joint from a free body to a multibody link is built
(PyBullet's `createConstraint failed`), `--no-ground` has no floor to fall through, and every
JSON output is strict."""

from __future__ import annotations

import json
import math
import textwrap

import pytest

from adfkit import jsonout
from adfkit.diagnostics import Severity
from adfkit.validator import validate_file

pytest.importorskip("pybullet")

from adfkit.cli import main  # noqa: E402

BODY = """\
BODY {name}:
  name: {name}
  mass: {mass}
  inertia: {{ix: 1.0e-3, iy: 1.0e-3, iz: 1.0e-3}}
  location: {{position: {{x: {x}, y: 0.0, z: {z}}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
{shape}"""
SPHERE = "  collision shape: SPHERE\n  collision geometry: {radius: 0.05}\n"


def _body(name, mass=1.0, x=0.0, z=0.0, shape=SPHERE):
    return BODY.format(name=name, mass=mass, x=x, z=z, shape=shape)


def _strict(text: str):
    def refuse(const):
        raise ValueError(f"bare {const} in JSON")

    return json.loads(text, parse_constant=refuse)


BAD_MESHES = {
    "empty.stl": (b"solid x\nendsolid x\n", "holds no triangles"),
    "garbage.stl": (bytes(range(256)) + b"\x07" * 44, "not a valid STL file"),
    "nofaces.obj": (b"v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no faces"),
    "nothing.obj": (b"# nothing\n", "no vertices"),
}


@pytest.mark.parametrize("mesh", sorted(BAD_MESHES))
def test_run_and_validate_on_a_mesh_without_triangles(tmp_path, capsys, mesh):
    data, why = BAD_MESHES[mesh]
    (tmp_path / mesh).write_bytes(data)
    f = tmp_path / "m.yaml"
    f.write_text("bodies: [BODY a]\n" + _body("a", z=0.5, shape=f"  mesh: {mesh}\n"))
    found = [d for d in validate_file(f).diagnostics if d.rule == "mesh-unreadable"]
    assert len(found) == 1 and why in found[0].message
    assert (found[0].location.line, found[0].location.column, found[0].severity) == (7, 9, Severity.WARNING)
    rc = main(["run", str(f), "--seconds", "0.02", "--no-frames", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert rc == 0 and "Traceback" not in err
    assert f"{f}:7:9: warning[runner-bad-mesh]" in err and why in err
    assert _strict((tmp_path / "out" / "report.json").read_text())["bodies"] == 0


def test_sound_meshes_pass_the_mesh_check(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    from adfkit.geometry.meshcheck import mesh_problem

    box = trimesh.creation.box((1, 1, 1))
    box.export(tmp_path / "b.stl")
    (tmp_path / "a.stl").write_text(trimesh.exchange.stl.export_stl_ascii(box))
    box.export(tmp_path / "b.obj")
    for name in ("a.stl", "b.stl", "b.obj"):
        assert mesh_problem(tmp_path / name) is None, name


SPRING_MODEL = (
    "bodies: [BODY free, BODY base, BODY link]\njoints: [JOINT hinge, JOINT spring]\n"
    + _body("free", 0.5, x=0.0, z=1.0)
    + _body("base", 0.0, z=0.0)
    + _body("link", 0.5, z=0.5)
    + textwrap.dedent("""\
    JOINT hinge:
      name: hinge
      parent: BODY base
      child: BODY link
      type: revolute
      parent pivot: {x: 0, y: 0, z: 0.25}
      parent axis: {x: 1, y: 0, z: 0}
      child pivot: {x: 0, y: 0, z: -0.25}
      child axis: {x: 1, y: 0, z: 0}
    JOINT spring:
      name: spring
      parent: BODY free
      child: BODY link
      type: six dof spring
      parent pivot: {x: 0, y: 0, z: -0.25}
      parent axis: {x: 0, y: 0, z: 1}
      child pivot: {x: 0, y: 0, z: 0.25}
      child axis: {x: 0, y: 0, z: 1}
      joint limits:
        linear: {low: {x: 0, y: 0, z: 0}, high: {x: 0, y: 0, z: 0}}
        angular: {low: {x: 0, y: 0, z: -0.5}, high: {x: 0, y: 0, z: 0.5}}
      stiffness: {linear: {x: 0, y: 0, z: 0}, angular: {x: 0, y: 0, z: 1.0}}
      damping: {linear: {x: 0, y: 0, z: 0}, angular: {x: 0, y: 0, z: 0.01}}
    """)
)


def test_spring_from_a_free_body_to_a_multibody_link_is_built(tmp_path):
    """The class behind `createConstraint failed` on the springy PSM/ECM/MTM models: PyBullet
    joins a multibody link and a maximal-coordinate body only with the link as body A. (A six-dof
    spring: a limited torsion spring from the free body now joins the multibody, reversed.)"""
    from adfkit.adf.scene import load_scene
    from adfkit.runner import Options, open_world

    f = tmp_path / "springy.yaml"
    f.write_text(SPRING_MODEL)
    world = open_world(load_scene(f, None, []), Options())
    try:
        names = [c[0] for c in world.constraints]
        assert names == ["JOINT spring"]
        parent, child = world.constraints[0][2], world.constraints[0][3]
        assert parent.articulation is None and child.articulation is not None
        world.run(0.3)
        assert world.constraint_error() < 1e-3  # the pivots stay together
        assert not [d for d in world.diagnostics if d.rule == "runner-constraint"]
    finally:
        world.close()


def test_no_ground_reports_nothing_fell_through_a_floor(tmp_path):
    f = tmp_path / "m.yaml"
    f.write_text("bodies: [BODY base, BODY ball]\n" + _body("base", 0.0, z=0.0) + _body("ball", 1.0, x=1.0, z=0.0))
    out = tmp_path / "out"
    assert main(["run", str(f), "--seconds", "0.5", "--no-frames", "--no-ground", "--out", str(out)]) == 0
    rep = _strict((out / "report.json").read_text())
    assert rep["fell_through_floor"] == [] and rep["ground_plane_z"] is None


def test_json_output_is_strict_and_explains_its_nulls():
    text = jsonout.dumps({"a": math.nan, "b": [1.0, math.inf, {"c": -math.inf}], "d": "x"})
    assert _strict(text) == {"a": None, "b": [1.0, None, {"c": None}], "d": "x", "non_finite": ["a", "b[1]", "b[2].c"]}
    assert _strict(jsonout.dumps({"ok": 1.5})) == {"ok": 1.5}


def test_collision_primitive_missing_a_dimension_is_a_located_warning(tmp_path, capsys):
    f = tmp_path / "m.yaml"
    f.write_text(
        "bodies: [BODY a]\n"
        + _body("a", z=0.5, shape="  collision shape: BOX\n  collision geometry: {x: 0.1, y: 0.1}\n")
    )
    rc = main(["run", str(f), "--seconds", "0.02", "--no-frames"])
    err = capsys.readouterr().err
    assert rc in (0, 1) and "Traceback" not in err
    assert f"{f}:8:23: warning[runner-no-collision]: BODY a: collision box has no usable z" in err


def test_a_mesh_whose_texture_is_missing_is_one_located_warning_not_pybullets_noise(tmp_path, capfd):
    """The challenge's low-res phantom names its texture by an absolute path from its author's
    machine: PyBullet's OBJ reader printed seven lines on standard output for it (every folder it
    tried) each time it read the file. Now the visual mesh gets one located warning and the
    process's standard output (file descriptor 1) carries nothing of PyBullet's."""
    (tmp_path / "drape.mtl").write_text("newmtl drape\nKd 0.5 0.5 0.5\nmap_Kd /home/someone/drape.png\n")
    (tmp_path / "t.obj").write_text(
        "mtllib drape.mtl\nusemtl drape\nv 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
    )
    f = tmp_path / "m.yaml"
    f.write_text(
        "bodies: [BODY a, BODY b]\n"
        + _body("a", mass=0.0, shape="  mesh: t.obj\n  collision mesh type: CONCAVE_MESH\n")
        + _body("b", x=0.5, z=0.3, shape="  mesh: t.obj\n")
    )
    rc = main(["run", str(f), "--seconds", "0.02", "--no-frames", "--out", str(tmp_path / "out")])
    out, err = capfd.readouterr()
    assert rc == 0
    assert "b3Warning" not in out + err and "drape.png" not in out
    found = [ln for ln in err.splitlines() if "runner-missing-texture" in ln]
    assert len(found) == 2  # each body's visual mesh, at its `mesh` key
    assert all(ln.startswith(f"{f}:") and ":9: warning[runner-missing-texture]" in ln for ln in found)
    assert (
        "texture /home/someone/drape.png (in drape.mtl; an absolute path, from the machine the file was made on)"
        in found[0]
    )


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_body_whose_collision_mesh_is_missing_is_skipped_in_both_engines(tmp_path, capsys, engine):
    """AMBF does not create a body whose collision mesh file is missing (the corpus's sophie.yaml:
    its Body.STL is missing in the source repository itself). The MuJoCo engine made it anyway,
    without a collision shape, and the robot's legs fell with it; both engines skip it now, and
    the joints that name it, each with a located warning. The file is its visual mesh too, which
    AMBF loads first: the warning names that."""
    f = tmp_path / "m.yaml"
    f.write_text(
        "bodies: [BODY a, BODY b]\njoints: [JOINT a-b]\n"
        + _body("a", z=0.5, shape="  mesh: gone.stl\n")
        + _body("b", z=0.3)
        + "JOINT a-b:\n  name: a-b\n  parent: BODY a\n  child: BODY b\n  type: revolute\n"
        "  parent pivot: {x: 0, y: 0, z: -0.1}\n  child pivot: {x: 0, y: 0, z: 0.1}\n"
        "  parent axis: {x: 1, y: 0, z: 0}\n  child axis: {x: 1, y: 0, z: 0}\n"
    )
    rc = main(["run", str(f), "--seconds", "0.05", "--no-frames", "--engine", engine, "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    report = _strict((tmp_path / "out" / "report.json").read_text())
    assert rc == 0 and report["skipped_bodies"] == ["BODY a"] and report["bodies"] == 1
    assert f"{f}:8:9: warning[runner-missing-mesh]: BODY a: visual mesh" in err and "gone.stl not found" in err
    assert f"{f}:17:3: warning[runner-joint-body]: JOINT a-b: parent or child body not found; skipped" in err


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_the_floor_under_a_model_played_alone_meets_bodies_of_every_collision_group(tmp_path, engine):
    """The floor stands in for a world's, which has no collision groups: it meets every body.
    It met only the bodies of one group before (Bullet's static default: the second group;
    MuJoCo's default bit: the first), and sophie.yaml's legs fell through it in MuJoCo."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    text = "bodies: [BODY a, BODY b, BODY c]\n" + "".join(
        _body(n, x=x, z=z) + f"  collision groups: {g}\n"
        for n, x, z, g in (("a", 0.0, 0.0, "[0]"), ("b", 0.5, 0.2, "[3]"), ("c", 1.0, 0.3, "[3, 7]"))
    )
    f = tmp_path / "m.yaml"
    f.write_text(text)
    world = open_world(load_scene(f), Options(), engine=engine)
    try:
        world.run(1.5)
        floor = world.ground_z
        for n in "abc":
            z = world.body(f"BODY {n}").com_position()[2]
            assert z == pytest.approx(floor + 0.05, abs=2e-3), (n, z, floor)  # the 5 cm spheres rest on it
    finally:
        world.close()


def test_a_joint_between_two_static_bodies_reports_no_constraint_error(tmp_path):
    """A `fixed` joint between two static boxes 0.2 m apart holds nothing (nor does AMBF's): the
    report's constraint error was their 223.6 mm (pivots at each centre, 0.1 m up on the child)."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    bodies = BODY.format(name="a", mass=0.0, x=0.0, z=0.3, shape=SPHERE) + BODY.format(
        name="b", mass=0.0, x=0.2, z=0.3, shape=SPHERE
    )
    joint = (
        "JOINT j:\n  name: j\n  parent: BODY a\n  child: BODY b\n  type: fixed\n"
        "  parent pivot: {x: 0, y: 0, z: 0}\n  child pivot: {x: 0, y: 0, z: 0.1}\n"
        "  parent axis: {x: 0, y: 0, z: 1}\n  child axis: {x: 0, y: 0, z: 1}\n"
    )
    (tmp_path / "m.yaml").write_text("bodies: [BODY a, BODY b]\njoints: [JOINT j]\n" + bodies + joint)
    world = open_world(load_scene(tmp_path / "m.yaml", None, []), Options(visuals=False, ground=False))
    try:
        world.run(0.1)
        assert world.constraint_error() == 0.0
    finally:
        world.close()


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_collision_shape_ambf_does_not_know_is_said_by_both_engines(tmp_path, engine):
    # `collision shape: Ball` (AMBF: undefined behaviour, validate: an error): the PyBullet runner
    # said the body had no usable collision primitive, the MuJoCo engine said nothing
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    path = tmp_path / "ball.yaml"
    body = BODY.format(
        name="a", mass=1.0, x=0.0, z=0.2, shape="  collision shape: Ball\n  collision geometry: {radius: 0.1}\n"
    )
    path.write_text("bodies: [BODY a]\n" + body)
    w = open_world(load_scene(path), Options(visuals=False, ground=True), engine=engine)
    try:
        said = [d for d in w.diagnostics if d.rule == "runner-no-collision"]
        assert len(said) == 1 and said[0].location.line == 3, [str(d) for d in w.diagnostics]  # the body
    finally:
        w.close()
