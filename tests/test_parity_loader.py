"""Loader parity: what AMBF 2.0's loader makes of a file (measured, through adfkit's AMBF
plugin) against what adfkit makes of it: `validate` refuses what AMBF refuses, the runner creates
what AMBF creates. Skips, with the reason, where no AMBF build (or no corpus) is present."""

from __future__ import annotations

import textwrap

import pytest
from conftest import CORPUS, corpus_files, corpus_id, require_corpus

pytest.importorskip("pybullet")

from adfkit.parity import ambf, loader  # noqa: E402

BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)


def _write(folder, name, text):
    p = folder / name
    p.write_text(textwrap.dedent(text).replace("BOX_SHAPES", BOX_SHAPES))
    return p


BOX_SHAPES = (
    "shape: BOX\n  geometry: {x: 0.1, y: 0.1, z: 0.1}\n"
    "  collision shape: BOX\n  collision geometry: {x: 0.1, y: 0.1, z: 0.1}"
)


@pytest.fixture
def ordered(tmp_path):
    """Model a: a ghost, a proximity sensor and a constraint actuator on `BODY x` of model b;
    model c: a body whose visual mesh is not there (a primitive collision shape all the same) and
    a joint naming it. Two launch files load them in either order."""
    _write(
        tmp_path,
        "a.yaml",
        """\
        ghost objects: [BODY g]
        sensors: [SENSOR s]
        actuators: [ACTUATOR act]
        namespace: /ambf/env/
        BODY g:
          name: g
          parent: BODY x
          BOX_SHAPES
        SENSOR s:
          name: s
          type: Proximity
          parent: BODY x
          range: 0.1
          array:
          - offset: {x: 0, y: 0, z: 0}
            direction: {x: 1, y: 0, z: 0}
        ACTUATOR act:
          name: act
          type: Constraint
          parent: BODY x
        """,
    )
    _write(
        tmp_path,
        "b.yaml",
        """\
        bodies: [BODY x]
        namespace: /ambf/env/
        BODY x:
          name: x
          mass: 0.0
          BOX_SHAPES
        """,
    )
    _write(
        tmp_path,
        "c.yaml",
        """\
        bodies: [BODY kept, BODY lost]
        joints: [JOINT kept-lost]
        namespace: /ambf/env/c/
        BODY kept:
          name: kept
          mass: 0.0
          BOX_SHAPES
        BODY lost:
          name: lost
          mesh: not_there.STL
          mass: 1.0
          inertia: {ix: 0.01, iy: 0.01, iz: 0.01}
          location: {position: {x: 0.5, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
          collision shape: BOX
          collision geometry: {x: 0.1, y: 0.1, z: 0.1}
        JOINT kept-lost:
          name: kept-lost
          parent: BODY kept
          child: BODY lost
          parent pivot: {x: 0.25, y: 0.0, z: 0.0}
          parent axis: {x: 0.0, y: 0.0, z: 1.0}
          child pivot: {x: -0.25, y: 0.0, z: 0.0}
          child axis: {x: 0.0, y: 0.0, z: 1.0}
          type: revolute
        """,
    )
    _write(tmp_path, "floor.yaml", "bodies: [BODY floor]\nBODY floor:\n  name: floor\n  mass: 0.0\n  BOX_SHAPES\n")
    _write(tmp_path, "world.yaml", "environment: floor.yaml\n")
    _write(tmp_path, "input_devices.yaml", "input devices: []\n")
    _write(tmp_path, "colors.yaml", "{}\n")
    # d.yaml: a joint without its axes, which AMBF refuses the whole file for
    _write(tmp_path, "d.yaml", (tmp_path / "c.yaml").read_text().replace("/ambf/env/c/", "/ambf/env/d/"))
    d = tmp_path / "d.yaml"
    d.write_text("\n".join(line for line in d.read_text().splitlines() if "axis" not in line) + "\n")
    for name, order in (
        ("before.yaml", "[a.yaml, b.yaml, c.yaml, d.yaml]"),
        ("after.yaml", "[b.yaml, a.yaml, c.yaml, d.yaml]"),
    ):
        _write(
            tmp_path,
            name,
            f"world config: world.yaml\ncolor config: colors.yaml\ninput devices config: input_devices.yaml\n"
            f"multibody configs: {order}\n",
        )
    return tmp_path


def test_a_verdict_needs_both_sides_to_agree():
    refused = loader.LoaderResult(CORPUS / "x.yaml", "model", "refuses", [])
    assert not refused.agree  # AMBF refuses, validate finds no error: a disagreement
    refused.validate_errors = ["yaml-syntax"]
    assert refused.agree
    loads = loader.LoaderResult(CORPUS / "y.yaml", "model", "loads", ["bad-value"])
    assert not loads.agree  # AMBF loads what validate calls an error
    loads.validate_errors = []
    loads.only_in_adfkit = [{"kind": "body", "name": "/ambf/env/b"}]
    assert not loads.agree
    loads.only_in_adfkit, loads.start_gap_m = [], 0.004  # a link starting on its joint: a figure
    assert loads.agree


