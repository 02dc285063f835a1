"""JSON Schemas (draft 2020-12) of the ADF file kinds, shipped as package data.

Generated from :mod:`adfkit.model` by ``python -m adfkit.validator.schemagen``.
"""

from __future__ import annotations

import json
from functools import cache
from importlib import resources

KINDS = ("launch", "world", "input_devices", "model", "colors")


def schema_file(kind: str):
    if kind not in KINDS:
        raise KeyError(f"unknown ADF file kind {kind!r}; one of {', '.join(KINDS)}")
    return resources.files(__name__).joinpath(f"{kind}.schema.json")


@cache
def load_schema(kind: str) -> dict:
    return json.loads(schema_file(kind).read_text(encoding="utf-8"))
