"""Layouts yaml-cpp (AMBF) reads but PyYAML rejects (adf-format.md §1, invariant 1).

The one known case (``rover_car/rover_info.yaml``) is a flow collection opened on the line
after its key, at or left of the key's indentation::

    suspension: &default_suspension
    {
      stiffness: 20.0,
    }

yaml-cpp accepts it; PyYAML stops with "could not find expected ':'". :func:`repair`
indents such blocks so PyYAML can read the file with unchanged line numbers, and
:func:`read_as_ambf` reads a file that way with a ``pyyaml-unparseable`` warning (the file is
fine for AMBF, only PyYAML-based tools choke on it) instead of a syntax error: what the validator
and the scene loader read.
"""

from __future__ import annotations

import re

from ..diagnostics import AdfError, Diagnostic, Severity, SourceLocation
from .reader import read_file

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


def read_as_ambf(path, kind: str | None = None, *, text: str | None = None, root_out=None, tree=None, referrer=None):
    """``read_file``, retrying a layout yaml-cpp accepts and PyYAML does not (``repair``):
    (document, diagnostics, the text read, the lines moved). The retry adds a located
    ``pyyaml-unparseable`` warning; a file still unreadable raises the first syntax error."""
    from .yamlnodes import read_text

    roots = root_out if root_out is not None else []
    if text is None:
        text = read_text(path, tree, referrer)
    try:
        doc, diags = read_file(path, kind, text=text, root_out=roots, tree=tree, referrer=referrer)
        return doc, diags, text, []
    except AdfError as exc:
        if not exc.diagnostics or exc.diagnostics[0].rule != "yaml-syntax":
            raise
        fixed, moved = repair(text)
        if not moved:
            raise
        try:
            roots.clear()
            doc, diags = read_file(path, kind, text=fixed, root_out=roots, tree=tree, referrer=referrer)
        except AdfError as again:
            if again.diagnostics and again.diagnostics[0].rule == "yaml-syntax":
                raise exc from None
            raise
        first = exc.diagnostics[0]
        note = Diagnostic(
            Severity.WARNING,
            "pyyaml-unparseable",
            f"PyYAML cannot parse this file ({first.message.removeprefix('not valid YAML: ')}), "
            f"but AMBF's yaml-cpp does: a flow collection starts at its key's indentation "
            f"(line {moved[0]}). Read after re-indenting it",
            SourceLocation(str(path), moved[0], 1),
            "indent the '{' or '[' block under its key so every YAML tool reads the file",
        )
        return doc, [note, *diags], fixed, moved
