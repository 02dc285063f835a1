"""One diagnostic type for every module: severity, rule id, message, file:line:col, hint."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum


class Severity(IntEnum):
    INFO = 0
    WARNING = 1
    ERROR = 2

    def __str__(self) -> str:  # "error", "warning", "info"
        return self.name.lower()

    @classmethod
    def parse(cls, text: str) -> Severity:
        return cls[text.upper()]


@dataclass(frozen=True, order=True)
class SourceLocation:
    """Where something came from; line and column are 1-based."""

    file: str
    line: int = 0
    column: int = 0

    def __str__(self) -> str:
        if self.line:
            return f"{self.file}:{self.line}:{self.column}"
        return self.file


@dataclass(frozen=True)
class Diagnostic:
    severity: Severity
    rule: str
    message: str
    location: SourceLocation | None = None
    hint: str | None = None
    related: tuple[SourceLocation, ...] = field(default=())

    def format(self) -> str:
        where = f"{one_line(str(self.location))}: " if self.location else ""
        text = f"{where}{self.severity}[{self.rule}]: {one_line(self.message)}"
        if self.hint:
            text += f"\n  hint: {one_line(self.hint)}"
        return text

    def __str__(self) -> str:
        return self.format()


_CONTROL = {c: f"\\x{c:02x}" for c in (*range(9), *range(10, 32), 127)}
_CONTROL.update({0x85: "\\x85", 0x2028: "\\u2028", 0x2029: "\\u2029"})


def one_line(text: str) -> str:
    """Text for one output line: control characters (newlines included) escaped, so a name
    or value from a file can never start a line of its own in a report."""
    return text.translate(_CONTROL)


class AdfError(Exception):
    """A user's mistake that stops the work; carries the diagnostics that explain it."""

    def __init__(self, diagnostics: list[Diagnostic] | Diagnostic):
        if isinstance(diagnostics, Diagnostic):
            diagnostics = [diagnostics]
        self.diagnostics = list(diagnostics)
        super().__init__("\n".join(d.format() for d in self.diagnostics))


def error(rule: str, message: str, location: SourceLocation | None = None, hint: str | None = None) -> Diagnostic:
    return Diagnostic(Severity.ERROR, rule, message, location, hint)


def warning(rule: str, message: str, location: SourceLocation | None = None, hint: str | None = None) -> Diagnostic:
    return Diagnostic(Severity.WARNING, rule, message, location, hint)


def info(rule: str, message: str, location: SourceLocation | None = None, hint: str | None = None) -> Diagnostic:
    return Diagnostic(Severity.INFO, rule, message, location, hint)
