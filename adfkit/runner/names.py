"""AMBF's object keys and string lookup (adf-format.md §12.1)."""

from __future__ import annotations

import re


def merge_namespace(parent: str | None, child: str | None) -> str:
    """A child namespace starting with '/' replaces the parent; otherwise the two are concatenated."""
    parent, child = parent or "", child or ""
    out = child if child.startswith("/") else parent + child
    return re.sub("/{2,}", "/", out)


class Registry:
    """Objects keyed namespace + identifier; lookup is exact, else a unique substring match."""

    def __init__(self) -> None:
        self.items: dict[str, object] = {}

    def add(self, key: str, value: object) -> str:
        k, n = key, 0
        while k in self.items:
            n += 1
            k = f"{key}{n}"
        self.items[k] = value
        return k

    def find(self, text: str | None):
        """(key, value), or (None, candidates list) when not found or ambiguous."""
        if not text:
            return None, []
        if text in self.items:
            return text, self.items[text]
        hits = [k for k in self.items if text in k]
        if len(hits) == 1:
            return hits[0], self.items[hits[0]]
        return None, hits
