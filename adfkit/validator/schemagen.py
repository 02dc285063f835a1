"""Generate the ADF JSON Schemas (draft 2020-12) from the model's field declarations.

``python -m adfkit.validator.schemagen`` rewrites ``adfkit/adf_schema/*.schema.json``;
``tests/test_schema.py`` checks the shipped files equal what this module builds, so the
schema cannot drift from :mod:`adfkit.model`.

The schemas accept what AMBF (yaml-cpp) accepts, applied to PyYAML output: quoted
numbers, boolean words such as ``'True'``, ``y``/``n`` (strings to PyYAML), numbers where
text is read. Unknown keys are allowed everywhere because AMBF ignores them (the validator
reports them separately). Enumerations whose bad values AMBF still loads (joint type,
shape names, collision mesh type) are left to semantic rules and given as ``examples``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from ..model import FILE_KINDS
from ..model.common import CartesianController, Geometry, ShapeEntry
from ..model.files import ObjectList
from ..model.spec import FloatOr, ListOf, Node, adf_fields
from .descriptions import describe

DIALECT = "https://json-schema.org/draft/2020-12/schema"
SCHEMA_DIR = Path(__file__).resolve().parent.parent / "adf_schema"

_BOOL_WORDS = [
    w
    for base in ("true", "false", "yes", "no", "on", "off", "y", "n")
    for w in dict.fromkeys((base, base.capitalize(), base.upper()))
]
NUMBER_PATTERN = r"^\s*[-+]?(([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?|\.(inf|Inf|INF|nan|NaN|NAN))\s*$"

SCALARS: dict[str, dict] = {
    "float": {"title": "a number", "anyOf": [{"type": "number"}, {"type": "string", "pattern": NUMBER_PATTERN}]},
    "bool": {
        "title": "true or false",
        "anyOf": [{"type": "boolean"}, {"type": "string", "pattern": "^\\s*(" + "|".join(_BOOL_WORDS) + ")\\s*$"}],
    },
    "int": {
        "title": "an integer",
        "anyOf": [{"type": "integer"}, {"type": "string", "pattern": r"^\s*[-+]?[0-9]+\s*$"}],
    },
    "uint": {
        "title": "a non-negative integer",
        "anyOf": [{"type": "integer", "minimum": 0}, {"type": "string", "pattern": r"^\s*\+?[0-9]+\s*$"}],
    },
    "str": {"title": "text", "type": ["string", "number", "boolean"]},
    "vec3": {
        "title": "a vector {x, y, z}",
        "type": "object",
        "required": ["x", "y", "z"],
        "properties": {k: {"$ref": "#/$defs/float"} for k in "xyz"},
    },
    "rpy": {
        "title": "an orientation {r, p, y}",
        "type": "object",
        "required": ["r", "p", "y"],
        "properties": {k: {"$ref": "#/$defs/float"} for k in "rpy"},
    },
    "pose": {
        "title": "a pose {position, orientation}",
        "type": "object",
        "properties": {"position": {"$ref": "#/$defs/vec3"}, "orientation": {"$ref": "#/$defs/rpy"}},
    },
    "any": {},
}

# Keys AMBF needs when the block is present (missing ones make it reject the file).
REQUIRED = {
    "Launch": ["world config", "color config", "input devices config", "multibody configs"],
    "Joint": ["type", "parent pivot", "child pivot", "parent axis", "child axis"],
    "Shaders": ["path", "vertex", "fragment"],
    "PublishFrequency": ["low", "high"],
    "RGBA": ["r", "g", "b", "a"],
    "RGB": ["r", "g", "b"],
    "AmbientLevel": ["level"],
    "ColorComponents": ["transparency"],
    "Inertia": ["ix", "iy", "iz"],
    "ClippingPlane": ["near", "far"],
    "Stereo": ["mode", "eye separation", "focal length"],
    "HapticGain": ["linear", "angular"],
    "Suspension": ["stiffness", "damping", "compression", "rest length"],
    "Parametric": ["resolution", "horizontal angle", "vertical angle", "start offset"],
    "Enclosure": ["length", "width", "height"],
    "Skybox": ["path"],
    "DepthNoise": ["mean"],
    "CartesianPID": ["P", "D"],
}

# AMBF reads `enable feedback` in place of `enable motor` (§8): the latter's value is never
# converted, but the former must then exist or the file is rejected.
ANY_VALUE = {"Joint.enable motor"}
DEPENDENT_REQUIRED = {"Joint": {"enable motor": ["enable feedback"]}}

EXAMPLES = {
    "Joint.type": [
        "revolute",
        "prismatic",
        "fixed",
        "continuous",
        "linear spring",
        "torsion spring",
        "p2p",
        "cone twist",
        "six dof",
        "six dof spring",
    ],
    "shape": ["Box", "Sphere", "Cylinder", "Capsule", "Cone", "Plane"],
    "collision shape": ["Box", "Sphere", "Cylinder", "Capsule", "Cone", "Plane"],
    "collision mesh type": ["CONCAVE_MESH", "CONVEX_HULL", "CONVEX_MESH", "POINT_CLOUD"],
    "controller output type": ["FORCE", "VELOCITY", "POSITION"],
    "Sensor.type": ["Proximity", "Resistance"],
    "Actuator.type": ["Constraint"],
    "Geometry.axis": ["x", "y", "z"],
}

# Geometry keys each primitive needs (§7.5); axis defaults to z.
SHAPE_KEYS = {
    "Box": ["x", "y", "z"],
    "Sphere": ["radius"],
    "Cylinder": ["radius", "height"],
    "Capsule": ["radius", "height"],
    "Cone": ["radius", "height"],
    "Plane": ["normal", "offset"],
}

# Add-on naming convention for top-level object mappings (for editors; AMBF goes by the lists).
OBJECT_PREFIXES = {
    "^BODY ": "Body",
    "^JOINT ": "Joint",
    "^GHOST ": "Ghost",
    "^SENSOR ": "Sensor",
    "^ACTUATOR ": "Actuator",
}

KIND_TITLES = {
    "launch": "AMBF launch file",
    "world": "AMBF world file",
    "input_devices": "AMBF input-devices file",
    "model": "AMBF model (multibody) file",
    "colors": "AMBF colors file",
}


def _shape_pattern(name: str) -> str:
    return f"^({name}|{name.lower()}|{name.upper()})$"


def _shape_rules(shape_key: str, geometry_key: str) -> list[dict]:
    return [
        {
            "if": {
                "required": [shape_key, geometry_key],
                "properties": {shape_key: {"type": "string", "pattern": _shape_pattern(name)}},
            },
            "then": {"properties": {geometry_key: {"required": keys}}},
        }
        for name, keys in SHAPE_KEYS.items()
    ]


class _Builder:
    def __init__(self) -> None:
        self.defs: dict[str, dict] = {}

    def ref(self, name: str) -> dict:
        return {"$ref": f"#/$defs/{name}"}

    def kind_schema(self, kind, owner: str) -> dict:
        if isinstance(kind, str):
            self.defs.setdefault(kind, SCALARS[kind])
            for dep in ("float", "vec3", "rpy"):
                if kind in ("vec3", "rpy", "pose"):
                    self.defs.setdefault(dep, SCALARS[dep])
            return self.ref(kind)
        if isinstance(kind, ListOf):
            return {"type": "array", "items": self.kind_schema(kind.item, owner)}
        if isinstance(kind, FloatOr):
            return {"anyOf": [self.kind_schema("float", owner), self.kind_schema(kind.struct, owner)]}
        if isinstance(kind, ObjectList):
            self.node(kind.kind)
            self.defs.setdefault("str", SCALARS["str"])
            return {"type": ["array", "null"], "items": self.ref("str")}
        if isinstance(kind, type) and issubclass(kind, Node):
            name = "CartesianPID" if owner == "CartesianController" else kind.__name__
            self.node(kind, name)
            return self.ref(name)
        raise TypeError(kind)  # pragma: no cover

    def node(self, cls, name: str | None = None) -> str:
        name = name or cls.__name__
        if name in self.defs:
            return name
        self.defs[name] = {}  # reserve (recursion guard)
        props = {}
        for f in adf_fields(cls):
            key = f.metadata["adf_key"]
            prop = dict(self.kind_schema(f.metadata["kind"], cls.__name__))
            described = describe(cls.__name__, key)
            if described:
                default, text = described
                prop["description"] = text
                if default is not None:
                    prop["default"] = default
            if f"{cls.__name__}.{key}" in ANY_VALUE:
                prop = {k: v for k, v in prop.items() if k != "$ref"}
            examples = EXAMPLES.get(f"{cls.__name__}.{key}") or EXAMPLES.get(key)
            if examples:
                prop["examples"] = examples
            props[key] = prop
        schema: dict = {"type": "object", "properties": props}
        if REQUIRED.get(name):
            schema["required"] = REQUIRED[name]
        if name in DEPENDENT_REQUIRED:
            schema["dependentRequired"] = DEPENDENT_REQUIRED[name]
        rules = []
        if "shape" in props and "geometry" in props:
            rules += _shape_rules("shape", "geometry")
        if "collision shape" in props:
            rules += _shape_rules("collision shape", "collision geometry")
        if rules:
            schema["allOf"] = rules
        if cls.__doc__ and not cls.__doc__.startswith(cls.__name__ + "("):
            schema["description"] = " ".join(cls.__doc__.split())
        self.defs[name] = schema
        return name


def build_schema(kind: str) -> dict:
    cls = FILE_KINDS[kind]
    b = _Builder()
    # Geometry and ShapeEntry always travel together; make sure both exist for the rules.
    top = b.node(cls)
    root = b.defs.pop(top)
    schema = {
        "$schema": DIALECT,
        "$id": f"urn:adfkit:schema:{kind}",
        "title": KIND_TITLES[kind],
        "description": f"{KIND_TITLES[kind]} as AMBF 2.x reads it (adf-format.md). Unknown keys are "
        "allowed because AMBF ignores them.",
        **root,
    }
    if kind == "colors":
        b.kind_schema("float", "Colors")
        schema["additionalProperties"] = {
            "type": "object",
            "description": "A named colour {r, g, b, a}, 0–1.",
            "properties": {k: {"$ref": "#/$defs/float"} for k in "rgba"},
        }
    if kind == "model":
        schema["patternProperties"] = {pat: b.ref(name) for pat, name in OBJECT_PREFIXES.items()}
    schema["$defs"] = dict(sorted(b.defs.items()))
    _ = (CartesianController, Geometry, ShapeEntry)
    return schema


def schema_text(kind: str) -> str:
    return json.dumps(build_schema(kind), indent=2, ensure_ascii=False) + "\n"


def main(argv: list[str] | None = None) -> int:
    out = Path(argv[0]) if argv else SCHEMA_DIR
    for kind in FILE_KINDS:
        (out / f"{kind}.schema.json").write_text(schema_text(kind), encoding="utf-8")
        print(f"wrote {out / f'{kind}.schema.json'}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main(sys.argv[1:]))
