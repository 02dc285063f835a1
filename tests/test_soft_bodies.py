"""Issue 16: soft bodies through the model, reader/writer, schema, validator, geometry,
runner and MJCF. Corpus tests (sb/cloth.yaml, cloth2.yaml) skip when the corpus is absent."""

from __future__ import annotations

import json
import shutil
import struct

import jsonschema
import numpy as np
import pytest
import yaml
from conftest import CORPUS, require_corpus, require_renderer

from adfkit.adf import dumps, read_file
from adfkit.adf.yamlnodes import compose, plain
from adfkit.adf_schema import load_schema
from adfkit.diagnostics import AdfError
from adfkit.geometry.softmesh import load_soft_mesh, read_3ds, unique_nodes, write_obj
from adfkit.model import ModelFile
from adfkit.model.objects import SoftBodyConfig
from adfkit.model.spec import adf_keys
from adfkit.validator import validate_file

SB = "ambf/ambf_models/descriptions/multi-bodies/sb/"
CLOTHS = ["cloth.yaml", "cloth2.yaml"]
# Every key AMBF 2.0's loader reads inside `config:` (ADFLoader_1_0::loadSoftBodyAttribs),
# less `cutting`, which it reads into a node and never uses.
AMBF_CONFIG_KEYS = {
    "kLST",
    "kAST",
    "kVST",
    "kVCF",
    "kDP",
    "kDG",
    "kLF",
    "kPR",
    "kVC",
    "kDF",
    "kMT",
    "kCHR",
    "kKHR",
    "kSHR",
    "kAHR",
    "kSRHR_CL",
    "kSKHR_CL",
    "kSSHR_CL",
    "kSR_SPLT_CL",
    "kSK_SPLT_CL",
    "kSS_SPLT_CL",
    "maxvolume",
    "timescale",
    "viterations",
    "piterations",
    "diterations",
    "citerations",
    "flags",
    "bending constraint",
    "clusters",
    "fixed nodes",
}


def _cloth(name: str):
    require_corpus()
    return CORPUS / SB / name


# --- model, reader, writer -------------------------------------------------------------------


@pytest.mark.parametrize("name", CLOTHS)
def test_corpus_cloth_reads_every_soft_body_key(name):
    doc, _ = read_file(_cloth(name))
    assert isinstance(doc, ModelFile)
    (sb,) = doc.soft_bodies
    assert (sb.identifier, sb.name, sb.mesh, sb.mass, sb.scale) == ("BODY Cloth", "cloth", "cloth.3DS", 1.0, 1.0)
    cfg = sb.config
    assert (cfg.kLST, cfg.kDP, cfg.piterations, cfg.bending_constraint, cfg.flags, cfg.fixed_nodes) == (
        0.005,
        0.001,
        6,
        2,
        16,
        [0],
    )
    assert sb.randomize_constraints is True
    # AMBF keeps the first of the duplicated `collision margin`; `margin` is not read by AMBF
    assert sb.collision_margin == {"cloth.yaml": 0.001, "cloth2.yaml": 0.1}[name]
    assert cfg.extras == {"margin": {"cloth.yaml": 0.01, "cloth2.yaml": 0.5}[name]}
    assert sb.location.position.y == {"cloth.yaml": 2.0, "cloth2.yaml": -0.5}[name]


@pytest.mark.parametrize("name", CLOTHS)
def test_corpus_cloth_round_trips_byte_stable_with_every_key(name, tmp_path):
    path = _cloth(name)
    doc, _ = read_file(path)
    text = dumps(doc)
    out = tmp_path / name
    out.write_text(text)
    again, _ = read_file(out)
    assert dumps(again) == text  # byte-stable
    original = plain(compose(path.read_text(), str(path), []))  # AMBF's first-wins reading
    written = yaml.safe_load(text)
    assert written["soft bodies"] == ["BODY Cloth"]
    orig_sb, new_sb = original["BODY Cloth"], written["BODY Cloth"]
    assert set(orig_sb) == set(new_sb)  # every key of the soft body kept
    assert orig_sb["config"] == new_sb["config"]  # config values exactly, margin included
    assert new_sb["collision margin"] == orig_sb["collision margin"]
    assert new_sb["randomize constraints"] is True


def test_model_declares_every_config_key_ambf_reads():
    assert adf_keys(SoftBodyConfig) == AMBF_CONFIG_KEYS


def test_soft_body_written_from_the_model_reads_back(tmp_path):
    from adfkit.model.objects import SoftBody

    m = ModelFile()
    m.soft_bodies.append(
        SoftBody(
            identifier="SOFT pad",
            name="pad",
            mesh="pad.obj",
            mass=0.2,
            config=SoftBodyConfig(
                kLST=0.4,
                kAST=0.3,
                kVST=0.2,
                kDF=0.6,
                kDP=0.05,
                piterations=8,
                clusters=4,
                bending_constraint=2,
                fixed_nodes=[0, 3, 7],
            ),
            randomize_constraints=True,
            collision_margin=0.002,
        )
    )
    text = dumps(m)
    p = tmp_path / "pad.yaml"
    p.write_text(text)
    back, diags = read_file(p)
    assert [d for d in diags if d.severity >= 2] == []
    assert back.soft_bodies[0].config == m.soft_bodies[0].config
    assert back.soft_bodies[0].mass == 0.2 and back.soft_bodies[0].collision_margin == 0.002
    assert dumps(back) == text


