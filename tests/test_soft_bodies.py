"""Issue 16: soft bodies through the model, reader/writer, schema, validator, geometry,
runner and MJCF. Corpus tests (sb/cloth.yaml, cloth2.yaml) skip when the corpus is absent."""
from __future__ import annotations

import struct

import jsonschema
import numpy as np
import pytest
import yaml

from adfkit.adf import dumps, read_file
from adfkit.adf.yamlnodes import compose, plain
from adfkit.adf_schema import load_schema
from adfkit.diagnostics import AdfError
from adfkit.geometry.softmesh import load_soft_mesh, read_3ds, unique_nodes, write_obj
from adfkit.model import ModelFile
from adfkit.model.objects import SoftBodyConfig
from adfkit.model.spec import adf_keys
from adfkit.validator import validate_file
from conftest import CORPUS, require_corpus

SB = "ambf/ambf_models/descriptions/multi-bodies/sb/"
CLOTHS = ["cloth.yaml", "cloth2.yaml"]
# Every key AMBF 2.0's loader reads inside `config:` (ADFLoader_1_0::loadSoftBodyAttribs),
# less `cutting`, which it reads into a node and never uses.
AMBF_CONFIG_KEYS = {
    "kLST", "kAST", "kVST", "kVCF", "kDP", "kDG", "kLF", "kPR", "kVC", "kDF", "kMT", "kCHR", "kKHR", "kSHR",
    "kAHR", "kSRHR_CL", "kSKHR_CL", "kSSHR_CL", "kSR_SPLT_CL", "kSK_SPLT_CL", "kSS_SPLT_CL", "maxvolume",
    "timescale", "viterations", "piterations", "diterations", "citerations", "flags", "bending constraint",
    "clusters", "fixed nodes",
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
    assert (cfg.kLST, cfg.kDP, cfg.piterations, cfg.bending_constraint, cfg.flags, cfg.fixed_nodes) == \
        (0.005, 0.001, 6, 2, 16, [0])
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
    assert dumps(again) == text                      # byte-stable
    original = plain(compose(path.read_text(), str(path), []))   # AMBF's first-wins reading
    written = yaml.safe_load(text)
    assert written["soft bodies"] == ["BODY Cloth"]
    orig_sb, new_sb = original["BODY Cloth"], written["BODY Cloth"]
    assert set(orig_sb) == set(new_sb)               # every key of the soft body kept
    assert orig_sb["config"] == new_sb["config"]     # config values exactly, margin included
    assert new_sb["collision margin"] == orig_sb["collision margin"]
    assert new_sb["randomize constraints"] is True


def test_model_declares_every_config_key_ambf_reads():
    assert adf_keys(SoftBodyConfig) == AMBF_CONFIG_KEYS


def test_soft_body_written_from_the_model_reads_back(tmp_path):
    from adfkit.model.objects import SoftBody

    m = ModelFile()
    m.soft_bodies.append(SoftBody(identifier="SOFT pad", name="pad", mesh="pad.obj", mass=0.2,
                                  config=SoftBodyConfig(kLST=0.4, kAST=0.3, kVST=0.2, kDF=0.6, kDP=0.05,
                                                        piterations=8, clusters=4, bending_constraint=2,
                                                        fixed_nodes=[0, 3, 7]),
                                  randomize_constraints=True, collision_margin=0.002))
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
    assert _findings(tmp_path) == []


@pytest.mark.parametrize("change, expected", [
    (dict(mesh="''"), ("soft-body-mesh", 4, "warning")),
    (dict(mass="0.0"), ("soft-body-mass", 5, "warning")),
    (dict(klst="1.5"), ("soft-body-coefficient", 6, "warning")),
    (dict(pit="0"), ("soft-body-iterations", 6, "warning")),
    (dict(bend="1"), ("soft-body-iterations", 6, "warning")),
    (dict(fixed="[0, 4]"), ("soft-body-fixed-nodes", 6, "error")),
    (dict(fixed="[-1]"), ("soft-body-fixed-nodes", 6, "error")),
])
def test_soft_body_rules(tmp_path, change, expected):
    assert expected in _findings(tmp_path, **change)


def test_fixed_nodes_rule_on_the_corpus_cloth(tmp_path):
    text = _cloth("cloth2.yaml").read_text().replace("fixed nodes: [0]", "fixed nodes: [0, 385, 386]")
    (tmp_path / "low_res").symlink_to(_cloth("cloth2.yaml").parent / "low_res")
    f = tmp_path / "cloth.yaml"
    f.write_text(text)
    hits = [d for d in validate_file(f).diagnostics if d.rule == "soft-body-fixed-nodes"]
    assert len(hits) == 1 and "386 outside the 386 nodes of cloth.3DS" in hits[0].message
    assert not [d for d in validate_file(_cloth("cloth2.yaml")).diagnostics if d.rule.startswith("soft-body")]
