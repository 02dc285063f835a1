"""Issue 4, data-driven over the public corpus: every file PyYAML parses loads into the
model, its counts match the raw YAML, and read → write → read round-trips."""

from __future__ import annotations

import functools
import math

import pytest
import yaml
from conftest import corpus_files, corpus_id

from adfkit.adf import dumps, read_file
from adfkit.model import ModelFile, World, rpy_to_quat
from adfkit.model.compare import differences
from adfkit.summary import model_summary

FILES = corpus_files()


def _pyyaml_ok(path) -> bool:
    try:
        yaml.safe_load(path.read_text())
        return True
    except yaml.YAMLError:
        return False


PARSEABLE = [p for p in FILES if _pyyaml_ok(p)]
UNPARSEABLE = [p for p in FILES if p not in PARSEABLE]


def test_corpus_is_what_the_manifest_says(corpus):
    # adf-format.md §16: 102 files, PyYAML fails on exactly two of them.
    assert len(FILES) == 102
    assert sorted(p.name for p in UNPARSEABLE) == ["compound_example.yaml", "rover_info.yaml"]


@pytest.mark.parametrize("path", UNPARSEABLE, ids=corpus_id)
def test_unparseable_files_give_a_located_yaml_error(path):
    from adfkit.diagnostics import AdfError

    with pytest.raises(AdfError) as info:
        read_file(path)
    (d,) = info.value.diagnostics
    assert d.rule == "yaml-syntax"
    assert d.location.line > 1 and d.location.column >= 1


def _list_len(raw: dict, key: str) -> int:
    v = raw.get(key)
    return len(v) if isinstance(v, list) else 0


@pytest.mark.parametrize("path", PARSEABLE, ids=corpus_id)
def test_corpus_file_loads_and_counts_match_raw_yaml(path):
    doc, diags = read_file(path)
    raw = yaml.safe_load(path.read_text())
    if isinstance(doc, ModelFile):
        s = model_summary(doc)
        assert s["bodies"] == _list_len(raw, "bodies")
        assert s["joints"] == _list_len(raw, "joints")
        assert s["ghost objects"] == _list_len(raw, "ghost objects")
        assert s["soft bodies"] == _list_len(raw, "soft bodies")
        assert s["sensors"] == _list_len(raw, "sensors")
        assert s["actuators"] == _list_len(raw, "actuators")
        assert s["cameras"] == _list_len(raw, "cameras")
        # Joint types counted by the model equal the raw `type` strings of listed joints.
        raw_types = sorted(raw[j]["type"] for j in raw.get("joints") or [] if isinstance(raw.get(j), dict))
        assert sorted(j.type for j in doc.joints if j.defined) == raw_types
        # Mass of bodies and soft bodies: missing mass means 1 kg (AMBF), quoted masses are numbers.
        listed = [*(raw.get("bodies") or []), *(raw.get("soft bodies") or [])]
        raw_mass = sum(float(raw[b].get("mass", 1.0)) if isinstance(raw.get(b), dict) else 1.0 for b in listed)
        assert math.isclose(s["total mass"], raw_mass, rel_tol=1e-9, abs_tol=1e-9)
    elif isinstance(doc, World):
        assert len(doc.lights) == _list_len(raw, "lights")
        assert len(doc.cameras) == _list_len(raw, "cameras")
        assert doc.environment == raw.get("environment")


# --- round trip ------------------------------------------------------------------------------

# Every way the written YAML may differ from the original, one by one. The comparison
# below records which rule it used for each difference; anything else fails the test.
NORMALISATIONS = {
    "typed-scalar": "a quoted number or boolean ('0.5', 'True', y/n) is written as a number or boolean",
    "int-as-float": "an integer in a real-valued field is written as a float (0 → 0.0)",
    "text-scalar": "a number in a text field (name: 1) is written as text ('1')",
    "pose-halves": "a pose that omits position or orientation is written with both (zero / identity)",
    "null-list": "an empty (null) object list is written as []",
    "duplicate-key": "a duplicated key keeps its first value (AMBF's choice; PyYAML keeps the last)",
}