# --- schema ------------------------------------------------------------------------------------


def test_schema_lists_every_soft_body_config_key():
    schema = load_schema("model")
    props = schema["$defs"]["SoftBodyConfig"]["properties"]
    assert set(props) == AMBF_CONFIG_KEYS
    assert props["kLST"]["default"] == 1 and props["piterations"]["default"] == 1
    assert props["fixed nodes"]["type"] == "array"


@pytest.mark.parametrize("name", CLOTHS)
def test_schema_accepts_the_corpus_cloth_and_rejects_a_bad_config(name):
    schema = load_schema("model")
    data = yaml.safe_load(_cloth(name).read_text())
    jsonschema.validate(data, schema)
    data["BODY Cloth"]["config"]["fixed nodes"] = "zero"
    sub = {"type": "object", "$defs": schema["$defs"], "properties": {"b": {"$ref": "#/$defs/SoftBody"}}}
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate({"b": data["BODY Cloth"]}, sub)


# --- geometry: the nodes AMBF makes of a mesh -------------------------------------------------------


def test_corpus_cloth_mesh_has_386_unique_nodes():
    mesh = load_soft_mesh(_cloth("cloth.yaml").parent / "low_res" / "cloth.3DS")
    raw_v, raw_f = read_3ds(_cloth("cloth.yaml").parent / "low_res" / "cloth.3DS")
    assert (len(raw_v), len(raw_f)) == (486, 768)
    assert (mesh.node_count, len(mesh.triangles)) == (386, 768)
    np.testing.assert_allclose(mesh.nodes.max(axis=0)[:2], [0.38972265, 0.67708838], atol=1e-7)
    np.testing.assert_allclose(mesh.nodes[0], [0.38972265, 0.67708838, 0.0], atol=1e-7)  # a corner


def _tiny_3ds(path, verts, faces):
    vchunk = struct.pack("<HIH", 0x4110, 6 + 2 + 12 * len(verts), len(verts)) + np.asarray(verts, "<f4").tobytes()
    f4 = np.hstack([np.asarray(faces), np.zeros((len(faces), 1), int)]).astype("<u2").tobytes()
    fchunk = struct.pack("<HIH", 0x4120, 6 + 2 + len(f4), len(faces)) + f4
    tri = struct.pack("<HI", 0x4100, 6 + len(vchunk) + len(fchunk)) + vchunk + fchunk
    obj = struct.pack("<HI", 0x4000, 6 + 3 + len(tri)) + b"sq\0" + tri
    ed = struct.pack("<HI", 0x3D3D, 6 + len(obj)) + obj
    path.write_bytes(struct.pack("<HI", 0x4D4D, 6 + len(ed)) + ed)


def test_3ds_reader_and_node_merge_on_a_written_square(tmp_path):
    # two triangles of a unit square with the shared edge's vertices repeated (6 -> 4 nodes)
    verts = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 0, 0), (1, 1, 0), (0, 1, 0)]
    _tiny_3ds(tmp_path / "sq.3ds", verts, [(0, 1, 2), (3, 4, 5)])
    mesh = load_soft_mesh(tmp_path / "sq.3ds", scale=2.0)
    assert mesh.node_count == 4
    np.testing.assert_allclose(mesh.nodes, [(0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 2, 0)])
    assert mesh.triangles.tolist() == [[0, 1, 2], [0, 2, 3]]
    obj = write_obj(mesh, tmp_path / "sq.obj").read_text().split("\n")
    assert obj[0] == "v 0 0 0" and obj[4] == "f 1 2 3"
    (tmp_path / "bad.3ds").write_bytes(b"MM\x01\x00\x00\x00")
    with pytest.raises(AdfError) as info:
        load_soft_mesh(tmp_path / "bad.3ds")
    assert info.value.diagnostics[0].rule in ("mesh-unreadable", "mesh-empty")


def test_nodes_at_maps_editor_vertices_to_fixed_nodes():
    from adfkit.geometry.softmesh import nodes_at

    v = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 0, 0), (1, 1, 0), (0, 1, 0)], float)
    mesh = unique_nodes(v, np.array([(0, 1, 2), (3, 4, 5)]))
    # a vertex group holding the repeated corner twice and the last vertex: nodes 0 and 3
    assert nodes_at(mesh, [v[3], v[0], v[5]]) == [0, 3]
    with pytest.raises(ValueError, match="no node at"):
        nodes_at(mesh, [(0.5, 0.5, 0.0)])


