"""Declarative link between model fields and ADF keys.

Every model field that mirrors an ADF key is declared with :func:`key`, naming the key
exactly as AMBF spells it and the kind of value it holds. The ADF reader and writer walk
these declarations, so a field added here is read, written and round-tripped everywhere.
A field left ``None`` was not written by the user; effective defaults live in
``adfkit.model.defaults``.
"""

from __future__ import annotations

from dataclasses import MISSING, dataclass, field, fields
from functools import cache
from typing import Any

from ..diagnostics import SourceLocation

# Scalar kinds understood by the reader/writer.
SCALAR_KINDS = {"float", "bool", "int", "uint", "str", "vec3", "pose", "rpy", "any"}


@dataclass(frozen=True)
class ListOf:
    item: Any


@dataclass(frozen=True)
class FloatOr:
    """A key that holds either a number or a structured block (six-dof spring gains)."""

    struct: type


def key(adf_key: str, kind: Any, *, default: Any = None, default_factory: Any = MISSING) -> Any:
    meta = {"adf_key": adf_key, "kind": kind}
    if default_factory is not MISSING:
        return field(default_factory=default_factory, metadata=meta)
    return field(default=default, metadata=meta)


@dataclass(kw_only=True)
class Node:
    """Base of every model element: unknown keys and source positions travel with it."""

    extras: dict[str, Any] = field(default_factory=dict)
    source: SourceLocation | None = field(default=None, compare=False, repr=False)
    key_sources: dict[str, SourceLocation] = field(default_factory=dict, compare=False, repr=False)

    def where(self, adf_key: str | None = None) -> SourceLocation | None:
        """Location of one key's value, or of the element itself."""
        if adf_key is not None and adf_key in self.key_sources:
            return self.key_sources[adf_key]
        return self.source


@dataclass(kw_only=True)
class Obj(Node):
    """A top-level ADF object: a mapping in a file, listed by its identifier (mapping key)."""

    identifier: str = ""
    # False when the identifier is listed but the file has no mapping for it (AMBF then
    # builds the object from an empty node).
    defined: bool = True


@cache
def _adf_fields_of(cls: type) -> tuple:
    return tuple(f for f in fields(cls) if "adf_key" in f.metadata)


@cache
def _adf_keys_of(cls: type) -> frozenset:
    return frozenset(f.metadata["adf_key"] for f in _adf_fields_of(cls))


def adf_fields(cls_or_obj) -> list:
    """The dataclass fields of an element that mirror ADF keys, in declaration order
    (computed once per class: the reader and the validator ask for every element)."""
    return list(_adf_fields_of(cls_or_obj if isinstance(cls_or_obj, type) else type(cls_or_obj)))


def adf_keys(cls_or_obj) -> frozenset[str]:
    return _adf_keys_of(cls_or_obj if isinstance(cls_or_obj, type) else type(cls_or_obj))
