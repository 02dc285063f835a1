"""Output formats for validation results: text (with the source line and a caret), json,
github (workflow annotations) and sarif (2.1.0)."""

from __future__ import annotations

from pathlib import Path
from typing import IO

from .. import __version__, jsonout
from ..diagnostics import Diagnostic, Severity, one_line
from .rules import RULES

SARIF_SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"
_LEVEL = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "note"}
_GITHUB = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "notice"}


def _source_line(texts: dict[str, str | None], d: Diagnostic) -> str | None:
    """The offending line, only from a file being reported on (``texts``: what the validator
    read); never read from disk here, so no other file's content can be quoted."""
    if not d.location or not d.location.line:
        return None
    text = texts.get(d.location.file)
    if not text:
        return None
    lines = text.split("\n")
    if d.location.line > len(lines):
        return None
    line = lines[d.location.line - 1].rstrip("\r")
    return one_line(line[:400] + (" ..." if len(line) > 400 else ""))


def write_text(
    diags: list[Diagnostic],
    stream: IO[str],
    texts: dict[str, str | None] | None = None,
    summary: bool = True,
    files: int = 0,
) -> None:
    texts = dict(texts or {})
    for d in diags:
        where = f"{d.location}: " if d.location else ""
        stream.write(f"{where}{d.severity}[{d.rule}]: {one_line(d.message)}\n")
        line = _source_line(texts, d)
        if line is not None and d.location is not None:
            col = max(1, d.location.column)
            stream.write(f"  {d.location.line:>5} | {line}\n")
            stream.write(f"        | {' ' * (col - 1)}^\n")
        if d.hint:
            stream.write(f"  hint: {one_line(d.hint)}\n")
    if summary:
        counts = {s: sum(1 for d in diags if d.severity == s) for s in Severity}
        stream.write(
            f"{files} file(s) checked: {counts[Severity.ERROR]} error(s), "
            f"{counts[Severity.WARNING]} warning(s), {counts[Severity.INFO]} info\n"
        )


def _dict(d: Diagnostic) -> dict:
    loc = d.location
    return {
        "file": loc.file if loc else None,
        "line": loc.line if loc else None,
        "column": loc.column if loc else None,
        "severity": str(d.severity),
        "rule": d.rule,
        "message": d.message,
        "hint": d.hint,
    }


def write_json(diags: list[Diagnostic], stream: IO[str], files: int = 0) -> None:
    jsonout.dump({"files": files, "diagnostics": [_dict(d) for d in diags]}, stream, indent=2)
    stream.write("\n")


def _escape_data(s: str) -> str:
    return s.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def _escape_prop(s: str) -> str:
    return _escape_data(s).replace(":", "%3A").replace(",", "%2C")


def github_line(d: Diagnostic) -> str:
    props = []
    if d.location:
        props.append(f"file={_escape_prop(d.location.file)}")
        if d.location.line:
            props.append(f"line={d.location.line}")
            props.append(f"col={max(1, d.location.column)}")
    props.append(f"title={_escape_prop(d.rule)}")
    message = d.message + (f"\n{d.hint}" if d.hint else "")
    return f"::{_GITHUB[d.severity]} {','.join(props)}::{_escape_data(message)}"


def write_github(diags: list[Diagnostic], stream: IO[str]) -> None:
    for d in diags:
        stream.write(github_line(d) + "\n")


def _uri(file: str) -> str:
    p = Path(file)
    try:
        return p.resolve().relative_to(Path.cwd().resolve()).as_posix()
    except ValueError:
        return p.resolve().as_uri()


def sarif(diags: list[Diagnostic]) -> dict:
    used = sorted({d.rule for d in diags})
    rules = []
    for rid in used:
        r = RULES.get(rid)
        entry = {"id": rid, "shortDescription": {"text": r.summary if r else rid}}
        if r:
            entry["fullDescription"] = {"text": f"{r.summary}. Example: {r.example}"}
            entry["defaultConfiguration"] = {"level": _LEVEL[r.severity]}
        rules.append(entry)
    index = {rid: i for i, rid in enumerate(used)}
    results = []
    for d in diags:
        res = {
            "ruleId": d.rule,
            "ruleIndex": index[d.rule],
            "level": _LEVEL[d.severity],
            "message": {"text": d.message + (f" Hint: {d.hint}" if d.hint else "")},
        }
        if d.location:
            phys: dict = {"artifactLocation": {"uri": _uri(d.location.file)}}
            if d.location.line:
                phys["region"] = {"startLine": d.location.line, "startColumn": max(1, d.location.column)}
            res["locations"] = [{"physicalLocation": phys}]
        results.append(res)
    return {
        "$schema": SARIF_SCHEMA,
        "version": "2.1.0",
        "runs": [
            {
                "tool": {
                    "driver": {
                        "name": "adfkit",
                        "version": __version__,
                        "informationUri": "https://github.com/WPI-AIM/ambf",
                        "rules": rules,
                    }
                },
                "columnKind": "unicodeCodePoints",
                "results": results,
            }
        ],
    }


def write_sarif(diags: list[Diagnostic], stream: IO[str]) -> None:
    jsonout.dump(sarif(diags), stream, indent=2)
    stream.write("\n")
