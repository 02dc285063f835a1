"""JSON Schema validation of ADF YAML with every error located on its YAML node.

Top-level object mappings are keyed by arbitrary identifiers, so a model (world,
input-devices) file is checked in two passes: its known top-level keys against the file
schema, then each listed object's mapping against its kind's ``$defs`` entry, located at
that mapping. A listed identifier with no mapping is checked as an empty mapping (AMBF
builds the object from an empty node) and located at the list entry.
"""

from __future__ import annotations

from functools import cache

import yaml

from ..adf.yamlnodes import location, mapping_items, plain
from ..adf_schema import load_schema
from ..diagnostics import Diagnostic, Severity
from ..model import FILE_KINDS
from ..model.files import ObjectList
from ..model.spec import adf_fields

_RULE_BY_KEYWORD = {
    "required": "schema-required",
    "type": "schema-type",
    "anyOf": "schema-type",
    "pattern": "schema-type",
}


# Schema keywords whose findings a semantic rule reports with a better message.
COVERED_BY_RULES = {"dependentRequired"}  # enable-motor-without-feedback


def _inline(node, defs: dict, depth: int = 0):
    """The schema with every local $ref replaced by its target (ADF types are not recursive).

    Same meaning as the shipped schema, ~2x faster to apply: no reference lookups."""
    if depth > 50:  # pragma: no cover - a recursive definition would be a schemagen bug
        raise ValueError("recursive $ref in the ADF schema")
    if isinstance(node, list):
        return [_inline(v, defs, depth) for v in node]
    if not isinstance(node, dict):
        return node
    out = {k: _inline(v, defs, depth) for k, v in node.items() if k not in ("$ref", "$defs")}
    ref = node.get("$ref")
    if isinstance(ref, str) and ref.startswith("#/$defs/"):
        target = _inline(defs[ref.removeprefix("#/$defs/")], defs, depth + 1)
        out = {**target, **out}
    return out


@cache
def _inlined(kind: str, definition: str | None) -> dict:
    schema = load_schema(kind)
    defs = schema["$defs"]
    target = defs[definition] if definition is not None else schema
    inlined = _inline(target, defs)
    inlined["$schema"] = schema["$schema"]
    return inlined


@cache
def _validator(kind: str, definition: str | None):
    from jsonschema import Draft202012Validator  # imported on first use: only for files with findings

    return Draft202012Validator(_inlined(kind, definition))


@cache
def _fast_validator(kind: str, definition: str | None):
    """jsonschema-rs (compiled) for the same inlined schema, or None when not installed.

    Only used to answer "valid?"; a file it finds invalid goes through ``jsonschema`` for the
    located findings, so both must agree on validity (tests/test_schema.py checks they do)."""
    try:
        import jsonschema_rs
    except ImportError:  # pragma: no cover - optional accelerator
        return None
    return jsonschema_rs.Draft202012Validator(_inlined(kind, definition))


def _errors(kind: str, definition: str | None, instance):
    fast = _fast_validator(kind, definition)
    if fast is not None:
        try:
            if fast.is_valid(instance):
                return ()
        except (ValueError, TypeError, OverflowError):  # a value it cannot take: jsonschema decides
            pass
    return _validator(kind, definition).iter_errors(instance)


def object_lists(kind: str) -> dict[str, str]:
    """Top-level list key → $defs name of the objects it lists."""
    return {
        f.metadata["adf_key"]: f.metadata["kind"].kind.__name__
        for f in adf_fields(FILE_KINDS[kind])
        if isinstance(f.metadata["kind"], ObjectList)
    }


def node_at(node: yaml.Node, path) -> tuple[yaml.Node, str | None]:
    """The node a JSON path points to (first occurrence of duplicate keys), and the last key."""
    last = None
    for step in path:
        if isinstance(node, yaml.MappingNode):
            for text, _, v in mapping_items(node):
                if text == str(step):
                    node, last = v, text
                    break
            else:
                return node, last
        elif isinstance(node, yaml.SequenceNode) and isinstance(step, int) and step < len(node.value):
            node = node.value[step]
        else:
            return node, last
    return node, last


def _diagnostic(err, base: yaml.Node, file: str, context: str, at: yaml.Node | None) -> Diagnostic:
    rule = _RULE_BY_KEYWORD.get(err.validator, "schema-type")
    node, last = node_at(base, err.absolute_path)
    where = location(file, at if at is not None else node)
    label = f"'{last}'" if last else context
    if err.validator == "required":
        missing = err.message.split("'")[1] if "'" in err.message else err.message
        owner = f"'{last}'" if last else context
        msg = f"{owner} lacks required key '{missing}'; AMBF rejects the file"
        hint = f"add '{missing}:'"
    elif err.validator in ("anyOf", "type", "pattern") and "title" in err.schema:
        shown = (
            node.value
            if isinstance(node, yaml.ScalarNode)
            else ("a mapping" if isinstance(node, yaml.MappingNode) else "a list")
        )
        shown = repr(shown) if len(repr(shown)) <= 80 else repr(shown)[:75] + "...'"
        msg = f"{label}: expected {err.schema['title']}, found {shown}"
        hint = "AMBF cannot convert this value and rejects the file"
    else:  # jsonschema's message can hold the whole value: the offending line at most
        text = err.message if len(err.message) <= 200 else err.message[:195] + " ..."
        msg = f"{label}: {text}"
        hint = None
    return Diagnostic(Severity.ERROR, rule, msg, where, hint)


def check(root: yaml.MappingNode, kind: str, file: str) -> list[Diagnostic]:
    out: list[Diagnostic] = []
    if kind in ("launch", "colors"):
        for err in _errors(kind, None, plain(root)):
            out.append(_diagnostic(err, root, file, "the file", None))
        return out
    lists = object_lists(kind)
    schema = load_schema(kind)
    known = set(schema["properties"])
    items = {text: (k, v) for text, k, v in mapping_items(root)}
    top = yaml.MappingNode(
        root.tag, [(k, v) for text, (k, v) in items.items() if text in known], root.start_mark, root.end_mark
    )
    for err in _errors(kind, None, plain(top)):
        out.append(_diagnostic(err, top, file, "the file", None))
    for list_key, definition in lists.items():
        lnode = items.get(list_key, (None, None))[1]
        if not isinstance(lnode, yaml.SequenceNode):
            continue
        for entry in lnode.value:
            if not isinstance(entry, yaml.ScalarNode):
                continue
            target = items.get(entry.value, (None, None))[1]
            if isinstance(target, yaml.MappingNode):
                for err in _errors(kind, definition, plain(target)):
                    if err.validator in COVERED_BY_RULES:
                        continue
                    out.append(_diagnostic(err, target, file, f"'{entry.value}'", None))
            elif target is None:
                for err in _errors(kind, definition, {}):  # AMBF builds it from an empty node
                    out.append(_diagnostic(err, entry, file, f"'{entry.value}'", entry))
    return out
