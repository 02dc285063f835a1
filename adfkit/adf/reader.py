"""Read ADF files into the scene model, walking the field declarations of adfkit.model.

A value that cannot be decoded becomes a located diagnostic and is kept verbatim in the
element's ``extras`` so that writing the file back loses nothing.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import yaml

from .. import inputs
from ..diagnostics import AdfError, Diagnostic, Severity, SourceLocation, error, warning
from ..model import FILE_KINDS, AdfFile, Colors, Pose, Quat, Vec3
from ..model.common import RGBA
from ..model.files import ObjectList
from ..model.pose import rpy_to_quat_kept
from ..model.spec import FloatOr, ListOf, Node, Obj, adf_fields
from .kinds import detect_kind
from .yamlnodes import STR_TAG, compose, location, mapping_items, plain, read_text, scalar_value

_BOOL_WORDS = {"true": True, "yes": True, "on": True, "y": True, "false": False, "no": False, "off": False, "n": False}


_NUMBER_TAGS = ("tag:yaml.org,2002:float", "tag:yaml.org,2002:int")


class BadValue(Exception):
    def __init__(self, rule: str, message: str, node: yaml.Node, hint: str | None = None, severity=Severity.ERROR):
        super().__init__(message)
        self.rule, self.message, self.node, self.hint, self.severity = rule, message, node, hint, severity


class Reader:
    def __init__(self, file: str):
        self.file = file
        self.diagnostics: list[Diagnostic] = []

    def loc(self, node) -> SourceLocation:
        return location(self.file, node)

    # --- scalars -------------------------------------------------------------------------
    def scalar(self, node, what: str) -> Any:
        if not isinstance(node, yaml.ScalarNode):
            raise BadValue("bad-type", f"expected {what}, found a {_shape(node)}", node)
        return scalar_value(node)

    def as_float(self, node) -> float:
        v = self._number(node)
        if v - v != 0.0:  # NaN or infinite (faster than math.isfinite on the hot path)
            raise BadValue(
                "non-finite-number",
                f"{_short(node.value)} is not a finite number",
                node,
                "write a finite number; Bullet turns NaN and infinity into a broken simulation",
            )
        return v

    def _number(self, node) -> float:
        if node.__class__ is yaml.ScalarNode and node.tag in _NUMBER_TAGS:
            try:  # fast path for plain decimal literals
                return float(node.value)
            except (ValueError, OverflowError):
                pass
        v = self.scalar(node, "a number")
        if isinstance(v, bool) or v is None:
            raise BadValue("bad-type", f"expected a number, found {_short(node.value)}", node)
        try:
            if isinstance(v, (int, float)):
                return float(v)
            return float(str(v).strip())  # AMBF (yaml-cpp) reads quoted numbers as doubles
        except OverflowError:  # a 400-digit integer: what strtod makes of it
            return math.inf
        except ValueError:
            raise BadValue("bad-type", f"expected a number, found {_short(node.value)}", node) from None

    def as_bool(self, node) -> bool:
        v = self.scalar(node, "true or false")
        if isinstance(v, bool):
            return v
        if (
            isinstance(v, str)
            and v.strip().lower() in _BOOL_WORDS
            and (v.strip() in (v.strip().lower(), v.strip().upper(), v.strip().capitalize()))
        ):
            return _BOOL_WORDS[v.strip().lower()]
        raise BadValue(
            "bad-bool",
            f"expected true or false, found {_short(node.value)}",
            node,
            "AMBF reads true/false/yes/no/on/off/y/n; 1 and 0 make it reject the file",
        )

    def as_int(self, node, unsigned: bool = False) -> int:
        v = self.scalar(node, "an integer")
        if isinstance(v, str):
            try:
                v = int(v.strip())
            except ValueError:
                pass
        if isinstance(v, bool) or not isinstance(v, int):
            raise BadValue(
                "bad-int",
                f"expected an integer, found {_short(node.value)}",
                node,
                "AMBF rejects the file when an integer field holds 2.5 or 5.0",
            )
        if unsigned and v < 0:
            raise BadValue("bad-int", f"expected a non-negative integer, found {_short(node.value)}", node)
        if not -(2**63) <= v < 2**64:
            raise BadValue(
                "bad-int",
                f"{_short(node.value)} is out of range for an integer",
                node,
                "AMBF reads integers as 32-bit values",
            )
        return v

    def as_str(self, node) -> str:
        self.scalar(node, "text")
        if node.tag != STR_TAG and node.value in ("", "~", "null", "Null", "NULL"):
            raise BadValue("bad-type", "expected text, found an empty value", node)
        return node.value

    def fields3(self, node, names: tuple[str, str, str], what: str) -> tuple[float, float, float]:
        if not isinstance(node, yaml.MappingNode):
            raise BadValue(
                "bad-type", f"expected a {what} mapping {{{', '.join(names)}}}, found a {_shape(node)}", node
            )
        got = {k: v for k, _, v in mapping_items(node)}
        missing = [n for n in names if n not in got]
        if missing:
            raise BadValue(
                "missing-component",
                f"{what} lacks {', '.join(missing)}",
                node,
                f"write all of {', '.join(names)}; AMBF rejects the file otherwise",
            )
        extra = [k for k in got if k not in names]
        if extra:
            self.diagnostics.append(
                warning("unknown-key", f"{what} ignores key(s) {', '.join(extra)}", self.loc(got[extra[0]]))
            )
        return tuple(self.as_float(got[n]) for n in names)  # type: ignore[return-value]

    def as_vec3(self, node) -> Vec3:
        return Vec3(*self.fields3(node, ("x", "y", "z"), "vector"))

    def as_rpy(self, node) -> Quat:
        # the angles as written are kept: a writer gives them back unchanged (pose.written_rpy)
        return rpy_to_quat_kept(*self.fields3(node, ("r", "p", "y"), "orientation"))

    def as_pose(self, node) -> Pose:
        if not isinstance(node, yaml.MappingNode):
            raise BadValue("bad-type", f"expected a pose {{position, orientation}}, found a {_shape(node)}", node)
        got = {k: v for k, _, v in mapping_items(node)}
        extra = [k for k in got if k not in ("position", "orientation")]
        if extra:
            raise BadValue(
                "bad-pose",
                f"a pose holds position and orientation, not {', '.join(extra)}; "
                "AMBF ignores the block and uses the identity pose",
                node,
                "write {position: {x, y, z}, orientation: {r, p, y}}",
                Severity.WARNING,
            )
        pos = self.as_vec3(got["position"]) if "position" in got else Vec3()
        rot = self.as_rpy(got["orientation"]) if "orientation" in got else Quat()
        return Pose(pos, rot)

    # --- generic field walk ----------------------------------------------------------------
    def value(self, kind, node) -> Any:
        if kind == "float":
            v = self.as_float(node)
            return v
        if kind == "bool":
            return self.as_bool(node)
        if kind == "int":
            return self.as_int(node)
        if kind == "uint":
            return self.as_int(node, unsigned=True)
        if kind == "str":
            return self.as_str(node)
        if kind == "vec3":
            return self.as_vec3(node)
        if kind == "rpy":
            return self.as_rpy(node)
        if kind == "pose":
            return self.as_pose(node)
        if kind == "any":
            return plain(node)
        if isinstance(kind, ListOf):
            if not isinstance(node, yaml.SequenceNode):
                raise BadValue("bad-type", f"expected a list, found a {_shape(node)}", node)
            return [self.value(kind.item, n) for n in node.value]
        if isinstance(kind, FloatOr):
            if isinstance(node, yaml.MappingNode):
                return self.struct(kind.struct, node)
            return self.as_float(node)
        if isinstance(kind, type) and issubclass(kind, Node):
            if not isinstance(node, yaml.MappingNode):
                raise BadValue("bad-type", f"expected a mapping, found a {_shape(node)}", node)
            return self.struct(kind, node)
        raise TypeError(f"unknown field kind {kind!r}")  # pragma: no cover

    def fill(self, obj: Node, node: yaml.MappingNode, skip: frozenset[str] | set[str] = frozenset()) -> None:
        """Set obj's declared fields from a mapping node; unknown keys go to extras."""
        by_key = {f.metadata["adf_key"]: f for f in adf_fields(obj) if not isinstance(f.metadata["kind"], ObjectList)}
        obj.source = self.loc(node)
        for text, _knode, vnode in mapping_items(node):
            if text in skip:
                continue
            obj.key_sources[text] = self.loc(vnode)
            f = by_key.get(text)
            if f is None or _is_null(vnode):
                obj.extras[text] = plain(vnode)
                continue
            try:
                setattr(obj, f.name, self.value(f.metadata["kind"], vnode))
            except BadValue as bad:
                self.report(bad, text)
                obj.extras[text] = plain(vnode)

    def report(self, bad: BadValue, key_text: str) -> None:
        self.diagnostics.append(
            Diagnostic(bad.severity, bad.rule, f"'{key_text}': {bad.message}", self.loc(bad.node), bad.hint)
        )

    def struct(self, cls, node: yaml.MappingNode):
        obj = cls()
        self.fill(obj, node)
        return obj


