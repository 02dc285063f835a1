"""Mutation test: broken variants of every corpus file. Each variant must give at least one
diagnostic naming the damage, every diagnostic must point at a line:col inside the
variant, and nothing may raise. ~150 variants by default, the full set (> 2,000) with -m slow."""

from __future__ import annotations

import os
import random
import re
from functools import cache
from pathlib import Path

import pytest
from conftest import CORPUS, corpus_files

from adfkit.adf import read_file
from adfkit.diagnostics import AdfError
from adfkit.model.spec import adf_fields, adf_keys
from adfkit.validator import validate_file

SEEDS_PER_OPERATOR = 3
BOMB = "".join(
    [
        "lol0: &l0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]\n",
        *(
            f"lol{i}: &l{i} [*l{i - 1}, *l{i - 1}, *l{i - 1}, *l{i - 1}, *l{i - 1}, *l{i - 1}, *l{i - 1}, *l{i - 1}, *l{i - 1}, *l{i - 1}]\n"
            for i in range(1, 8)
        ),
    ]
)
NUMBER = r"-?[0-9]+\.?[0-9]*(?:[eE][-+]?[0-9]+)?"


def _lines_matching(text: str, pattern: str) -> list[re.Match]:
    """Matches outside comments."""
    return [
        m
        for m in re.finditer(pattern, text, flags=re.M)
        if "#" not in text[text.rfind("\n", 0, m.start()) + 1 : m.start()]
    ]


def _replace(text: str, m: re.Match, group: int, new: str) -> str:
    return text[: m.start(group)] + new + text[m.end(group) :]


def op_delete_required(text, rng):
    for pat in (
        r"^[ \t]+(?:parent pivot|child pivot|parent axis|child axis|type):.*\n",
        r"^(?:world config|input devices config|multibody configs):.*\n",
        r"^environment:.*\n",
        r"^[ \t]+hardware name:.*\n",
    ):
        found = _lines_matching(text, pat)
        if found:
            m = rng.choice(found)
            return text[: m.start()] + text[m.end() :]
    return None


def op_wrong_type(text, rng):
    found = _lines_matching(
        text,
        rf"^[ \t]+(?:mass|scale|restitution|collision margin|range|max motor impulse"
        rf"|spot exponent|field view angle|workspace scaling):[ \t]*({NUMBER})[ \t]*$",
    )
    if found:
        return _replace(text, rng.choice(found), 1, "not_a_number")
    found = _lines_matching(
        text, r"^[ \t]+(?:passive|visible|publish image|enable feedback):[ \t]*(true|false|True|False)"
    )
    if found:
        return _replace(text, rng.choice(found), 1, "1")
    found = _lines_matching(text, r"\b[rgba]: (" + NUMBER + ")")
    return _replace(text, rng.choice(found), 1, "[oops]") if found else None


def op_dangling(text, rng):
    found = _lines_matching(text, r"^[ \t]+(?:parent|child|chassis|root link):[ \t]*(\S.*?)[ \t]*$")
    return _replace(text, rng.choice(found), 1, f"BODY nowhere_{rng.randrange(10**6)}") if found else None


def op_bad_path(text, rng):
    found = _lines_matching(text, r"^[ \t]+(?:mesh|collision mesh):[ \t]*([^'\s].*?)[ \t]*$")
    found = found or _lines_matching(
        text, r"^(?:world config|color config|input devices config|environment):[ \t]*(\S.*?)[ \t]*$"
    )
    return _replace(text, rng.choice(found), 1, f"no/such/file_{rng.randrange(10**6)}.stl") if found else None


def op_alias_bomb(text, rng):
    return text.rstrip("\n") + "\n" + BOMB


def op_recursive_alias(text, rng):
    return text.rstrip("\n") + "\nloop: &loop [1, *loop]\n"


def op_nan(text, rng):
    found = _lines_matching(text, rf"position:[ \t]*\{{[ \t]*x:[ \t]*({NUMBER})")
    found = found or _lines_matching(text, rf"^[ \t]+(?:mass|scale|x|radius):[ \t]*({NUMBER})[ \t]*$")
    return _replace(text, rng.choice(found), 1, rng.choice([".nan", ".inf", "-.inf"])) if found else None


def op_huge(text, rng):
    found = _lines_matching(text, rf"position:[ \t]*\{{[ \t]*x:[ \t]*({NUMBER})")
    found = found or _lines_matching(text, rf"^[ \t]+(?:mass|x|radius):[ \t]*({NUMBER})[ \t]*$")
    return _replace(text, rng.choice(found), 1, rng.choice(["1e300", "-3.5e12", "'7e9'"])) if found else None


