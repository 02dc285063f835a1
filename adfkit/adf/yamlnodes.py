"""YAML as node trees with positions (PyYAML ``compose``), safe loading only.

Duplicate keys, recursive aliases and alias bombs become diagnostics here, so nothing
downstream ever sees them as Python exceptions.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from .. import inputs
from ..diagnostics import AdfError, Diagnostic, SourceLocation, error

try:  # libyaml is much faster and keeps marks
    _Loader = yaml.CSafeLoader
except AttributeError:  # pragma: no cover - depends on the PyYAML build
    _Loader = yaml.SafeLoader

_constructor = yaml.constructor.SafeConstructor()

# Scalars, mappings and sequences a file may expand to through aliases before we stop.
MAX_EXPANDED_NODES = 2_000_000

STR_TAG = "tag:yaml.org,2002:str"
MAP_TAG = "tag:yaml.org,2002:map"


def location(file: str, node: yaml.Node | None) -> SourceLocation:
    if node is None or node.start_mark is None:
        return SourceLocation(file)
    return SourceLocation(file, node.start_mark.line + 1, node.start_mark.column + 1)


def read_text(path: Path, tree=None, referrer: SourceLocation | None = None) -> str:
    """Read an ADF file as UTF-8 through the input policy (adfkit.inputs): a regular file,
    under the size cap, inside ``tree`` when given; every failure is a located diagnostic."""
    return inputs.read_text(path, "adf", tree=tree, referrer=referrer, what="ADF file")


def compose(text: str, file: str, diagnostics: list[Diagnostic] | None = None) -> yaml.Node | None:
    """Parse YAML text into a node tree; syntax errors raise AdfError.

    Duplicate keys are reported into ``diagnostics`` (AMBF keeps the first occurrence,
    and so does :func:`mapping_items`)."""
    try:
        root = yaml.compose(text, Loader=_Loader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        loc = SourceLocation(file, mark.line + 1, mark.column + 1) if mark else SourceLocation(file)
        problem = exc.problem or "invalid YAML"
        ctx = f" ({exc.context})" if exc.context else ""
        raise AdfError(error("yaml-syntax", f"not valid YAML: {problem}{ctx}", loc,
                             "fix the YAML syntax; an online or editor YAML linter shows the exact spot")) from None
    except yaml.YAMLError as exc:
        raise AdfError(error("yaml-syntax", f"not valid YAML: {exc}", SourceLocation(file))) from None
    if root is not None:
        found = check_tree(root, file)
        if diagnostics is not None:
            diagnostics.extend(found)
    return root


def check_tree(root: yaml.Node, file: str) -> list[Diagnostic]:
    """Find duplicate keys; reject recursive aliases and alias bombs, with positions."""
    diags: list[Diagnostic] = []
    sizes: dict[int, int] = {}
    on_stack: set[int] = set()
    Mapping, Sequence = yaml.MappingNode, yaml.SequenceNode

    def walk(node: yaml.Node) -> int:
        cls = node.__class__
        if cls is not Mapping and cls is not Sequence:
            return 1
        nid = id(node)
        known = sizes.get(nid)
        if known is not None:
            return known
        if nid in on_stack:
            raise AdfError(error("yaml-recursive-alias", "an alias refers to a node that contains it",
                                 location(file, node), "ADF data is a tree; replace the recursive alias with data"))
        on_stack.add(nid)
        size = 1
        if cls is Mapping:
            seen: dict[Any, yaml.Node] = {}
            for k, v in node.value:
                if k.__class__ is yaml.ScalarNode:
                    kv = k.value
                    first = seen.get(kv)
                    if first is not None:
                        diags.append(error(
                            "yaml-duplicate-key",
                            f"duplicate key '{kv}' (first at line {first.start_mark.line + 1}); "
                            "AMBF keeps the first value, PyYAML the last",
                            location(file, k), "remove one of the two entries"))
                    else:
                        seen[kv] = k
                    size += 1 + walk(v)
                else:
                    size += walk(k) + walk(v)
        else:
            for item in node.value:
                size += walk(item)
        on_stack.discard(nid)
        sizes[nid] = size
        return size

    expanded = walk(root)
    if expanded > MAX_EXPANDED_NODES:
        raise AdfError(error("yaml-alias-bomb", f"aliases expand this file to {expanded:,} nodes",
                             location(file, root), "an ADF file never needs this; remove the nested aliases"))
    return diags


def plain(node: yaml.Node) -> Any:
    """A node as plain Python data (what ``yaml.safe_load`` would give)."""
    if isinstance(node, yaml.ScalarNode):
        return scalar_value(node)
    if isinstance(node, yaml.SequenceNode):
        return [plain(n) for n in node.value]
    if isinstance(node, yaml.MappingNode):
        out = {}
        for k, v in node.value:
            key = plain(k)
            if isinstance(key, (list, dict)):
                key = str(key)
            out.setdefault(key, plain(v))
        return out
    raise TypeError(node)  # pragma: no cover


def scalar_value(node: yaml.ScalarNode) -> Any:
    """A scalar as YAML 1.1 (PyYAML's safe schema) reads it; unknown tags stay text."""
    construct = _constructor.yaml_constructors.get(node.tag)
    if construct is None:
        return node.value
    try:
        return construct(_constructor, node)
    except (yaml.YAMLError, ValueError, TypeError):
        return node.value


def mapping_items(node: yaml.MappingNode) -> list[tuple[str, yaml.Node, yaml.Node]]:
    """(key text, key node, value node) for each entry; keys are compared as text like yaml-cpp."""
    out, seen = [], set()
    for k, v in node.value:
        text = k.value if isinstance(k, yaml.ScalarNode) else str(plain(k))
        if text not in seen:  # first occurrence wins, as in AMBF (yaml-cpp)
            seen.add(text)
            out.append((text, k, v))
    return out
