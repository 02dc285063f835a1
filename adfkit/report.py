"""Printing diagnostics and progress for people: text on a terminal, quiet when piped."""

from __future__ import annotations

import sys
import time
from collections.abc import Iterable
from typing import IO

from .diagnostics import Diagnostic


def print_diagnostics(diags: Iterable[Diagnostic], stream: IO[str] | None = None) -> None:
    stream = stream or sys.stderr
    for d in diags:
        print(d.format(), file=stream)


class Progress:
    """A one-line progress bar on a terminal (stderr); silent when stderr is not a TTY.

    ``extra`` is a callable returning text shown after the counts (e.g. a real-time factor).
    """

    def __init__(
        self,
        total: int | None,
        label: str = "",
        stream: IO[str] | None = None,
        enabled: bool | None = None,
        min_interval: float = 0.1,
    ):
        self.total, self.label = total, label
        self.stream = stream or sys.stderr
        self.enabled = self.stream.isatty() if enabled is None else enabled
        self.count = 0
        self.start = time.monotonic()
        self._last = 0.0
        self.min_interval = min_interval
        self.suffix = ""

    def update(self, n: int = 1, suffix: str | None = None) -> None:
        self.count += n
        if suffix is not None:
            self.suffix = suffix
        now = time.monotonic()
        if self.enabled and (now - self._last >= self.min_interval or self.count == self.total):
            self._last = now
            self._draw(now)

    def _draw(self, now: float) -> None:
        elapsed = now - self.start
        if self.total:
            frac = min(1.0, self.count / self.total)
            bar = "#" * int(frac * 30)
            head = f"{self.label} [{bar:<30}] {self.count}/{self.total} {frac:5.1%}"
        else:
            head = f"{self.label} {self.count}"
        self.stream.write(f"\r{head} {elapsed:6.1f}s {self.suffix}\x1b[K")
        self.stream.flush()

    def close(self) -> None:
        if self.enabled:
            self._draw(time.monotonic())
            self.stream.write("\n")
            self.stream.flush()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
