"""YAML as node trees with positions (PyYAML ``compose``), safe loading only.

Duplicate keys, recursive aliases and alias bombs become diagnostics here, so nothing
downstream ever sees them as Python exceptions.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from .. import inputs
from ..diagnostics import AdfError, Diagnostic, SourceLocation, error, warning

_BaseLoader: Any
try:  # libyaml is much faster and keeps marks
    _BaseLoader = yaml.CSafeLoader
except AttributeError:  # pragma: no cover - depends on the PyYAML build
    _BaseLoader = yaml.SafeLoader

_PLAIN = (True, False)
_RESOLVED: dict[str, str] = {}


class _Loader(_BaseLoader):
    """The safe loader with plain-scalar tags resolved once per distinct text.

    The C composer asks Python's regex resolver for every scalar (174,000 calls over the
    corpus, a third of composing); ADF files repeat few texts (0.0, 1.0, true, ...)."""

    def resolve(self, kind, value, implicit):
        if kind is yaml.ScalarNode and implicit == _PLAIN:
            tag = _RESOLVED.get(value)
            if tag is None:
                tag = _BaseLoader.resolve(self, kind, value, implicit)
                if len(_RESOLVED) < 200_000 and len(value) < 200:
                    _RESOLVED[value] = tag
            return tag
        return _BaseLoader.resolve(self, kind, value, implicit)


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


#: Deepest nesting of collections read (ADF needs about 6). Deeper files are an error: the C
#: composer recurses (its stack overflows near 100,000 levels) and so do YAML writers.
MAX_DEPTH = 100
# Below this bound on the nesting (see _depth_bound) the C composer is safe without a pre-scan.
_SAFE_BOUND = 3000

_SCALAR_TAGS_CHECKED = {
    "tag:yaml.org,2002:bool",
    "tag:yaml.org,2002:int",
    "tag:yaml.org,2002:float",
    "tag:yaml.org,2002:null",
    "tag:yaml.org,2002:timestamp",
    "tag:yaml.org,2002:binary",
}


def _syntax_error(exc: yaml.YAMLError, file: str, text: str) -> AdfError:
    if isinstance(exc, yaml.MarkedYAMLError):
        mark = exc.problem_mark or exc.context_mark
        loc = SourceLocation(file, mark.line + 1, mark.column + 1) if mark else SourceLocation(file, 1, 1)
        problem = exc.problem or "invalid YAML"
        ctx = f" ({exc.context})" if exc.context else ""
        return AdfError(
            error(
                "yaml-syntax",
                f"not valid YAML: {problem}{ctx}",
                loc,
                "fix the YAML syntax; an online or editor YAML linter shows the exact spot",
            )
        )
    line = col = 1
    position = getattr(exc, "position", None)  # ReaderError: a character YAML does not allow
    if isinstance(position, int):
        before = text[:position]
        line, col = before.count("\n") + 1, position - (before.rfind("\n") + 1) + 1
    return AdfError(
        error(
            "yaml-syntax",
            f"not valid YAML: {exc}",
            SourceLocation(file, line, col),
            "remove control characters; YAML allows tab, newline and printable text",
        )
    )


def _depth_bound(text: str) -> int:
    """An upper bound on the collection nesting of ``text``, from counts alone: each flow level
    needs a '[' or '{', and each block level needs indentation or an indicator on its line
    (both at most the longest line's length, twice over)."""
    longest = max(map(len, text.split("\n"))) if len(text) > 200 else len(text)
    return text.count("[") + text.count("{") + 2 * longest + 2


def _check_depth(text: str, file: str) -> None:
    """Refuse nesting deeper than MAX_DEPTH from the parser's events (iterative, no node built).

    libyaml first; when it stops with an error of its own, the pure-Python parser, which has no
    nesting limit: libyaml 0.2.6 (PyYAML 6.0.4) refuses 1,000 levels itself, while it still
    looks ahead for a simple key, before emitting the event at level 101. Which parser stops
    first must not decide the diagnostic: too deep is ``yaml-too-deep`` at level 101 with any
    release."""
    try:
        _scan_depth(text, file, _Loader)
    except yaml.YAMLError:
        try:
            _scan_depth(text, file, yaml.SafeLoader)
        except yaml.YAMLError:
            return  # a syntax error within the first MAX_DEPTH levels: the composer reports it, located


def _scan_depth(text: str, file: str, loader) -> None:
    depth = 0
    starts = (yaml.MappingStartEvent, yaml.SequenceStartEvent)
    ends = (yaml.MappingEndEvent, yaml.SequenceEndEvent)
    for ev in yaml.parse(text, Loader=loader):
        if isinstance(ev, starts):
            depth += 1
            if depth > MAX_DEPTH:
                m = ev.start_mark
                assert m is not None  # parsers always mark their events
                raise AdfError(
                    error(
                        "yaml-too-deep",
                        f"collections nest more than {MAX_DEPTH} levels deep here",
                        SourceLocation(file, m.line + 1, m.column + 1),
                        "an ADF file nests a few levels; flatten the data",
                    )
                )
        elif isinstance(ev, ends):
            depth -= 1


def compose(text: str, file: str, diagnostics: list[Diagnostic] | None = None) -> yaml.Node | None:
    """Parse YAML text into a node tree; syntax errors raise AdfError.

    Duplicate keys, keys that are not text and explicit tags with bad values are reported into
    ``diagnostics`` (AMBF keeps the first occurrence of a key, and so does :func:`mapping_items`).
    Nesting deeper than MAX_DEPTH, recursive aliases and alias bombs raise AdfError."""
    if _depth_bound(text) > _SAFE_BOUND:
        _check_depth(text, file)
    try:
        root = yaml.compose(text, Loader=_Loader)
    except yaml.YAMLError as exc:
        if _depth_bound(text) > MAX_DEPTH:  # a parser's own nesting limit is still yaml-too-deep, at level 101
            _check_depth(text, file)
        raise _syntax_error(exc, file, text) from None
    if root is not None:
        found = check_tree(root, file, check_tags="!" in text, aliases="*" in text)
        if diagnostics is not None:
            diagnostics.extend(found)
    return root


def check_tree(root: yaml.Node, file: str, check_tags: bool = True, aliases: bool = True) -> list[Diagnostic]:
    """Find duplicate keys, keys that are not text and explicit tags with bad values; reject
    recursive aliases, alias bombs and nesting deeper than MAX_DEPTH, with positions.

    An explicit stack, no recursion: any depth is walked. ``check_tags`` False skips the tag
    check (a text without '!' has no explicit tags); ``aliases`` False (no '*' in the text)
    walks the tree without the bookkeeping shared nodes need."""
    diags: list[Diagnostic] = []
    if not aliases:
        _check_alias_free(root, file, check_tags, diags)
        return diags
    sizes: dict[int, int] = {}
    on_stack: set[int] = set()
    Mapping, _Sequence, Scalar = yaml.MappingNode, yaml.SequenceNode, yaml.ScalarNode
    # Frames: [node, child iterator, size so far]; a node's size is counted when it is left.
    stack: list[list] = []

    def enter(node) -> int | None:
        """Push a collection (None) or return the size of a leaf / already-sized node."""
        cls = node.__class__
        if cls is Scalar:
            if check_tags and node.tag in _SCALAR_TAGS_CHECKED:
                _check_scalar_tag(node, file, diags)
            return 1
        nid = id(node)
        known = sizes.get(nid)
        if known is not None:
            return known
        if nid in on_stack:
            raise AdfError(
                error(
                    "yaml-recursive-alias",
                    "an alias refers to a node that contains it",
                    location(file, node),
                    "ADF data is a tree; replace the recursive alias with data",
                )
            )
        if len(stack) >= MAX_DEPTH:
            raise AdfError(
                error(
                    "yaml-too-deep",
                    f"collections nest more than {MAX_DEPTH} levels deep here",
                    location(file, node),
                    "an ADF file nests a few levels; flatten the data",
                )
            )
        on_stack.add(nid)
        if cls is Mapping:
            _check_keys(node, file, diags)
            children = (n for pair in node.value for n in pair)
        else:
            children = iter(node.value)
        stack.append([node, children, 1])
        return None

    first = enter(root)
    expanded = first if first is not None else 0
    while stack:
        frame = stack[-1]
        child = next(frame[1], None)
        if child is not None:
            size = enter(child)
            if size is not None:
                frame[2] += size
            continue
        stack.pop()
        node, _, size = frame
        on_stack.discard(id(node))
        sizes[id(node)] = size
        if stack:
            stack[-1][2] += size
        else:
            expanded = size
        if size > MAX_EXPANDED_NODES:
            break
    if expanded > MAX_EXPANDED_NODES or any(f[2] > MAX_EXPANDED_NODES for f in stack):
        raise AdfError(
            error(
                "yaml-alias-bomb",
                f"aliases expand this file to over {MAX_EXPANDED_NODES:,} nodes",
                location(file, root),
                "an ADF file never needs this; remove the nested aliases",
            )
        )
    return diags


def _check_alias_free(root: yaml.Node, file: str, check_tags: bool, diags: list[Diagnostic]) -> None:
    """check_tree for a tree without aliases: every node is visited once, so no sizes."""
    Mapping, Sequence, Scalar = yaml.MappingNode, yaml.SequenceNode, yaml.ScalarNode
    stack = [(root, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise AdfError(
                error(
                    "yaml-too-deep",
                    f"collections nest more than {MAX_DEPTH} levels deep here",
                    location(file, node),
                    "an ADF file nests a few levels; flatten the data",
                )
            )
        if node.__class__ is Mapping:
            _check_keys(node, file, diags)
            for k, v in node.value:
                cls = v.__class__
                if cls is not Scalar:
                    stack.append((v, depth + 1))
                elif check_tags and v.tag in _SCALAR_TAGS_CHECKED:
                    _check_scalar_tag(v, file, diags)
                if k.__class__ is not Scalar:
                    stack.append((k, depth + 1))
        elif node.__class__ is Sequence:
            for v in node.value:
                if v.__class__ is not Scalar:
                    stack.append((v, depth + 1))
                elif check_tags and v.tag in _SCALAR_TAGS_CHECKED:
                    _check_scalar_tag(v, file, diags)
        elif check_tags and node.tag in _SCALAR_TAGS_CHECKED:
            _check_scalar_tag(node, file, diags)  # type: ignore[arg-type]  # neither collection: a scalar


def _check_keys(node: yaml.MappingNode, file: str, diags: list[Diagnostic]) -> None:
    seen: dict[Any, yaml.Node] = {}
    Scalar = yaml.ScalarNode
    for k, _ in node.value:
        if k.__class__ is Scalar:
            kv = k.value
            if k.tag != STR_TAG:
                diags.append(
                    warning(
                        "yaml-key-type",
                        f"the key {_quote(kv)} is read as {_tag_name(k.tag)}, not text; "
                        "AMBF (yaml-cpp) compares it as the text written",
                        location(file, k),
                        "quote the key, or check the mapping: `{a, b}` is a mapping of two keys",
                    )
                )
            first = seen.get(kv)
            if first is not None:
                diags.append(
                    warning(  # AMBF loads the file (sb/cloth.yaml): every command reads it
                        "yaml-duplicate-key",
                        f"duplicate key {_quote(kv)} (first at line {first.start_mark.line + 1}); "
                        "AMBF keeps the first value, PyYAML the last",
                        location(file, k),
                        "remove one of the two entries",
                    )
                )
            else:
                seen[kv] = k
        else:
            diags.append(
                warning(
                    "yaml-key-type",
                    f"a {'mapping' if isinstance(k, yaml.MappingNode) else 'list'} "
                    "is used as a key; AMBF reads it as text",
                    location(file, k),
                    "use a text key",
                )
            )


def _check_scalar_tag(node: yaml.ScalarNode, file: str, diags: list[Diagnostic]) -> None:
    """A scalar whose (explicit) tag cannot construct its value: `!!bool maybe`."""
    construct = _constructor.yaml_constructors.get(node.tag)
    if construct is None:
        return
    try:
        construct(_constructor, node)
    except Exception:  # noqa: BLE001 - every constructor failure is the same finding
        diags.append(
            error(
                "yaml-bad-tag",
                f"{_quote(node.value)} is not a valid {_tag_name(node.tag)}",
                location(file, node),
                "remove the explicit tag (`!!...`) or fix the value",
            )
        )


def _tag_name(tag: str) -> str:
    return tag.rsplit(":", 1)[-1] if tag.startswith("tag:yaml.org,2002:") else tag


def _quote(text: str, limit: int = 60) -> str:
    r = repr(text)
    return r if len(r) <= limit else r[: limit - 5] + "...'"


def plain(node: yaml.Node) -> Any:
    """A node as plain Python data (what ``yaml.safe_load`` would give, but keys are always the
    text written, as AMBF's yaml-cpp compares them, and the first of duplicate keys wins).

    Iterative: any depth; aliases are shared, not copied."""
    if node.__class__ is yaml.ScalarNode:
        return _cached_value(node)
    made: dict[int, Any] = {}
    root_out: Any = [] if isinstance(node, yaml.SequenceNode) else {}
    made[id(node)] = root_out
    stack: list[tuple[yaml.Node, Any]] = [(node, root_out)]
    while stack:
        src, out = stack.pop()
        if src.__class__ is yaml.SequenceNode:
            for item in src.value:
                out.append(_plain_child(item, made, stack))
        else:
            for k, v in src.value:
                key = k.value if k.__class__ is yaml.ScalarNode else _key_text(k)
                if key not in out:
                    out[key] = _plain_child(v, made, stack)
    return root_out


def _plain_child(node, made: dict, stack: list):
    if node.__class__ is yaml.ScalarNode:
        return _cached_value(node)
    done = made.get(id(node))
    if done is not None:
        return done
    out: Any = [] if node.__class__ is yaml.SequenceNode else {}
    made[id(node)] = out
    stack.append((node, out))
    return out


def _key_text(node: yaml.Node) -> str:
    """A collection used as a key, as one line of text (yaml-cpp compares keys as text)."""
    parts: list[str] = []
    stack = [node]
    while stack and len(parts) < 200:
        n = stack.pop()
        if isinstance(n, yaml.ScalarNode):
            parts.append(n.value)
        else:
            items = [x for pair in n.value for x in pair] if isinstance(n, yaml.MappingNode) else list(n.value)
            stack.extend(reversed(items))
    return "[" + ", ".join(parts) + "]"


_VALUES: dict[tuple[str, str], Any] = {}


def _cached_value(node: yaml.ScalarNode) -> Any:
    """scalar_value, remembered per (tag, text): the values are immutable (str, int, float,
    bool, None) and ADF files repeat few texts."""
    key = (node.tag, node.value)
    try:
        return _VALUES[key]
    except KeyError:
        pass
    v = scalar_value(node)
    if len(_VALUES) < 200_000 and len(node.value) < 200:
        _VALUES[key] = v
    return v


def scalar_value(node: yaml.ScalarNode) -> Any:
    """A scalar as YAML 1.1 (PyYAML's safe schema) reads it; unknown tags, and values their
    tag cannot construct (`!!bool maybe`, reported by check_tree), stay text."""
    tag = node.tag
    if tag in _TEXT_TAGS:
        return node.value
    construct = _constructor.yaml_constructors.get(tag)
    if construct is None:
        return node.value
    try:
        return construct(_constructor, node)
    except Exception:  # noqa: BLE001 - KeyError, ValueError, AttributeError... all mean "not this type"
        return node.value


# yaml-cpp has no date or binary values: AMBF reads `2001-12-14` and `!!binary ...` as the text
# written, and so does adfkit (their Python types are not JSON either).
_TEXT_TAGS = frozenset({STR_TAG, "tag:yaml.org,2002:timestamp", "tag:yaml.org,2002:binary"})


def mapping_items(node: yaml.MappingNode) -> list[tuple[str, yaml.Node, yaml.Node]]:
    """(key text, key node, value node) for each entry; keys are compared as text like yaml-cpp."""
    out, seen = [], set()
    for k, v in node.value:
        text = k.value if isinstance(k, yaml.ScalarNode) else _key_text(k)
        if text not in seen:  # first occurrence wins, as in AMBF (yaml-cpp)
            seen.add(text)
            out.append((text, k, v))
    return out
