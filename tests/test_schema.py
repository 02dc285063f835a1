"""The shipped JSON Schemas: in sync with the model, complete, valid draft 2020-12, and
accepting exactly what AMBF accepts on the corpus and on scalar forms (adf-format.md §1)."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest
import yaml
from conftest import corpus_files, corpus_id

from adfkit.adf.yamlcompat import repair
from adfkit.adf_schema import KINDS, load_schema, schema_file
from adfkit.model import FILE_KINDS
from adfkit.model.spec import Node, adf_fields
from adfkit.validator.engine import validate_file
from adfkit.validator.schemagen import build_schema, schema_text


@pytest.mark.parametrize("kind", KINDS)
def test_shipped_schema_is_generated_from_the_model(kind):
    assert schema_file(kind).read_text(encoding="utf-8") == schema_text(kind), (
        "run: python -m adfkit.validator.schemagen"
    )


@pytest.mark.parametrize("kind", KINDS)
def test_schema_is_valid_draft_2020_12(kind):
    schema = load_schema(kind)
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    jsonschema.Draft202012Validator.check_schema(schema)


def _classes(cls, seen):
    if cls.__name__ in seen:
        return
    seen[cls.__name__] = cls
    for f in adf_fields(cls):
        k = f.metadata["kind"]
        for inner in (k, getattr(k, "item", None), getattr(k, "struct", None), getattr(k, "kind", None)):
            if isinstance(inner, type) and issubclass(inner, Node):
                _classes(inner, seen)


def test_every_model_key_is_in_a_schema_with_a_description():
    seen: dict = {}
    for cls in FILE_KINDS.values():
        _classes(cls, seen)
    schemas = {k: build_schema(k) for k in KINDS}
    file_class = {c.__name__: k for k, c in FILE_KINDS.items()}
    missing = []
    for name, cls in seen.items():
        if name in file_class:
            props = schemas[file_class[name]]["properties"]
        else:
            props = next(s["$defs"][name]["properties"] for s in schemas.values() if name in s["$defs"])
        for f in adf_fields(cls):
            key = f.metadata["adf_key"]
            if key not in props or "description" not in props[key]:
                missing.append(f"{name}.{key}")
    assert missing == []
    assert len(seen) >= 50


def test_defaults_and_descriptions_follow_the_reference():
    body = load_schema("model")["$defs"]["Body"]["properties"]
    assert body["collision margin"]["default"] == 0.001
    assert body["mass"]["description"].startswith("Mass, kg; 0 means static")
    joint = load_schema("model")["$defs"]["Joint"]
    assert joint["required"] == ["type", "parent pivot", "child pivot", "parent axis", "child axis"]
    assert joint["properties"]["ignore inter-collision"]["default"] is True
    assert joint["dependentRequired"] == {"enable motor": ["enable feedback"]}
    assert load_schema("launch")["required"] == [
        "world config",
        "color config",
        "input devices config",
        "multibody configs",
    ]
    assert load_schema("world")["properties"]["gravity"]["default"] == {"x": 0, "y": 0, "z": -9.8}


def _accepts(definition: str, value) -> bool:
    schema = load_schema("model")
    v = jsonschema.Draft202012Validator({"$defs": schema["$defs"], "$ref": f"#/$defs/{definition}"})
    ok = v.is_valid(value)
    # the compiled validator the CLI uses as a fast path must agree (regex dialects differ)
    fast = _fast_validator_for(definition)
    if fast is not None:
        assert fast.is_valid(value) is ok, (definition, value)
    return ok


def _fast_validator_for(definition):
    from adfkit.validator.schema_check import _fast_validator

    return _fast_validator("model", definition)


@pytest.mark.parametrize(
    "value, ok",
    [
        (0.5, True),
        (3, True),
        ("0.5", True),
        (" -1.5e3 ", True),
        ("1e-3", True),
        (".5", True),
        ("abc", False),
        (True, False),
        (None, False),
        ([1], False),
    ],
)
def test_float_scalar_forms(value, ok):
    assert _accepts("float", value) is ok


@pytest.mark.parametrize(
    "value, ok",
    [
        (True, True),
        ("True", True),
        ("y", True),
        ("N", True),
        ("off", True),
        ("YES", True),
        (1, False),
        (0, False),
        ("tRue", False),
        ("1", False),
    ],
)
def test_bool_scalar_forms(value, ok):
    assert _accepts("bool", value) is ok


@pytest.mark.parametrize(
    "definition, value, ok",
    [
        ("int", 3, True),
        ("int", "-4", True),
        ("int", 2.5, False),
        ("uint", 0, True),
        ("uint", -1, False),
        ("uint", "7", True),
        ("uint", "-7", False),
        ("str", 12, True),
        ("str", None, False),
    ],
)
def test_integer_and_text_forms(definition, value, ok):
    assert _accepts(definition, value) is ok


@pytest.mark.parametrize("path", corpus_files(), ids=corpus_id)
def test_whole_file_schema_agrees_with_ambf_on_the_corpus(path):
    """What check-jsonschema sees: the file schema alone, on PyYAML's reading of the file."""
    res = validate_file(path)
    if res.kind is None:  # compound_example.yaml: not YAML at all
        assert "compound_example" in path.name
        return
    text = path.read_text(encoding="utf-8")
    data = yaml.safe_load(repair(text)[0])
    errors = list(jsonschema.Draft202012Validator(load_schema(res.kind)).iter_errors(data))
    if path.name in {
        f"urdf-{n}.yaml" for n in ("ecm", "kuka", "mtm", "psm", "suj")
    }:  # rejected by AMBF: enable motor without enable feedback
        assert errors and {e.validator for e in errors} == {"dependentRequired"}
    else:
        assert errors == [], [e.message for e in errors][:3]