@needs_ambf
def test_load_order_and_missing_visual_meshes_as_ambf(ordered):
    before = loader.check_file(ordered / "before.yaml", BUILD)
    after = loader.check_file(ordered / "after.yaml", BUILD)
    for r in (before, after):
        assert r.ambf == "loads" and r.agree, r.as_json()
        # AMBF refuses d.yaml (a joint without axes) and loads the rest; validate says why
        assert list(r.refused_models.values()) == [["schema-required"]]
        # the body without its visual mesh is not made, nor the joint naming it (measured in AMBF)
        assert r.ambf_counts["body"] == r.adfkit_counts["body"] == 3  # floor, x, kept
        assert r.ambf_counts["joint"] == r.adfkit_counts["joint"] == 0
        assert r.ambf_counts["ghost"] == 1  # a ghost finds a parent loaded after it
    # a sensor and an actuator are made only when their parent was loaded before them
    assert (before.ambf_counts["sensor"], before.ambf_counts["actuator"]) == (0, 0)
    assert (after.ambf_counts["sensor"], after.ambf_counts["actuator"]) == (1, 1)
    assert (before.adfkit_counts["sensor"], after.adfkit_counts["actuator"]) == (0, 1)


@needs_ambf
@pytest.mark.parametrize(
    "rel, ambf_does, rules",
    [
        (
            "ambf/ambf_models/descriptions/multi-bodies/robots/urdf-kuka.yaml",
            "refuses",
            ["enable-motor-without-feedback"],
        ),
        ("ambf/ambf_models/descriptions/multi-bodies/puzzles/compound_example.yaml", "refuses", ["yaml-syntax"]),
        ("ambf/ambf_models/descriptions/multi-bodies/robots/rover_car/rover_info.yaml", "loads", []),
        ("src/ADF/PSMs/LND_420006/psm1.yaml", "loads", []),  # its meshes are not in the corpus
        ("ambf/ambf_models/descriptions/multi-bodies/robots/blender-kuka.yaml", "loads", []),
    ],
)
def test_corpus_files_as_ambf_loads_them(rel, ambf_does, rules):
    require_corpus()
    r = loader.check_file(CORPUS / rel, BUILD)
    assert (r.ambf, r.validate_errors, r.agree) == (ambf_does, rules, True), r.as_json()
    if rel.endswith("blender-kuka.yaml"):
        assert r.ambf_counts["body"] == 8 and r.ambf_counts["joint"] == 7
        # its links start on their joints: the file's `r: -1.571` is not quite -π/2
        assert 1e-4 < r.start_gap_deg < 0.02 and r.start_gap_m < 1e-6
    if rel.endswith("LND_420006/psm1.yaml"):  # of its ten bodies only the mesh-less tool id is made
        assert r.ambf_counts["body"] == r.adfkit_counts["body"] == 1


@needs_ambf
@pytest.mark.slow
@pytest.mark.parametrize("path", corpus_files(), ids=corpus_id)
def test_every_corpus_file_loads_in_adfkit_as_in_ambf(path):
    r = loader.check_file(path, BUILD)
    assert r.agree, r.as_json()


TRIANGLE_VT = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"


def _one_mesh_model(folder, mesh_text):
    (folder / "m.obj").write_text(mesh_text)
    return _write(
        folder,
        "m.yaml",
        """\
        bodies: [BODY a]
        BODY a:
          name: a
          mesh: m.obj
          mass: 0.0
          collision shape: BOX
          collision geometry: {x: 0.1, y: 0.1, z: 0.1}
        """,
    )


