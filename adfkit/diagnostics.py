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
    def parse(cls, text: str) -> "Severity":
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
        where = f"{self.location}: " if self.location else ""
        text = f"{where}{self.severity}[{self.rule}]: {self.message}"
        if self.hint:
            text += f"\n  hint: {self.hint}"
        return text

    def __str__(self) -> str:
        return self.format()


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