def test_schema_command_matches_package_data(capsys):
    from adfkit.cli import main

    for kind in KINDS:
        assert main(["schema", kind]) == 0
        assert json.loads(capsys.readouterr().out) == load_schema(kind)


def test_fast_schema_path_agrees_with_jsonschema_on_corpus_objects_and_mutations():
    """jsonschema-rs answers "valid?" before the located jsonschema pass: a disagreement would
    hide findings. Check every corpus object (the bundled sample scenes when the corpus is
    absent) and a bad-value variant of each of its scalars, as the validator builds them
    (adfkit.adf.yamlnodes.plain: keys are text, so `{kDP, 0.001}` cannot make it raise)."""
    pytest.importorskip("jsonschema_rs", reason="jsonschema-rs (the validator's accelerator) is not installed")
    from adfkit.adf.yamlnodes import compose, plain
    from adfkit.validator.schema_check import _fast_validator, _validator, object_lists

    checked = disagreements = invalid = 0
    bad_values = ["abc", "1", "tRue", -1, 2.5, None, [1], {"x": 1}, " -1.5e3 ", "off"]
    paths = corpus_files()
    enough = (2000, 500) if paths else (150, 40)
    if not paths:
        paths = sorted((Path(__file__).resolve().parent.parent / "sample_scenes").rglob("*.yaml"))
        assert paths, "neither the corpus nor sample_scenes/ is present"
    for path in paths:
        res = validate_file(path)
        if res.kind not in ("model", "world", "input_devices"):
            continue
        data = plain(compose(repair(path.read_text(encoding="utf-8"))[0], str(path)))
        for list_key, definition in object_lists(res.kind).items():
            slow, fast = _validator(res.kind, definition), _fast_validator(res.kind, definition)
            for ident in data.get(list_key) or []:
                obj = data.get(ident)
                if not isinstance(obj, dict):
                    continue
                scalars = [k for k in obj if not isinstance(obj[k], (dict, list))]
                picks = scalars[checked % max(1, len(scalars)) :: max(1, len(scalars) // 2)][:2]
                variants = [obj] + [
                    {**obj, k: bad_values[(checked + n) % len(bad_values)]} for n, k in enumerate(picks)
                ]
                for v in variants:
                    checked += 1
                    ok = slow.is_valid(v)
                    invalid += not ok
                    disagreements += fast.is_valid(v) is not ok
    assert checked > enough[0] and invalid > enough[1], (checked, invalid)  # both answers exercised
    assert disagreements == 0