def test_obj_faces_that_crash_ambf_are_an_error_and_adfkit_writes_none(tmp_path):
    from adfkit.geometry.meshwrite import obj_faces
    from adfkit.scenes.suturing.meshes import obj_text
    from adfkit.validator.engine import validate_file

    bad = _one_mesh_model(tmp_path, TRIANGLE_VT + "f 1/1 2/2 3/3\n")
    rules = [d.rule for d in validate_file(bad).diagnostics]
    assert rules == ["obj-faces-crash-ambf"]
    for good in ("f 1/1/1 2/2/1 3/3/1\n", "f 1 2 3\n", "f 1//1 2//1 3//1\n"):
        ok = _one_mesh_model(tmp_path, TRIANGLE_VT + "vn 0 0 1\n" + good)
        assert [d.rule for d in validate_file(ok).diagnostics] == [], good
    # adfkit's writers: every corner a full triplet, the normal at the vertex's own index
    _, faces = obj_faces([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [(0, 1, 2)], uvs=[[0, 0], [1, 0], [0, 1]])
    assert faces == ["f 1/1/1 2/2/2 3/3/3"]
    text = obj_text([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [(0, 1, 2)])
    assert "f 1//1 2//2 3//3" in text and "vn 0 0 1" in text


@needs_ambf
def test_ambf_crashes_on_texture_faces_without_normals_and_loads_the_sample_scene(tmp_path):
    from adfkit.diagnostics import AdfError

    with pytest.raises(AdfError, match="ambf-failed|stopped"):  # measured: chai3d's OBJ reader
        ambf.run(
            BUILD, ambf.write_stage(None, [_one_mesh_model(tmp_path, TRIANGLE_VT + "f 1/1 2/2 3/3\n")], None), 0.0, 0.0
        )
    rec = ambf.run(
        BUILD, ambf.write_stage(None, [_one_mesh_model(tmp_path, TRIANGLE_VT + "f 1 2 3\n")], None), 0.0, 0.0
    )
    assert [b["name"] for b in rec.created["bodies"]] == ["a"]
    from conftest import ROOT

    launch = ROOT / "sample_scenes" / "suturing" / "launch.yaml"
    rec = ambf.run(BUILD, ambf.Stage(launch, list(range(6))), 0.0, 0.0)
    counts = {k: len(v) for k, v in rec.created.items() if isinstance(v, list)}
    assert counts == {"bodies": 70, "soft_bodies": 0, "ghosts": 12, "joints": 56, "sensors": 2, "actuators": 2}


NULL_AND_ABSENT = """\
namespace: /ambf/env/
bodies: [BODY a, BODY null, BODY absent]
BODY a:
  name: a
  mass: 0.1
  BOX_SHAPES
BODY null:
"""


def test_a_body_listed_with_an_empty_mapping_is_not_made_and_one_without_a_mapping_is(tmp_path):
    # AMBF's loader skips an object whose node is null ("RIGID BODY ~ NODE IS NULL") and builds
    # one from an empty node for a listed key the file does not map (measured, below)
    from adfkit.adf import load_scene
    from adfkit.diagnostics import Severity
    from adfkit.runner import Options, open_world
    from adfkit.validator.engine import validate_file

    path = _write(tmp_path, "m.yaml", NULL_AND_ABSENT)
    res = validate_file(path)
    said = [d.message for d in res.diagnostics if d.rule == "undefined-object" and d.severity == Severity.WARNING]
    assert any("'BODY null'" in m and "mapping is empty; AMBF skips it" in m for m in said), said
    assert any("'BODY absent'" in m and "has no mapping" in m for m in said), said
    world = open_world(load_scene(path), Options(visuals=False, ground=False))
    try:
        assert sorted(b.key for b in world.bodies) == ["/ambf/env/BODY a", "/ambf/env/BODY absent"]
    finally:
        world.close()
    if BUILD is not None:
        r = loader.check_file(path, BUILD)
        assert r.ambf == "loads" and r.agree, r.as_json()
        assert r.ambf_counts["body"] == r.adfkit_counts["body"] == 2


def test_inertia_is_compared_within_one_percent_and_a_zero_moment_as_frozen():
    from adfkit.runner.ambf_bodies import FROZEN_INERTIA

    assert loader._same_inertia((1e-3, 2e-3, 3e-3), (1.004e-3, 2e-3, 3e-3))  # the PSM's mesh links: 0.5 %
    assert not loader._same_inertia((4.486e-3, 4.486e-3, 3.84e-4), (1.48e-2, 1.48e-2, 4.17e-4))
    assert loader._same_inertia((0.0, 1e-3, 1e-3), (FROZEN_INERTIA, 1e-3, 1e-3))  # AMBF never turns about x


@needs_ambf
def test_a_bodys_inertia_is_compared_with_ambfs(tmp_path):
    # a CONVEX_MESH body without `inertia`: AMBF's estimate and the runner's (since it grows the
    # mesh's bounds by Bullet's 0.04 m margin as AMBF's btConvexTriangleMeshShape keeps them)
    import trimesh

    trimesh.creation.box((0.1, 0.2, 0.3)).export(tmp_path / "block.stl")
    path = _write(
        tmp_path,
        "m.yaml",
        """\
        namespace: /ambf/env/
        bodies: [BODY block]
        BODY block:
          name: block
          mesh: block.stl
          collision mesh type: CONVEX_MESH
          mass: 2.0
        """,
    )
    r = loader.check_file(path, BUILD)
    assert r.ambf == "loads" and r.agree, r.as_json()
    assert not any("inertia" in d for d in r.differences)