def _rot_equal(a: dict, b: dict) -> bool:
    qa = rpy_to_quat(float(a["r"]), float(a["p"]), float(a["y"]))
    qb = rpy_to_quat(float(b["r"]), float(b["p"]), float(b["y"]))
    return qa.angle_to(qb) < 1e-9


def _content_equal(orig, new, used: set, path="") -> list[str]:
    if isinstance(orig, dict) and isinstance(new, dict):
        if set(orig) == {"r", "p", "y"} == set(new) and not all(orig[k] == new[k] for k in orig):
            # angles are written as they were read, even the same rotation in other angles is a change
            same = "the same rotation" if _rot_equal(orig, new) else "another rotation"
            return [f"{path}: angles {orig} written as {new} ({same})"]
        out = []
        for k in orig.keys() | new.keys():
            if k not in new:
                out.append(f"{path}.{k}: dropped")
            elif k not in orig:
                if k in ("position", "orientation") and set(new) == {"position", "orientation"}:
                    used.add("pose-halves")
                    continue
                out.append(f"{path}.{k}: added")
            else:
                out += _content_equal(orig[k], new[k], used, f"{path}.{k}")
        return out
    if isinstance(orig, list) and isinstance(new, list):
        if len(orig) != len(new):
            return [f"{path}: length {len(orig)} != {len(new)}"]
        return [e for i, (a, b) in enumerate(zip(orig, new)) for e in _content_equal(a, b, used, f"{path}[{i}]")]
    if orig is None and new == []:
        used.add("null-list")
        return []
    if type(orig) is type(new) and orig == new:
        return []
    if isinstance(orig, str) and isinstance(new, bool):
        if orig.strip().lower() in ("true", "yes", "on", "y", "false", "no", "off", "n"):
            used.add("typed-scalar")
            return []
    if isinstance(orig, str) and isinstance(new, float):
        try:
            if float(orig) == new:
                used.add("typed-scalar")
                return []
        except ValueError:
            pass
    if isinstance(orig, int) and not isinstance(orig, bool) and isinstance(new, float) and orig == new:
        used.add("int-as-float")
        return []
    if isinstance(orig, (int, float)) and not isinstance(orig, bool) and isinstance(new, str):
        used.add("text-scalar")
        return []
    return [f"{path}: {orig!r} != {new!r}"]


def _first_wins_load(text: str):
    """Plain data with AMBF's duplicate-key rule (first occurrence wins)."""
    from adfkit.adf.yamlnodes import compose, plain

    return plain(compose(text, "<orig>", []))


@functools.cache
def _read_and_dump(path):
    doc, _ = read_file(path)
    return doc, dumps(doc)


@pytest.mark.parametrize("path", PARSEABLE, ids=corpus_id)
def test_round_trip(path, tmp_path):
    doc, text = _read_and_dump(path)
    out = tmp_path / path.name
    out.write_text(text)
    again, _ = read_file(out)
    assert differences(doc, again, tol=1e-12, quat_tol=1e-9) == []
    assert dumps(again) == text, "writing is deterministic"

    original_text = path.read_text()
    orig = yaml.safe_load(original_text)
    first_wins = _first_wins_load(original_text)
    used: set[str] = set()
    if orig != first_wins:
        used.add("duplicate-key")
    diffs = _content_equal(first_wins, yaml.safe_load(text), used)
    assert diffs == []
    assert used <= set(NORMALISATIONS)


def test_round_trip_uses_every_listed_normalisation_somewhere(corpus):
    """Keeps the list honest: each normalisation is really needed by some corpus file."""
    needed: set[str] = set()
    for path in PARSEABLE:
        doc, text = _read_and_dump(path)
        original_text = path.read_text()
        first_wins = _first_wins_load(original_text)
        if yaml.safe_load(original_text) != first_wins:
            needed.add("duplicate-key")
        _content_equal(first_wins, yaml.safe_load(text), needed)
    # pose-halves and text-scalar do not occur in the corpus; test_adf_unit.py covers them.
    assert needed == set(NORMALISATIONS) - {"pose-halves", "text-scalar"}
