"""Strict JSON for everything adfkit prints or writes: no bare NaN or Infinity (invalid JSON
that most parsers refuse). A non-finite number becomes ``null`` and, in an object at the top,
its path is listed under ``"non_finite"`` so that the null is explained, not silent."""

from __future__ import annotations

import json
import math
from typing import IO, Any


def finite(obj: Any) -> tuple[Any, list[str]]:
    """``obj`` with every non-finite float replaced by None, and the paths replaced."""
    notes: list[str] = []
    root: list[Any] = [None]
    stack: list[tuple[Any, list | dict, Any, str]] = [(obj, root, 0, "")]
    while stack:  # explicit stack: any depth
        value, holder, key, path = stack.pop()
        if isinstance(value, float) and not math.isfinite(value):
            notes.append(path or "$")
            holder[key] = None
        elif isinstance(value, dict):
            out: dict = {}
            holder[key] = out
            for k, v in value.items():
                out[k] = None
                stack.append((v, out, k, f"{path}.{k}" if path else str(k)))
        elif isinstance(value, (list, tuple)):
            seq: list = [None] * len(value)
            holder[key] = seq
            for i, v in enumerate(value):
                stack.append((v, seq, i, f"{path}[{i}]"))
        else:
            holder[key] = value
    return root[0], sorted(notes)


def dumps(obj: Any, **kw) -> str:
    """``json.dumps`` with ``allow_nan=False`` after :func:`finite`."""
    clean, notes = finite(obj)
    if notes and isinstance(clean, dict):
        clean["non_finite"] = notes
    return json.dumps(clean, allow_nan=False, **kw)


def dump(obj: Any, stream: IO[str], **kw) -> None:
    stream.write(dumps(obj, **kw))
