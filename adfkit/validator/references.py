"""AMBF's lookup of objects by string (adf-format.md §12.1): namespaced keys, exact match
first, then the unique key containing the string."""

from __future__ import annotations

import re


def merge_namespace(parent: str | None, child: str | None) -> str:
    parent, child = parent or "", child or ""
    if child.startswith("/"):
        merged = child
    else:
        merged = parent + child
    return re.sub("/{2,}", "/", merged)


def object_key(model_namespace: str | None, obj) -> str:
    return merge_namespace(model_namespace, getattr(obj, "namespace", None)) + obj.identifier


class Registry:
    """Keys of the objects AMBF would have registered, with the object each names."""

    def __init__(self) -> None:
        self.keys: dict[str, object] = {}

    def add(self, key: str, obj) -> None:
        self.keys.setdefault(key, obj)

    def lookup(self, text: str, prefixed: str | None = None) -> tuple[str, list[str]]:
        """('found', [key]) / ('ambiguous', keys) / ('missing', []).

        ``prefixed`` is the string with the referring object's namespace prepended; AMBF
        tries it exactly before giving up on an ambiguous substring."""
        if text in self.keys:
            return "found", [text]
        if prefixed is not None and prefixed in self.keys:
            return "found", [prefixed]
        hits = [k for k in self.keys if text in k]
        if len(hits) == 1:
            return "found", hits
        if hits:
            return "ambiguous", hits
        return "missing", []


def body_registry(models) -> Registry:
    reg = Registry()
    for m in models:
        for b in m.bodies:
            reg.add(object_key(m.namespace, b), b)
    return reg


def camera_registry(models) -> Registry:
    """The cameras of ``models``: AMBF finds a parent among every object, and cameras are
    parents of cameras and lights (the drilling projects' stereoL under main_camera)."""
    reg = Registry()
    for m in models:
        for c in m.cameras:
            reg.add(object_key(m.namespace, c), c)
    return reg