def _is_null(node) -> bool:
    return isinstance(node, yaml.ScalarNode) and node.tag == "tag:yaml.org,2002:null"


def _short(text, limit: int = 60) -> str:
    """A value quoted in a message: repr, at most ``limit`` characters."""
    r = repr(text)
    return r if len(r) <= limit else r[: limit - 5] + "...'"


def _shape(node) -> str:
    if isinstance(node, yaml.MappingNode):
        return "mapping"
    if isinstance(node, yaml.SequenceNode):
        return "list"
    return f"scalar {_short(node.value)}"


def read_file(
    path: str | Path,
    kind: str | None = None,
    text: str | None = None,
    root_out: list | None = None,
    tree: inputs.Tree | None = None,
    referrer: SourceLocation | None = None,
) -> tuple[AdfFile, list[Diagnostic]]:
    """Read one ADF file. Returns the model element and the diagnostics met on the way.

    Raises AdfError when the file cannot be read at all (missing, not YAML, wrong kind).
    ``root_out``, if given, receives the composed YAML root node (the validator reuses it).
    ``tree`` None: the user named this file (read wherever it is; its own tree is computed
    for the files it names). Otherwise the file was named by another one (``referrer``) and
    must lie inside ``tree`` (adfkit.inputs).
    """
    path = Path(path)
    shown = str(path)
    if text is None:
        text = read_text(path, tree, referrer)
    reader = Reader(shown)
    root = compose(text, shown, reader.diagnostics)
    if root_out is not None:
        root_out.append(root)
    if root is None:
        raise AdfError(
            error(
                "empty-file",
                "the file is empty",
                SourceLocation(shown, 1, 1),
                "an ADF file is a YAML mapping of keys such as bodies:, joints: or world config:",
            )
        )
    if not isinstance(root, yaml.MappingNode):
        raise AdfError(
            error(
                "not-a-mapping",
                f"the top level is a {_shape(root)}, not a mapping",
                location(shown, root),
                "an ADF file is a YAML mapping of keys",
            )
        )
    keys = [k for k, _, _ in mapping_items(root)]
    detected = detect_kind(keys, {k: v for k, _, v in mapping_items(root)})
    if kind is None:
        if detected is None:
            raise AdfError(
                error(
                    "unknown-kind",
                    "cannot tell which kind of ADF file this is",
                    location(shown, root),
                    "a launch file has 'world config', a world 'environment', a model 'bodies' "
                    "or 'joints', an input-devices file 'input devices'; or pass --kind",
                )
            )
        kind = detected
    elif kind not in FILE_KINDS:
        raise AdfError(
            error(
                "unknown-kind",
                f"unknown file kind '{kind}'",
                SourceLocation(shown),
                f"use one of {', '.join(FILE_KINDS)}",
            )
        )
    elif detected is not None and detected != kind:
        raise AdfError(
            error(
                "wrong-kind",
                f"this looks like a {detected} file, not a {kind} file",
                location(shown, root),
                f"pass --kind {detected}, or the file meant for this slot",
            )
        )
    cls = FILE_KINDS[kind]
    obj: AdfFile
    if cls is Colors:
        obj = _read_colors(reader, root)
    else:
        obj = _read_with_objects(reader, cls, root)
    obj.path = path
    obj.tree = tree if tree is not None else inputs.tree_of(path)
    return obj, reader.diagnostics


