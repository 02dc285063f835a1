"""Layouts yaml-cpp (AMBF) reads but PyYAML rejects (adf-format.md §1, invariant 1).

The one known case (``rover_car/rover_info.yaml``) is a flow collection opened on the line
after its key, at or left of the key's indentation::

    suspension: &default_suspension
    {
      stiffness: 20.0,
    }

yaml-cpp accepts it; PyYAML stops with "could not find expected ':'". :func:`repair`
indents such blocks so PyYAML can read the file with unchanged line numbers, and the
validator reports ``pyyaml-unparseable`` (a warning: the file is fine for AMBF, only
PyYAML-based tools choke on it) instead of a syntax error.
"""

from __future__ import annotations

import re

_KEY_LINE = re.compile(r"^(\s*)[^#\s][^#]*:\s*(&\S+\s*)?(#.*)?$")


def repair(text: str) -> tuple[str, list[int]]:
    """Indent flow blocks that start at or left of their key; returns (text, 1-based lines moved)."""
    lines = text.split("\n")
    moved: list[int] = []
    i = 0
    prev_key_indent = None
    while i < len(lines):
        line = lines[i]
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if prev_key_indent is not None and stripped[:1] in ("{", "[") and indent <= prev_key_indent:
            shift = " " * (prev_key_indent + 2 - indent)
            depth = 0
            j = i
            while j < len(lines):
                depth += _depth_change(lines[j])
                lines[j] = shift + lines[j]
                moved.append(j + 1)
                j += 1
                if depth <= 0:
                    break
            i = j
            prev_key_indent = None
            continue
        if stripped and not stripped.startswith("#"):
            m = _KEY_LINE.match(line)
            prev_key_indent = len(m.group(1)) if m else None
        i += 1
    return "\n".join(lines), moved


def _depth_change(line: str) -> int:
    code = line.split("#", 1)[0]
    return code.count("{") + code.count("[") - code.count("}") - code.count("]")