def op_truncate(text, rng):
    """Cut inside a flow mapping, or else in the middle of a (non-comment) line of the first half."""
    braces = [m.start() + 1 for m in re.finditer(r"\{", text)]
    if braces:
        return text[: rng.choice(braces)]
    lines = [m for m in _lines_matching(text[: max(1, len(text) // 2)] + "\n", r"^[ \t]*[^#\s].{2,}$")]
    if not lines:
        return text[: len(text) // 2]
    m = rng.choice(lines)
    return text[: m.start() + (m.end() - m.start()) // 2]


def op_duplicate_key(text, rng):
    found = _lines_matching(text, r"^[ \t]+(?:name|mass|type|parent|mesh):.*\n")
    found = found or _lines_matching(text, r"^[^ \t#\n][^\n]*:.*\n")
    if not found:
        return None
    m = rng.choice(found)
    return text[: m.end()] + m.group(0) + text[m.end() :]


def op_invalid_utf8(data: bytes, rng) -> bytes:
    at = rng.randrange(0, len(data) + 1)
    return data[:at] + rng.choice([b"\xff", b"\xc3\x28", b"\xe9t\xe9", b"\x80"]) + data[at:]


# operator -> rules of which at least one must be reported. Besides these, a syntax error
# (the damage broke the YAML) or an unknown/ignored-key finding (the damage sits in a block
# AMBF does not read, and the validator says so) count as detecting it.
ALWAYS_DETECTED_BY = {"yaml-syntax", "unknown-key", "ignored-key"}
OPERATORS = {
    "delete_required": (
        op_delete_required,
        {
            "schema-required",
            "no-environment",
            "input-device",
            "missing-type",
            "unknown-kind",
            "undefined-object",
            "bad-type",
        },
    ),
    "wrong_type": (op_wrong_type, {"bad-type", "bad-bool", "schema-type", "missing-component"}),
    "dangling": (op_dangling, {"dangling-reference", "external-reference", "input-device"}),
    "bad_path": (op_bad_path, {"missing-mesh", "missing-file", "missing-color-file", "missing-model-file"}),
    "alias_bomb": (op_alias_bomb, {"yaml-alias-bomb"}),
    "recursive_alias": (op_recursive_alias, {"yaml-recursive-alias"}),
    "nan": (op_nan, {"non-finite-number"}),
    "huge": (op_huge, {"absurd-value"}),
    "truncate": (
        op_truncate,
        {
            "undefined-object",
            "schema-required",
            "empty-file",
            "unknown-kind",
            "not-a-mapping",
            "missing-component",
            "no-environment",
            "bad-type",
            "missing-model-file",
            "missing-file",
            "missing-mesh",
            "dangling-reference",
            "external-reference",
            "schema-type",
            "bad-bool",
            "input-device",
        },
    ),
    "duplicate_key": (op_duplicate_key, {"yaml-duplicate-key"}),
    "invalid_utf8": (op_invalid_utf8, {"yaml-encoding"}),
}


def variants():
    """(id, original path, text or bytes, operator name), deterministic."""
    out = []
    for path in corpus_files():
        data = path.read_bytes()
        text = data.decode("utf-8")
        for name, (op, _) in OPERATORS.items():
            for seed in range(SEEDS_PER_OPERATOR):
                rng = random.Random(f"{path.relative_to(CORPUS)}:{name}:{seed}")
                mutated = op(data if name == "invalid_utf8" else text, rng)
                if mutated is not None and mutated != (data if name == "invalid_utf8" else text):
                    out.append((f"{path.relative_to(CORPUS)}:{name}:{seed}", path, mutated, name))
    return out


ALL = variants()
FAST = ALL[:: max(1, len(ALL) // 150)]


@cache
def _read_keys(path: Path) -> frozenset[str]:
    """Top-level keys AMBF reads in the original file: its own keys and listed identifiers."""
    doc, _ = read_file(path)
    keys = set(adf_keys(doc))
    for f in adf_fields(doc):
        value = getattr(doc, f.name)
        if isinstance(value, list):
            keys |= {o.identifier for o in value if hasattr(o, "identifier")}
    return frozenset(keys)


def in_ignored_block(path: Path, original: str, mutated: str) -> bool:
    """True when the damage sits in a top-level mapping AMBF never reads (an unlisted
    object or an anchor holder): nothing specific is then expected, only some diagnostic."""
    at = len(os.path.commonprefix([original, mutated]))
    owner = None
    for m in re.finditer(r"^([^ \t#\n-][^:\n]*):", original[:at], flags=re.M):
        owner = m.group(1).strip().strip("'\"")
    try:
        return owner is not None and owner not in _read_keys(path)
    except AdfError:
        return False


def check_variant(path: Path, mutated, op_name: str, tmp_path: Path) -> None:
    if isinstance(mutated, bytes):
        target = tmp_path / path.name
        target.write_bytes(mutated)
        res = validate_file(target)
        text = mutated.decode("utf-8", errors="replace")
    else:
        target = path  # validated in place (text given) so relative meshes resolve as in the real file
        res = validate_file(path, text=mutated)
        text = res.text if res.text is not None else mutated
    diags = res.diagnostics
    assert diags, f"{op_name}: no diagnostic"
    n_lines = text.count("\n") + 1
    for d in diags:
        loc = d.location
        assert loc is not None and loc.file == str(target), d
        assert 1 <= loc.line <= n_lines and loc.column >= 1, d
    if isinstance(mutated, str) and in_ignored_block(path, path.read_text(encoding="utf-8"), mutated):
        return
    expected = OPERATORS[op_name][1] | (ALWAYS_DETECTED_BY if op_name not in ("invalid_utf8",) else set())
    assert expected & {d.rule for d in diags}, (op_name, sorted({d.rule for d in diags}))


def test_enough_variants():
    if not CORPUS.is_dir():
        pytest.skip("corpus absent")
    assert len(ALL) >= 2000
    assert {v[3] for v in FAST} == set(OPERATORS)


@pytest.mark.parametrize("vid, path, mutated, op_name", FAST, ids=[v[0] for v in FAST])
def test_mutation_fast(vid, path, mutated, op_name, tmp_path):
    check_variant(path, mutated, op_name, tmp_path)


@pytest.mark.slow
def test_mutation_full(tmp_path):
    failures = []
    for vid, path, mutated, op_name in ALL:
        try:
            check_variant(path, mutated, op_name, tmp_path)
        except AssertionError as exc:
            failures.append(f"{vid}: {exc}")
    assert failures == [], f"{len(failures)} of {len(ALL)} variants:\n" + "\n".join(failures[:20])