def _read_with_objects(reader: Reader, cls, root: yaml.MappingNode) -> AdfFile:
    obj = cls()
    items = {k: (kn, v) for k, kn, v in mapping_items(root)}
    consumed: set[str] = set()
    for f in adf_fields(cls):
        kind = f.metadata["kind"]
        if not isinstance(kind, ObjectList):
            continue
        list_key = f.metadata["adf_key"]
        if list_key not in items:
            continue
        consumed.add(list_key)
        obj.present_lists.add(list_key)
        _, lnode = items[list_key]
        objects: list[Obj] = []
        if _is_null(lnode):
            setattr(obj, f.name, objects)
            continue
        if not isinstance(lnode, yaml.SequenceNode):
            reader.diagnostics.append(
                error(
                    "bad-type",
                    f"'{list_key}' must be a list of names, found a {_shape(lnode)}",
                    reader.loc(lnode),
                    f"write {list_key}: [NAME, ...]",
                )
            )
            obj.extras[list_key] = plain(lnode)
            obj.present_lists.discard(list_key)
            continue
        for entry in lnode.value:
            if not isinstance(entry, yaml.ScalarNode) or _is_null(entry):
                reader.diagnostics.append(
                    error(
                        "bad-type",
                        f"'{list_key}' entries are names of mappings in this file, found a {_shape(entry)}",
                        reader.loc(entry),
                        "list the key of each object's mapping",
                    )
                )
                continue
            ident = entry.value
            item = kind.kind(identifier=ident)
            mapping = items[ident][1] if ident in items else None
            if isinstance(mapping, yaml.MappingNode):
                reader.fill(item, mapping)
                consumed.add(ident)
            elif mapping is not None and _is_null(mapping):
                # `BODY x:` with nothing under it: AMBF's loader skips the object (its node is
                # null: "RIGID BODY ... NODE IS NULL", and alike for every kind), where a listed
                # key with no mapping at all gets an object built from an empty node
                reader.diagnostics.append(
                    warning(
                        "undefined-object",
                        f"'{ident}' is listed in '{list_key}' but its mapping is empty; AMBF skips it",
                        reader.loc(mapping),
                        f"give '{ident}:' its keys or remove it from the list",
                    )
                )
                continue
            else:
                item.defined = False
                item.source = reader.loc(entry)
                reader.diagnostics.append(
                    warning(
                        "undefined-object",
                        f"'{ident}' is listed in '{list_key}' but has no mapping in this file",
                        reader.loc(entry),
                        f"add a mapping '{ident}:' or remove it from the list; AMBF builds an empty object",
                    )
                )
            objects.append(item)
        setattr(obj, f.name, objects)
    rest = yaml.MappingNode(
        root.tag, [(kn, v) for k, (kn, v) in items.items() if k not in consumed], root.start_mark, root.end_mark
    )
    reader.fill(obj, rest)
    obj.source = reader.loc(root)
    return obj


def _read_colors(reader: Reader, root: yaml.MappingNode) -> Colors:
    colors = Colors()
    colors.source = reader.loc(root)
    for text, _, vnode in mapping_items(root):
        if isinstance(vnode, yaml.MappingNode) and {k for k, _, _ in mapping_items(vnode)} <= {"r", "g", "b", "a"}:
            try:
                colors.colors[text] = reader.struct(RGBA, vnode)
                continue
            except BadValue as bad:
                reader.report(bad, text)
        colors.extras[text] = plain(vnode)
    return colors


def load(path: str | Path, kind: str | None = None) -> AdfFile:
    """Read one ADF file; raise AdfError if it has any error-level diagnostic."""
    obj, diags = read_file(path, kind)
    errors = [d for d in diags if d.severity >= 2]
    if errors:
        raise AdfError(errors)
    return obj


__all__ = ["read_file", "load", "Reader", "math"]