def test_unique_nodes_drops_collapsed_triangles():
    v = np.array([(0, 0, 0), (1, 0, 0), (1, 0, 0), (0, 1, 0)], float)
    m = unique_nodes(v, np.array([(0, 1, 2), (0, 2, 3)]))
    assert m.node_count == 3 and m.triangles.tolist() == [[0, 1, 2]]


# --- validator ------------------------------------------------------------------------------------

SOFT = """soft bodies: [SOFT s]
SOFT s:
  name: s
  mesh: {mesh}
  mass: {mass}
  config: {{kLST: {klst}, kDF: 0.5, piterations: {pit}, bending constraint: {bend}, fixed nodes: {fixed}}}
"""


def _findings(tmp_path, mesh="sq.3ds", mass="0.1", klst="0.5", pit="4", bend="2", fixed="[0, 3]"):
    _tiny_3ds(tmp_path / "sq.3ds", [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [(0, 1, 2), (0, 2, 3)])
    f = tmp_path / "soft.yaml"
    f.write_text(SOFT.format(mesh=mesh, mass=mass, klst=klst, pit=pit, bend=bend, fixed=fixed))
    return [(d.rule, d.location.line, str(d.severity)) for d in validate_file(f).diagnostics]


def test_clean_soft_body_has_no_findings(tmp_path):
    """Only the note every soft body gets: in AMBF rigid bodies pass through it (measured: a
    capsule needle and an 8 mm sphere dropped on the soft_phantom sample's skin fell through it
    onto the tray beneath, with the file's collision flags and with CL_RS and 32 clusters)."""
    assert _findings(tmp_path) == [("rigid-through-soft-body", 3, "info")]


@pytest.mark.parametrize(
    "change, expected",
    [
        (dict(mesh="''"), ("soft-body-mesh", 4, "warning")),
        (dict(mass="0.0"), ("soft-body-mass", 5, "warning")),
        (dict(klst="1.5"), ("soft-body-coefficient", 6, "warning")),
        (dict(pit="0"), ("soft-body-iterations", 6, "warning")),
        (dict(bend="1"), ("soft-body-iterations", 6, "warning")),
        (dict(fixed="[0, 4]"), ("soft-body-fixed-nodes", 6, "error")),
        (dict(fixed="[-1]"), ("soft-body-fixed-nodes", 6, "error")),
    ],
)
def test_soft_body_rules(tmp_path, change, expected):
    assert expected in _findings(tmp_path, **change)


def test_fixed_nodes_rule_on_the_corpus_cloth(tmp_path):
    text = _cloth("cloth2.yaml").read_text().replace("fixed nodes: [0]", "fixed nodes: [0, 385, 386]")
    # a copy, not a symlink: a link out of the scene's tree is not followed (adfkit.inputs)
    shutil.copytree(_cloth("cloth2.yaml").parent / "low_res", tmp_path / "low_res")
    f = tmp_path / "cloth.yaml"
    f.write_text(text)
    hits = [d for d in validate_file(f).diagnostics if d.rule == "soft-body-fixed-nodes"]
    assert len(hits) == 1 and "386 outside the 386 nodes of cloth.3DS" in hits[0].message
    assert not [d for d in validate_file(_cloth("cloth2.yaml")).diagnostics if d.rule.startswith("soft-body")]


# --- runner: PyBullet's deformable world ------------------------------------------------------------

pb = pytest.importorskip("pybullet", reason="pybullet (sim extra) is not installed")
from adfkit.adf import load_scene  # noqa: E402
from adfkit.cli import main  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402

BOX_UNDER_CLOTH = """bodies: [BODY table]
BODY table:
  name: table
  mass: 0.0
  location: {position: {x: 0.0, y: 2.0, z: -0.35}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision shape: BOX
  collision geometry: {x: 0.4, y: 0.4, z: 0.5}
  shape: BOX
  geometry: {x: 0.4, y: 0.4, z: 0.5}
"""


def _world(path, seconds: float, **opt):
    world = open_world(load_scene(path, None, []), Options(visuals=False, **opt))
    world.run(seconds)
    return world


def test_corpus_cloth_falls_and_drapes_on_a_box(tmp_path, monkeypatch):
    """cloth.yaml (386 nodes, hung from node 0) over a 0.4 m box whose top is 0.1 m below it."""
    monkeypatch.setenv("ADFKIT_INPUT_ROOT", "/")  # the launch in tmp names the corpus file by path
    cloth = _cloth("cloth.yaml")
    (tmp_path / "box.yaml").write_text(BOX_UNDER_CLOTH)
    (tmp_path / "launch.yaml").write_text(f"multibody configs:\n  - {cloth}\n  - box.yaml\n")
    world = _world(tmp_path / "launch.yaml", 1.0)
    try:
        (soft,) = world.soft.items
        nodes = soft.nodes(world.cid)
        rep = world.report()
    finally:
        world.close()
    assert (soft.node_count, soft.triangles, soft.fixed) == (386, 768, [0])
    (row,) = rep["soft_bodies"]
    assert (row["name"], row["nodes"], row["fixed_nodes"]) == ("/ambf/env/BODY Cloth", 386, 1)
    assert rep["nan"] == rep["exploded"] == rep["fell_through_floor"] == []
    assert np.all(np.isfinite(nodes))
    np.testing.assert_allclose(nodes[0], [0.38972265, 2.67708838, 0.0], atol=1e-6)  # the anchored corner
    top = -0.1
    on_box = (np.abs(nodes[:, 0]) < 0.2) & (np.abs(nodes[:, 1] - 2.0) < 0.2)
    assert on_box.sum() >= 10
    # over the box the cloth is held up by it (tensioned towards the corner pinned 0.1 m above
    # the top); everywhere else it hangs far lower, over the box's sides
    assert nodes[on_box, 2].min() > top - 0.005, nodes[on_box, 2]
    assert nodes[on_box, 2].max() < -0.02
    assert nodes[~on_box, 2].min() < top - 0.3
    assert row["size_m"] < 1.5 * row["rest_size_m"]  # stretched, not exploded


@pytest.mark.slow
@pytest.mark.parametrize("name", CLOTHS)
def test_corpus_cloth_plays_5_seconds_on_a_box(name, tmp_path, monkeypatch):
    monkeypatch.setenv("ADFKIT_INPUT_ROOT", "/")  # the launch in tmp names the corpus file by path
    cloth = _cloth(name)
    y = {"cloth.yaml": 2.0, "cloth2.yaml": -0.5}[name]
    (tmp_path / "box.yaml").write_text(BOX_UNDER_CLOTH.replace("y: 2.0", f"y: {y}"))
    (tmp_path / "launch.yaml").write_text(f"multibody configs:\n  - {cloth}\n  - box.yaml\n")
    world = _world(tmp_path / "launch.yaml", 5.0)
    try:
        rep = world.report()
        nodes = world.soft.items[0].nodes(world.cid)
    finally:
        world.close()
    assert rep["nan"] == rep["exploded"] == rep["fell_through_floor"] == []
    on_box = (np.abs(nodes[:, 0]) < 0.2) & (np.abs(nodes[:, 1] - y) < 0.2)
    # held up by the box top (z = -0.1): cloth2's 0.1 m collision margin holds it higher still
    assert on_box.sum() >= 10 and nodes[on_box, 2].min() > -0.1 - 0.005


def test_adfkit_run_plays_corpus_cloth2_and_reports_it(tmp_path, capsys):
    rc = main(["run", str(_cloth("cloth2.yaml")), "--seconds", "0.2", "--out", str(tmp_path), "--no-frames"])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert "warning[yaml-duplicate-key]" in err and "runner-soft-body-approx" in err
    import json

    rep = json.loads((tmp_path / "report.json").read_text())
    (row,) = rep["soft_bodies"]
    assert (row["nodes"], row["triangles"], row["fixed_nodes"]) == (386, 768, 1)
    assert row["not_played"] == ["randomize constraints"]
    assert rep["nan"] == rep["exploded"] == []


SHEET = """bodies: [BODY hook, BODY weight]
soft bodies: [SOFT sheet]
joints: [JOINT sheet-weight]
BODY hook:
  name: hook
  mass: 0.0
  location: {{position: {{x: 0.0, y: 0.0, z: 1.0}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
  collision shape: SPHERE
  collision geometry: {{radius: 0.005}}
BODY weight:
  name: weight
  mass: 0.05
  inertia: {{ix: 1.0e-5, iy: 1.0e-5, iz: 1.0e-5}}
  location: {{position: {{x: 0.1, y: 0.1, z: 1.0}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
  collision shape: SPHERE
  collision geometry: {{radius: 0.005}}
SOFT sheet:
  name: sheet
  mesh: sheet.obj
  mass: 0.02
  collision margin: 0.002
  location: {{position: {{x: 0.0, y: 0.0, z: 1.0}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
  config: {{kLST: 0.5, piterations: 4, kDP: 0.5, kAST: 0.3, clusters: 2, fixed nodes: [0]}}
JOINT sheet-weight:
  name: sheet-weight
  parent: SOFT sheet
  child: BODY weight
  type: fixed
  parent pivot: {{x: 0.1, y: 0.1, z: 0.0}}
  child pivot: {{x: 0.0, y: 0.0, z: 0.0}}
  parent axis: {{x: 0.0, y: 0.0, z: 1.0}}
  child axis: {{x: 0.0, y: 0.0, z: 1.0}}
"""


def test_soft_rigid_attachment_and_parameter_mapping(tmp_path):
    """A 0.1 m sheet pinned at node 0 carries a 50 g weight joined to its far corner."""
    from adfkit.scenes.soft_phantom import grid_obj

    # grid_obj is centred; shift it so node 0 is at the origin and node 24 at (0.1, 0.1)
    text = grid_obj(0.1, 4).splitlines()
    shifted = [
        f"v {float(l.split()[1]) + 0.05:.6f} {float(l.split()[2]) + 0.05:.6f} 0.0" if l.startswith("v ") else l
        for l in text
    ]
    (tmp_path / "sheet.obj").write_text("\n".join(shifted) + "\n")
    (tmp_path / "sheet.yaml").write_text(SHEET.format())
    world = _world(tmp_path / "sheet.yaml", 0.6, ground=False)
    try:
        (soft,) = world.soft.items
        nodes = soft.nodes(world.cid)
        weight = np.array(world.body("weight").com_position())
        rules = {d.rule: d.message for d in world.diagnostics}
        rep = world.report()
    finally:
        world.close()
    assert soft.attached == {"BODY weight": [24]}
    assert world.joint_names == []  # the joint became an anchor, not a rigid joint
    np.testing.assert_allclose(nodes[0], [0.0, 0.0, 1.0], atol=1e-6)
    assert np.linalg.norm(nodes[24] - weight) < 0.01  # the weight hangs on its node
    assert 0.8 < weight[2] < 0.99  # held up by the sheet, not falling freely
    assert "config.kAST, config.clusters not played" in rules["runner-soft-body-approx"]
    p = soft.params
    m_node = 0.02 / 25
    assert p["springElasticStiffness"] == pytest.approx(min(1 - 0.5**4, 0.4) * m_node / 1e-6)
    assert p["springDampingStiffness"] == pytest.approx(0.5 * m_node / 1e-3)
    assert (p["collisionMargin"], p["frictionCoeff"], p["useBendingSprings"]) == (0.002, 0.2, 0)
    assert rep["soft_bodies"][0]["attached_nodes"] == {"BODY weight": 1}


def test_soft_rigid_attachment_in_the_mujoco_engine(tmp_path):
    """The same sheet and weight in MuJoCo: the joint holds node 24 to the weight (a connect
    equality), node 0 stays pinned, and the sheet carries the weight as in PyBullet."""
    from adfkit.adf import load_scene
    from adfkit.scenes.soft_phantom import grid_obj

    text = grid_obj(0.1, 4).splitlines()
    shifted = [
        f"v {float(l.split()[1]) + 0.05:.6f} {float(l.split()[2]) + 0.05:.6f} 0.0" if l.startswith("v ") else l
        for l in text
    ]
    (tmp_path / "sheet.obj").write_text("\n".join(shifted) + "\n")
    (tmp_path / "sheet.yaml").write_text(SHEET.format())
    world = open_world(load_scene(tmp_path / "sheet.yaml"), Options(visuals=False, ground=False), engine="mujoco")
    try:
        world.run(0.6)
        (soft,) = world.soft.items
        nodes = soft.nodes()
        weight = np.array(world.body("weight").com_position())
        rules = {d.rule: d.message for d in world.diagnostics}
        rep = world.report()
    finally:
        world.close()
    assert soft.attached == {"BODY weight": [24]}
    np.testing.assert_allclose(nodes[0], [0.0, 0.0, 1.0], atol=1e-6)
    # the weight hangs on its node (measured 0.8 mm; MuJoCo's default equality softness: 13 mm)
    assert np.linalg.norm(nodes[24] - weight) < 0.002
    assert 0.8 < weight[2] < 0.99  # held up by the sheet, not falling freely (PyBullet: 0.868, MuJoCo 0.856)
    assert "config.kAST" in rules["runner-soft-body-approx"]
    assert rep["soft_bodies"][0]["attached_nodes"] == {"BODY weight": 1} and rep["nan"] == []


def test_plane_beside_a_soft_body_is_warned_and_the_default_floor_is_a_slab(tmp_path):
    (tmp_path / "sq.obj").write_text("v 0 0 0\nv 0.1 0 0\nv 0.1 0.1 0\nv 0 0.1 0\nf 1 2 3\nf 1 3 4\n")
    soft = "SOFT s:\n  name: s\n  mesh: sq.obj\n  mass: 0.01\n"
    (tmp_path / "plane.yaml").write_text(
        "bodies: [BODY floor]\nsoft bodies: [SOFT s]\nBODY floor:\n  name: floor\n  mass: 0.0\n"
        "  location: {position: {x: 0, y: 0, z: -0.5}, orientation: {r: 0, p: 0, y: 0}}\n"
        "  collision shape: PLANE\n  collision geometry: {normal: {x: 0, y: 0, z: 1}, offset: 0}\n" + soft
    )
    world = _world(tmp_path / "plane.yaml", 0.0)
    try:
        assert "runner-soft-plane" in {d.rule for d in world.diagnostics}
    finally:
        world.close()
    (tmp_path / "alone.yaml").write_text(
        "soft bodies: [SOFT s]\n"
        + soft.replace("mesh", "location: {position: {x: 0, y: 0, z: 0.3}, orientation: {r: 0, p: 0, y: 0}}\n  mesh")
    )
    world = _world(tmp_path / "alone.yaml", 0.5)
    try:
        z = world.soft.items[0].nodes(world.cid)[:, 2]
        assert world.ground_z == pytest.approx(0.299)  # 1 mm under the sheet, as for rigid bodies
        assert np.all(np.abs(z - 0.3) < 0.003), z  # resting on it, not centimetres above
    finally:
        world.close()


# --- the soft phantom sample scene -------------------------------------------------------------------


def _skin_under_tool(launch, seconds, tool="Probe"):
    world = _world(launch, seconds)
    try:
        (skin,) = world.soft.items
        nodes = skin.nodes(world.cid)
        rep = world.report()
        at = world.body(tool).com_position() if any(tool in k for k in world.registry.items) else None
    finally:
        world.close()
    assert rep["nan"] == rep["exploded"] == rep["fell_through_floor"] == []
    return nodes, at


@pytest.fixture(scope="module")
def sag(tmp_path_factory):
    """How far the skin sinks under its own weight, at its centre, without a tool."""
    from adfkit.scenes.soft_phantom import SoftPhantomParams, write_soft_phantom

    p = SoftPhantomParams(with_probe=False)
    alone, _ = _skin_under_tool(write_soft_phantom(tmp_path_factory.mktemp("alone"), p), 0.5)
    return p.height - alone[np.linalg.norm(alone[:, :2], axis=1) < 0.006, 2].min()


def test_soft_phantom_is_indented_by_a_spherical_probe(tmp_path, sag):
    from adfkit.scenes.soft_phantom import SoftPhantomParams, write_soft_phantom

    p = SoftPhantomParams(tool="sphere")
    nodes, probe = _skin_under_tool(write_soft_phantom(tmp_path, p), 0.5)
    centre = np.linalg.norm(nodes[:, :2], axis=1) < 0.006
    far = np.linalg.norm(nodes[:, :2], axis=1) > 0.035
    depth = p.height - nodes[centre, 2].min()
    print(f"skin indentation under the probe: {(depth - sag) * 1000:.1f} mm (sag alone {sag * 1000:.1f} mm)")
    assert 0.005 < depth - sag < 0.03  # visibly indented: millimetres to centimetres
    assert probe[2] - p.probe_radius == pytest.approx(nodes[centre, 2].min(), abs=0.004)  # tip on the skin
    # the dent is local: far from the probe the skin moved much less than under it
    assert (p.height - nodes[far, 2].min()) < 0.5 * depth


@pytest.mark.slow  # six capsules against the skin: ~3x the sphere's contact cost
def test_soft_phantom_is_indented_by_the_suturing_needle(tmp_path, sag):
    """The bundled scene's tool: the suturing pad's needle lying flat, pressed with 0.49 N."""
    from adfkit.scenes.soft_phantom import SoftPhantomParams, write_soft_phantom

    p = SoftPhantomParams()
    assert p.tool == "needle"
    nodes, needle = _skin_under_tool(write_soft_phantom(tmp_path, p), 0.6, "Needle")
    under = np.linalg.norm(nodes[:, :2], axis=1) < 0.015
    depth = p.height - nodes[under, 2].min()
    print(f"skin indentation under the needle: {(depth - sag) * 1000:.1f} mm")
    assert 0.005 < depth - sag < 0.03
    # the needle rests on the skin (its wire within a few millimetres of the skin's lowest node), not through it
    assert -0.002 < needle[2] - nodes[under, 2].min() < 0.006
    assert needle[2] > 0.015  # well above the tray (top at 0.01)


def test_soft_phantom_sample_scene_is_generated(tmp_path):
    from pathlib import Path

    from adfkit.scenes import BUILDERS

    bundled = Path(__file__).resolve().parent.parent / "sample_scenes" / "soft_phantom"
    BUILDERS["soft-phantom"](tmp_path)
    for f in sorted(bundled.iterdir()):
        assert (tmp_path / f.name).read_bytes() == f.read_bytes(), f.name
    assert sorted(x.name for x in tmp_path.iterdir()) == sorted(x.name for x in bundled.iterdir())
    res = validate_file(bundled / "phantom.yaml")
    assert [d for d in res.diagnostics if d.severity >= 1] == [], [str(d) for d in res.diagnostics]


# --- MJCF and URDF ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", CLOTHS)
def test_convert_cloth_to_mjcf_loads_and_plays_in_mujoco(name, tmp_path):
    mujoco = pytest.importorskip("mujoco")
    out = tmp_path / "cloth.xml"
    assert main(["convert", str(_cloth(name)), str(out), "--to", "mjcf"]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    assert (model.nflex, list(model.flex_vertnum)) == (1, [386])
    data = mujoco.MjData(model)
    start = data.flexvert_xpos.copy() if data.flexvert_xpos.size else None
    for _ in range(300):
        mujoco.mj_step(model, data)
    pos = data.flexvert_xpos
    assert np.all(np.isfinite(pos))
    np.testing.assert_allclose(
        pos[0], [0.38972265, {"cloth.yaml": 2.67708838, "cloth2.yaml": 0.17708838}[name], 0.0], atol=1e-6
    )  # fixed node 0: a pin
    assert pos[:, 2].min() < -0.05  # the rest falls
    assert start is None or np.linalg.norm(pos - start, axis=1).max() < 5.0


def test_mjcf_flex_parameters_and_losses(tmp_path):
    import xml.etree.ElementTree as ET

    from adfkit.converters import write
    from adfkit.model.objects import SoftBody

    (tmp_path / "sq.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n")
    m = ModelFile(path=tmp_path / "m.yaml")
    m.soft_bodies.append(
        SoftBody(
            identifier="SOFT s",
            name="s",
            mesh="sq.obj",
            mass=0.4,
            collision_margin=0.01,
            config=SoftBodyConfig(kLST=0.5, piterations=2, kDF=0.7, kVC=3.0, kDP=0.2, fixed_nodes=[1, 9]),
            randomize_constraints=True,
        )
    )
    losses = write(m, tmp_path / "m.xml", "mjcf")
    flex = ET.parse(tmp_path / "m.xml").getroot().find("worldbody/flexcomp")
    assert flex.get("point") == "0.0 0.0 0.0 1.0 0.0 0.0 1.0 1.0 0.0 0.0 1.0 0.0"
    assert (flex.get("element"), flex.get("mass"), flex.get("radius")) == ("0 1 2 0 2 3", "0.4", "0.01")
    k = (1 - 0.5**2) * 0.1 / 1e-6
    el = flex.find("elasticity")
    assert float(el.get("young")) * float(el.get("thickness")) == pytest.approx(k)
    assert el.get("elastic2d") == "stretch"
    assert flex.find("contact").get("friction") == "0.7" and flex.find("pin").get("id") == "1"
    feats = {(l.element, l.feature) for l in losses}
    assert {
        ("SOFT s", "config.kVC"),
        ("SOFT s", "randomize constraints"),
        ("SOFT s", "fixed nodes"),
        ("SOFT s", "soft body"),
    } <= feats
    # and back: MuJoCo's flex is a named loss, its vertex bodies are not made ADF bodies
    from adfkit.converters import read

    back, read_losses = read(tmp_path / "m.xml", "mjcf")
    assert back.bodies == [] and back.joints == []
    assert [(l.element, l.feature) for l in read_losses] == [("s", "flex")]


def test_urdf_names_the_soft_body_loss(tmp_path):
    from adfkit.converters import write
    from adfkit.model.objects import Body, SoftBody

    m = ModelFile(path=tmp_path / "m.yaml")
    m.bodies.append(Body(identifier="BODY b", name="b", mass=1.0))
    m.soft_bodies.append(SoftBody(identifier="SOFT s", name="s", mesh="sq.obj", mass=0.4))
    losses = write(m, tmp_path / "m.urdf", "urdf")
    assert ("SOFT s", "soft body") in {(l.element, l.feature) for l in losses}


@pytest.mark.parametrize("where", ["outside", "long-name"])
def test_soft_body_mesh_outside_the_tree_or_unnameable_is_not_read(tmp_path, monkeypatch, where):
    """The fixed-nodes rule and the MJCF soft writer read the mesh through the input policy:
    a mesh outside the scene's tree is never opened (found by the 100,000-case fuzz run: the
    validator and `convert` read /etc/passwd there), and a name over 255 bytes is a located
    finding, not an OSError."""
    from adfkit.cli import main

    scene = tmp_path / "scene"
    scene.mkdir()
    secret = tmp_path / "secret.3ds"
    _tiny_3ds(secret, [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [(0, 1, 2), (0, 2, 3)])
    mesh = str(secret) if where == "outside" else "d" * 300 + "/m.3ds"
    f = scene / "soft.yaml"
    f.write_text(SOFT.format(mesh=mesh, mass="0.1", klst="0.5", pit="4", bend="2", fixed="[0, 9]"))
    monkeypatch.setenv("ADFKIT_INPUT_ROOT", str(scene))
    import fuzzkit  # its audit hook records every open (one hook for the whole session)

    fuzzkit._install_hook()
    fuzzkit._OPENED = []
    try:
        rules = [d.rule for d in validate_file(f).diagnostics]
        assert rules and "soft-body-fixed-nodes" not in rules  # the mesh was not counted
        assert ({"outside-tree"} if where == "outside" else {"missing-mesh", "bad-path"}) & set(rules)
        assert main(["convert", str(f), str(scene / "out.xml")]) in (0, 1, 2)
        opened = [str(p) for p in fuzzkit._OPENED]
    finally:
        fuzzkit._OPENED = None
    assert not [p for p in opened if "secret" in p]


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_soft_body_is_in_rgb_depth_and_segmentation_with_its_own_label(tmp_path, engine):
    """The soft phantom's skin, drawn by the camera: labelled after the rigid bodies (soft body k
    is label len(bodies) + k), with depth where it is seen, and named in a dataset's labels."""
    from adfkit.adf import load_scene
    from adfkit.dataset.writer import DatasetWriter
    from adfkit.scenes import write_soft_phantom

    if engine == "mujoco":
        require_renderer("mujoco")
    launch = write_soft_phantom(tmp_path / "scene")
    world = open_world(load_scene(launch), Options(), engine=engine)
    try:
        world.run(0.1)
        frame = world.cameras[0].render(world)
        skin = frame["segmentation"] == len(world.bodies)
        assert skin.mean() > 0.05 and np.isfinite(frame["depth"][skin]).all()
        r, g, b = frame["rgb"][skin].reshape(-1, 3).astype(float).mean(axis=0)
        assert r > g + 20 and r > b + 20  # drawn in its tissue colour, not the floor's grey
        writer = DatasetWriter(world, tmp_path / "ds")
        writer.close()
        labels = json.loads((tmp_path / "ds" / "labels.json").read_text())
        assert labels[str(len(world.bodies))] == world.soft.items[0].key
    finally:
        world.close()


# --- a soft pad on its tray, in both engines ----------------------------------------------------

PAD_NODES, PAD_SIZE, TRAY_TOP, MARGIN = 11, 0.08, 0.01, 0.001


def _pad_scene(tmp_path, tray_x: float = 0.0):
    """An 8 cm pad (11 x 11 nodes, 20 g, kLST 0.5 over 2 iterations, bending links) 1 cm above a
    12 cm tray whose top is at z = 10 mm; ``tray_x`` moves the tray aside."""
    n = PAD_NODES
    lines = [
        f"v {-PAD_SIZE / 2 + PAD_SIZE * i / (n - 1):.6f} {-PAD_SIZE / 2 + PAD_SIZE * j / (n - 1):.6f} 0"
        for j in range(n)
        for i in range(n)
    ]
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i + 1
            lines += [f"f {a} {a + 1} {a + n + 1}", f"f {a} {a + n + 1} {a + n}"]
    (tmp_path / "pad.obj").write_text("\n".join(lines) + "\n")
    (tmp_path / "pad.yaml").write_text(
        f"""bodies: [BODY Tray]
soft bodies: [SOFTBODY Pad]
BODY Tray:
  name: Tray
  mass: 0.0
  location: {{position: {{x: {tray_x}, y: 0, z: {TRAY_TOP / 2}}}, orientation: {{r: 0, p: 0, y: 0}}}}
  collision shape: BOX
  collision geometry: {{x: 0.12, y: 0.12, z: {TRAY_TOP}}}
SOFTBODY Pad:
  name: Pad
  mass: 0.02
  mesh: pad.obj
  collision margin: {MARGIN}
  location: {{position: {{x: 0, y: 0, z: 0.02}}, orientation: {{r: 0, p: 0, y: 0}}}}
  config: {{kLST: 0.5, piterations: 2, kDP: 0.2, kDF: 0.5, bending constraint: 2}}
"""
    )
    from adfkit.adf import load_scene

    return load_scene(tmp_path / "pad.yaml")


def _settle(scene, engine: str, seconds: float = 0.6):
    world = open_world(scene, Options(visuals=False), engine=engine)
    try:
        world.run(seconds)
        (pad,) = world.soft.items
        return pad.nodes(), world.report(), world.diagnostics
    finally:
        world.close()


def test_a_soft_pad_settles_on_its_tray_alike_in_both_engines(tmp_path):
    """The pad falls 1 cm onto the tray and rests on it, every node one collision margin above
    its top (PyBullet's margin; the MuJoCo flex's radius), in both engines, node by node within
    0.5 mm of each other (measured: 0.09 mm at most). MuJoCo plays it with its discrete
    integrator (implicitfast refuses a flex's elasticity: adfkit run raised ValueError)."""
    scene = _pad_scene(tmp_path)
    nodes, reports = {}, {}
    for engine in ("pybullet", "mujoco"):
        nodes[engine], reports[engine], diags = _settle(scene, engine)
        assert diags == []
        (row,) = reports[engine]["soft_bodies"]
        assert (row["nodes"], row["triangles"], row["fixed_nodes"]) == (121, 200, 0)
        assert row["size_m"] == pytest.approx(row["rest_size_m"], rel=0.01)  # neither stretched nor shrunk
        assert reports[engine]["nan"] == reports[engine]["exploded"] == reports[engine]["not_played"] == []
        z = nodes[engine][:, 2]
        assert z == pytest.approx(np.full(121, TRAY_TOP + MARGIN), abs=2.5e-4), engine
    gap = np.linalg.norm(nodes["pybullet"] - nodes["mujoco"], axis=1)
    assert gap.max() < 5e-4, gap.max()


def test_a_soft_pad_beside_its_tray_does_not_settle_on_it(tmp_path):
    """The negative control: the tray moved from under the pad, the same check fails in both
    engines (the pad falls past the tray's top to the floor a scene without a world gets)."""
    scene = _pad_scene(tmp_path, tray_x=0.3)
    for engine in ("pybullet", "mujoco"):
        nodes, _, _ = _settle(scene, engine)
        assert nodes[:, 2].max() < TRAY_TOP - 0.005, engine
