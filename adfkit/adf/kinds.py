"""Which ADF file kind a mapping is (adf-format.md §2): AMBF decides by slot; tools guess
from the top-level keys."""

from __future__ import annotations

import yaml

MODEL_KEYS = {"bodies", "joints", "soft bodies", "ghost objects", "sensors", "actuators", "vehicles", "volumes"}
WORLD_KEYS = {"environment", "enclosure", "enclosure size", "skybox", "max iterations"}


def detect_kind(keys, values: dict | None = None) -> str | None:
    keys = set(keys)
    if "world config" in keys or "multibody configs" in keys:
        return "launch"
    if "input devices" in keys:
        return "input_devices"
    if keys & WORLD_KEYS:
        return "world"
    if keys & MODEL_KEYS:
        return "model"
    if values and all(_is_rgba(v) for v in values.values()):
        return "colors"
    if keys & {"lights", "cameras"}:
        return "model"
    return None


def _is_rgba(node) -> bool:
    return (
        isinstance(node, yaml.MappingNode)
        and {k.value for k, _ in node.value if isinstance(k, yaml.ScalarNode)} <= {"r", "g", "b", "a"}
        and len(node.value) > 0
    )
