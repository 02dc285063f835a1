"""The ADF keys the add-on shows as typed Blender properties, as one table per object kind.

Pure Python (no bpy): the same table makes the PropertyGroups, draws the panels, fills
them on import and reads them on export. Blender stores floats in single precision, so
each object also keeps a *snapshot* (the exact ADF text it was imported or exported
as); on export a value whose float32 image is unchanged keeps its exact snapshot value.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from dataclasses import fields as dc_fields

import yaml

from adfkit.adf.reader import Reader
from adfkit.adf.writer import _Dumper, node_to_plain
from adfkit.model import Actuator, Body, Camera, Ghost, Joint, Light, Pose, Sensor
from adfkit.model.objects import Inertia, SoftBody
from adfkit.model.pose import Vec3, quat_to_rpy, rpy_to_quat
from adfkit.model.spec import FloatOr, Node, adf_fields


@dataclass(frozen=True)
class Field:
    prop: str  # Blender property name
    path: tuple[str, ...]  # attribute path in the adfkit model object
    kind: str  # float | int | bool | str | vec3 | enum | groups | inertia | pose
    default: object
    label: str
    desc: str = ""
    items: tuple[str, ...] = ()
    min: float | None = None


OUTPUT_TYPES = ("FORCE", "VELOCITY", "POSITION", "EFFORT", "force", "velocity", "position", "effort")
MESH_TYPES = (
    "CONCAVE_MESH",
    "CONVEX_HULL",
    "CONVEX_MESH",
    "POINT_CLOUD",
    "convex_hull",
    "hull",
    "convex_mesh",
    "TRIMESH",
    "trimesh",
    "point_cloud",
)
JOINT_TYPES = (
    "revolute",
    "hinge",
    "continuous",
    "prismatic",
    "slider",
    "fixed",
    "linear spring",
    "spring",
    "torsion spring",
    "torsional spring",
    "angular spring",
    "p2p",
    "cone twist",
    "six dof",
    "six dof spring",
)


def _freq() -> list[Field]:
    return [
        Field(f"publish_frequency_{k}", ("publish_frequency", k), "int", d, f"Publish frequency {k}", "Hz")
        for k, d in (("low", 50), ("high", 1000))
    ]


def _pid(prefix: str, path: tuple[str, ...], label: str) -> list[Field]:
    return [
        Field(f"{prefix}_{g.lower()}", path + (g,), "float", d, f"{label} {g}")
        for g, d in (("P", 10.0), ("I", 0.0), ("D", 1.0))
    ]


VISIBLE = "drawn in AMBF; applied only together with a colour (color rgba or color components)"

BODY = [
    Field("mass", ("mass",), "float", 1.0, "Mass", "kg; 0 makes the body static", min=0.0),
    Field("inertia", ("inertia",), "inertia", (0.001, 0.001, 0.001), "Inertia", "principal moments ix, iy, iz (kg·m²)"),
    Field(
        "inertial_offset",
        ("inertial_offset",),
        "pose",
        (0.0,) * 6,
        "Inertial offset",
        "COM frame in the body frame: x, y, z (m), roll, pitch, yaw (rad)",
    ),
    Field("friction_static", ("friction", "static"), "float", 0.5, "Static friction", min=0.0),
    Field("friction_rolling", ("friction", "rolling"), "float", 0.01, "Rolling friction", min=0.0),
    Field("restitution", ("restitution",), "float", 0.1, "Restitution", min=0.0),
    Field("damping_linear", ("damping", "linear"), "float", 0.04, "Linear damping", min=0.0),
    Field("damping_angular", ("damping", "angular"), "float", 0.1, "Angular damping", min=0.0),
    Field("collision_margin", ("collision_margin",), "float", 0.001, "Collision margin", "m", min=0.0),
    Field("collision_groups", ("collision_groups",), "groups", "", "Collision groups", "comma-separated ints 0-999"),
    Field(
        "collision_mesh_type", ("collision_mesh_type",), "enum", "CONCAVE_MESH", "Collision mesh type", items=MESH_TYPES
    ),
    *_pid("controller_linear", ("controller", "linear"), "Linear"),
    *_pid("controller_angular", ("controller", "angular"), "Angular"),
    Field(
        "controller_output_type", ("controller_output_type",), "enum", "FORCE", "Controller output", items=OUTPUT_TYPES
    ),
    Field("passive", ("passive",), "bool", False, "Passive", "no ROS communication"),
    Field("visible", ("visible",), "bool", True, "Visible", VISIBLE),
    Field("gravity", ("gravity",), "vec3", (0.0, 0.0, -9.8), "Gravity override", "m/s², this body only"),
    Field("publish_children_names", ("publish_children_names",), "bool", False, "Publish children names"),
    Field("publish_joint_names", ("publish_joint_names",), "bool", False, "Publish joint names"),
    Field("publish_joint_positions", ("publish_joint_positions",), "bool", False, "Publish joint positions"),
    *_freq(),
]

GHOST = [
    Field("collision_margin", ("collision_margin",), "float", 0.001, "Collision margin", min=0.0),
    Field(
        "collision_mesh_type", ("collision_mesh_type",), "enum", "CONCAVE_MESH", "Collision mesh type", items=MESH_TYPES
    ),
    Field("passive", ("passive",), "bool", False, "Passive"),
]

JOINT = [
    Field("type", ("type",), "enum", "revolute", "Joint type", items=JOINT_TYPES),
    Field("limit_low", ("joint_limits", "low"), "float", -1.0, "Lower limit", "rad or m"),
    Field("limit_high", ("joint_limits", "high"), "float", 1.0, "Upper limit", "rad or m"),
    Field("cone_limits", ("joint_limits",), "conelimits", (0.7, 0.7, 0.7), "Cone-twist limits", "x, y, z (rad)"),
    Field("linear_low", ("joint_limits", "linear", "low"), "vec3", (-0.01,) * 3, "Linear low", "six-dof, m"),
    Field("linear_high", ("joint_limits", "linear", "high"), "vec3", (0.01,) * 3, "Linear high", "six-dof, m"),
    Field("angular_low", ("joint_limits", "angular", "low"), "vec3", (-0.5,) * 3, "Angular low", "six-dof, rad"),
    Field("angular_high", ("joint_limits", "angular", "high"), "vec3", (0.5,) * 3, "Angular high", "six-dof, rad"),
    Field("damping", ("damping",), "float", 0.0, "Damping", "springs"),
    Field("stiffness", ("stiffness",), "float", 0.0, "Stiffness", "springs"),
    Field("equilibrium", ("equilibrium_point",), "float", 0.0, "Equilibrium point", "rad or m"),
    Field("damping_linear", ("damping", "linear"), "vec3", (0.7,) * 3, "Damping linear", "six-dof spring"),
    Field("damping_angular", ("damping", "angular"), "vec3", (0.7,) * 3, "Damping angular", "six-dof spring"),
    Field("stiffness_linear", ("stiffness", "linear"), "vec3", (1.0,) * 3, "Stiffness linear", "six-dof spring"),
    Field("stiffness_angular", ("stiffness", "angular"), "vec3", (1.0,) * 3, "Stiffness angular", "six-dof spring"),
    Field(
        "equilibrium_linear",
        ("equilibrium_point", "linear"),
        "vec3",
        (0.0,) * 3,
        "Equilibrium linear",
        "six-dof spring",
    ),
    Field(
        "equilibrium_angular",
        ("equilibrium_point", "angular"),
        "vec3",
        (0.0,) * 3,
        "Equilibrium angular",
        "six-dof spring",
    ),
    Field("max_motor_impulse", ("max_motor_impulse",), "float", 0.1, "Max motor impulse", min=0.0),
    *_pid("controller", ("controller",), "Controller"),
    Field(
        "controller_output_type", ("controller_output_type",), "enum", "FORCE", "Controller output", items=OUTPUT_TYPES
    ),
    Field("enable_feedback", ("enable_feedback",), "bool", False, "Enable feedback"),
    Field("ignore_inter_collision", ("ignore_inter_collision",), "bool", True, "Ignore inter-collision"),
    Field("joint_erp", ("joint_erp",), "float", 0.1, "ERP"),
    Field("joint_cfm", ("joint_cfm",), "float", 0.1, "CFM"),
    Field("passive", ("passive",), "bool", False, "Passive"),
]

SENSOR = [
    Field(
        "type",
        ("type",),
        "enum",
        "Proximity",
        "Sensor type",
        items=("Proximity", "proximity", "PROXIMITY", "Resistance", "resistance", "RESISTANCE"),
    ),
    Field("range", ("range",), "float", 0.5, "Range", "m", min=0.0),
    Field("visible", ("visible",), "bool", False, "Visible"),
    Field("visible_size", ("visible_size",), "float", 0.02, "Visible size", min=0.0),
    Field("passive", ("passive",), "bool", False, "Passive"),
    # resistance sensors (needle-tissue contact)
    Field("friction_static", ("friction", "static"), "float", 0.5, "Resistance static friction", min=0.0),
    Field("friction_dynamic", ("friction", "dynamic"), "float", 0.3, "Resistance dynamic friction", min=0.0),
    Field("friction_damping", ("friction", "damping"), "float", 0.1, "Resistance friction damping", min=0.0),
    Field("friction_variable", ("friction", "variable"), "bool", False, "Variable friction"),
    Field("contact_area", ("contact_area",), "float", 0.001, "Contact area", "m", min=0.0),
    Field("contact_stiffness", ("contact_stiffness",), "float", 1000.0, "Contact stiffness", "N/m", min=0.0),
    Field("contact_damping", ("contact_damping",), "float", 10.0, "Contact damping", "N·s/m", min=0.0),
    *_freq(),
]
RESISTANCE_ONLY = {
    "friction_static",
    "friction_dynamic",
    "friction_damping",
    "friction_variable",
    "contact_area",
    "contact_stiffness",
    "contact_damping",
}

ACTUATOR = [
    Field("type", ("type",), "enum", "Constraint", "Actuator type", items=("Constraint", "constraint", "CONSTRAINT")),
    Field("max_impulse", ("max_impulse",), "float", 10.0, "Max impulse", min=0.0),
    Field("tau", ("tau",), "float", 1.0, "Tau", min=0.0),
    Field("visible", ("visible",), "bool", False, "Visible"),
    Field("visible_size", ("visible_size",), "float", 0.02, "Visible size", min=0.0),
    Field("passive", ("passive",), "bool", False, "Passive"),
]

CAMERA = [
    Field("publish_image", ("publish_image",), "bool", False, "Publish image"),
    Field("publish_depth", ("publish_depth",), "bool", False, "Publish depth"),
    Field("image_width", ("publish_image_resolution", "width"), "float", 640.0, "Image width", min=1.0),
    Field("image_height", ("publish_image_resolution", "height"), "float", 480.0, "Image height", min=1.0),
    Field("publish_image_interval", ("publish_image_interval",), "int", 1, "Publish image interval", "frames"),
    Field("publish_depth_interval", ("publish_depth_interval",), "int", 1, "Publish depth interval", "frames"),
    Field("depth_width", ("publish_depth_resolution", "width"), "float", 640.0, "Depth width", min=1.0),
    Field("depth_height", ("publish_depth_resolution", "height"), "float", 480.0, "Depth height", min=1.0),
    Field("multipass", ("multipass",), "bool", False, "Multipass"),
    Field("passive", ("passive",), "bool", False, "Passive"),
]

LIGHT = [
    Field("spot_exponent", ("spot_exponent",), "float", 0.7, "Spot exponent", min=0.0),
    Field("shadow_quality", ("shadow_quality",), "int", 5, "Shadow quality", "0 none … 5 very high", min=0),
    Field("attenuation_constant", ("attenuation", "constant"), "float", 1.0, "Attenuation constant"),
    Field("attenuation_linear", ("attenuation", "linear"), "float", 0.0, "Attenuation linear"),
    Field("attenuation_quadratic", ("attenuation", "quadratic"), "float", 0.0, "Attenuation quadratic"),
    Field("passive", ("passive",), "bool", False, "Passive"),
]

_SOFT_FLOATS = (
    "kLST",
    "kAST",
    "kVST",
    "kVCF",
    "kDP",
    "kDG",
    "kLF",
    "kPR",
    "kVC",
    "kDF",
    "kMT",
    "kCHR",
    "kKHR",
    "kSHR",
    "kAHR",
    "kSRHR_CL",
    "kSKHR_CL",
    "kSSHR_CL",
    "kSR_SPLT_CL",
    "kSK_SPLT_CL",
    "kSS_SPLT_CL",
    "maxvolume",
    "timescale",
)
_SOFT_INTS = ("viterations", "piterations", "diterations", "citerations", "flags", "bending_constraint", "clusters")
SOFT_DESC = {
    "kLST": "linear stiffness 0-1",
    "kAST": "angular stiffness 0-1",
    "kVST": "volume stiffness 0-1",
    "kVCF": "velocities correction factor",
    "kDP": "damping",
    "kDG": "drag",
    "kLF": "lift",
    "kPR": "pressure",
    "kVC": "volume conservation",
    "kDF": "dynamic friction 0-1",
    "kMT": "pose matching 0-1",
    "kCHR": "rigid contact hardness",
    "kKHR": "kinetic contact hardness",
    "kSHR": "soft contact hardness",
    "kAHR": "anchor hardness",
    "piterations": "position solver iterations",
    "viterations": "velocity solver iterations",
    "diterations": "drift solver iterations",
    "citerations": "cluster solver iterations",
    "bending_constraint": "bending constraint distance",
    "clusters": "cluster count (0: none)",
    "flags": "collision flags (bit set)",
}

# Bullet's btSoftBody defaults (what AMBF uses for a key not written)
SOFT_DEFAULTS = {
    "kLST": 1.0,
    "kAST": 1.0,
    "kVST": 1.0,
    "kVCF": 1.0,
    "kDF": 0.2,
    "kCHR": 1.0,
    "kKHR": 0.1,
    "kSHR": 1.0,
    "kAHR": 0.7,
    "kSRHR_CL": 0.1,
    "kSKHR_CL": 1.0,
    "kSSHR_CL": 0.5,
    "kSR_SPLT_CL": 0.5,
    "kSK_SPLT_CL": 0.5,
    "kSS_SPLT_CL": 0.5,
    "maxvolume": 1.0,
    "timescale": 1.0,
    "piterations": 1,
    "viterations": 0,
    "diterations": 0,
    "citerations": 4,
    "flags": 1,
    "bending_constraint": 2,
    "clusters": 0,
}

SOFT = [
    Field("mass", ("mass",), "float", 1.0, "Mass", "kg, spread over the nodes", min=0.0),
    Field("visible", ("visible",), "bool", True, "Visible", VISIBLE),
    Field("collision_margin", ("collision_margin",), "float", 0.001, "Collision margin", "m", min=0.0),
    Field("collision_groups", ("collision_groups",), "groups", "", "Collision groups", "comma-separated ints 0-999"),
    Field("gravity", ("gravity",), "vec3", (0.0, 0.0, -9.8), "Gravity override", "m/s², this body only"),
    Field("randomize_constraints", ("randomize_constraints",), "bool", False, "Randomize constraints"),
    *[
        Field(
            f"config_{k.lower()}",
            ("config", k),
            "float",
            SOFT_DEFAULTS.get(k, 0.0),
            k.replace("_", " "),
            SOFT_DESC.get(k, k),
            min=0.0,
        )
        for k in _SOFT_FLOATS
    ],
    *[
        Field(
            f"config_{k.lower()}",
            ("config", k),
            "int",
            SOFT_DEFAULTS.get(k, 0),
            k.replace("_", " "),
            SOFT_DESC.get(k, k),
            min=0,
        )
        for k in _SOFT_INTS
    ],
    Field("passive", ("passive",), "bool", False, "Passive"),
    *_freq(),
]

TABLES = {
    "BODY": (Body, BODY),
    "SOFT_BODY": (SoftBody, SOFT),
    "GHOST": (Ghost, GHOST),
    "JOINT": (Joint, JOINT),
    "SENSOR": (Sensor, SENSOR),
    "ACTUATOR": (Actuator, ACTUATOR),
    "CAMERA": (Camera, CAMERA),
    "LIGHT": (Light, LIGHT),
}
PREFIX = {
    "BODY": "BODY ",
    "SOFT_BODY": "SOFT ",
    "GHOST": "GHOST ",
    "JOINT": "JOINT ",
    "SENSOR": "SENSOR ",
    "ACTUATOR": "ACTUATOR ",
    "CAMERA": "CAMERA ",
    "LIGHT": "LIGHT ",
}


# --- values on model objects ----------------------------------------------------------


def get_value(obj: Node, f: Field):
    """The field's value on a model object, in Blender form, or None when not written."""
    v = obj
    for name in f.path:
        if v is None or not isinstance(v, Node):
            return None
        v = getattr(v, name, None)
    if v is None:
        return None
    if f.kind == "inertia":
        return None if None in (v.ix, v.iy, v.iz) else (v.ix, v.iy, v.iz)
    if f.kind == "conelimits":
        return None if None in (v.x, v.y, v.z) else (v.x, v.y, v.z)
    if f.kind == "pose":
        return (*v.position, *quat_to_rpy(v.orientation))
    if f.kind == "groups":
        return ", ".join(str(int(g)) for g in v)
    if f.kind == "vec3":
        return tuple(v) if isinstance(v, tuple) else None
    if f.kind == "float":
        return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else None
    if f.kind == "int":
        return int(v)
    return v


def _field_class(parent: Node, name: str):
    for fl in adf_fields(parent):
        if fl.name == name:
            k = fl.metadata["kind"]
            return k.struct if isinstance(k, FloatOr) else k
    raise KeyError(name)


PRECISION = {"digits": 9}  # significant digits of floats the add-on computes (scene setting)


def tidy(x: float) -> float:
    """A float from Blender (single precision) as the shortest decimal that is the same
    float32 (0.004999999888241291 -> 0.005), at most PRECISION significant digits."""
    import numpy as np

    x = float(x)
    if x != x or x in (float("inf"), float("-inf")):
        return x
    if abs(x) < 3.4e38 and f32(x) == x:
        x = float(np.format_float_positional(np.float32(x), unique=True, trim="-")) if x else 0.0
    return float(f"{x:.{PRECISION['digits']}g}") + 0.0


def set_value(obj: Node, f: Field, value) -> None:
    """Write a Blender-form value (or None to remove the key) into the model object."""
    parents = [obj]
    v = obj
    for name in f.path[:-1]:
        nxt = getattr(v, name, None)
        if not isinstance(nxt, Node):
            if value is None:
                return
            nxt = _field_class(v, name)()
            setattr(v, name, nxt)
        v = nxt
        parents.append(v)
    leaf = f.path[-1]
    if value is None:
        out = None
    elif f.kind == "inertia":
        out = Inertia(ix=tidy(value[0]), iy=tidy(value[1]), iz=tidy(value[2]))
    elif f.kind == "conelimits":
        cur = getattr(v, leaf, None)
        cur = cur if isinstance(cur, Node) else _field_class(v, leaf)()
        cur.x, cur.y, cur.z = (tidy(c) for c in value)
        out = cur
    elif f.kind == "pose":
        # an exact (float64) angle goes to the writer as it is: pi stays pi (addon/exact.py)
        angles = (tidy(a) if f32(a) == a else float(a) for a in value[3:])
        out = Pose(Vec3(*map(tidy, value[:3])), rpy_to_quat(*angles))
    elif f.kind == "groups":
        out = parse_groups(value)
    elif f.kind == "vec3":
        out = Vec3(*map(tidy, value))
    elif f.kind == "float":
        out = tidy(value)
    elif f.kind == "int":
        out = int(value)
    else:
        out = value
    if f.kind == "conelimits" and value is None:
        cur = getattr(v, leaf, None)
        if isinstance(cur, Node):
            cur.x = cur.y = cur.z = None
            out = cur
    setattr(v, leaf, out)
    # drop sub-blocks left empty (friction: {} is not what the user meant)
    for parent, name in reversed(list(zip(parents, f.path))):
        child = getattr(parent, name, None)
        if isinstance(child, Node) and _empty(child):
            setattr(parent, name, None)


def _empty(n: Node) -> bool:
    return not n.extras and all(getattr(n, fl.name) is None for fl in adf_fields(n))


def parse_groups(text: str) -> list[int]:
    """'0, 3' -> [0, 3]. Raises ValueError with a readable message."""
    out = []
    for part in str(text).replace(";", ",").split(","):
        part = part.strip()
        if not part:
            continue
        try:
            g = int(part)
        except ValueError:
            raise ValueError(f"collision group '{part}' is not an integer") from None
        if not 0 <= g <= 999:
            raise ValueError(f"collision group {g} is outside 0-999")
        out.append(g)
    return out


def f32(x: float) -> float:
    return struct.unpack("f", struct.pack("f", float(x)))[0]


def same32(a, b) -> bool:
    """Equal once both are stored as Blender floats (single precision)."""
    if a is None or b is None:
        return a is None and b is None
    if isinstance(a, (tuple, list)):
        return len(a) == len(b) and all(same32(x, y) for x, y in zip(a, b))
    if isinstance(a, bool) or isinstance(b, bool) or isinstance(a, str) or isinstance(b, str):
        return a == b
    return f32(a) == f32(b)


def close(a, b, tol: float = 1e-6) -> bool:
    """Equal within ``tol`` (absolute, or relative for large values): for values Blender
    recomputes from single-precision matrices (poses of child objects)."""
    if a is None or b is None:
        return a is None and b is None
    if isinstance(a, (tuple, list)):
        return len(a) == len(b) and all(close(x, y, tol) for x, y in zip(a, b))
    if isinstance(a, (bool, str)) or isinstance(b, (bool, str)):
        return a == b
    return abs(a - b) <= tol * max(1.0, abs(a), abs(b))


def merge(obj: Node, table: list[Field], values: dict) -> None:
    """Apply Blender values onto ``obj`` (the snapshot), keeping exact snapshot values that
    Blender's single-precision storage did not change."""
    for f in table:
        new = values.get(f.prop)
        old = get_value(obj, f)
        if f.kind == "enum" and new is None and old is not None and old not in f.items:
            continue  # a spelling the menu does not offer: kept as written
        if not same32(old, new):
            set_value(obj, f, new)


# --- snapshots: the exact ADF text of one object ----------------------------------------


def snapshot_text(obj: Node) -> str:
    return yaml.dump(node_to_plain(obj), Dumper=_Dumper, sort_keys=False, allow_unicode=True, width=100)


def from_snapshot(cls, text: str, where: str = "<blender>"):
    """Parse a snapshot back into a model object (an empty one when there is none)."""
    if not text.strip():
        return cls()
    node = yaml.compose(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    if not isinstance(node, yaml.MappingNode):
        return cls()
    reader = Reader(where)
    obj = reader.struct(cls, node)
    obj.key_sources = {}
    obj.source = None
    return obj


def model_fields(cls) -> set[str]:
    return {fl.name for fl in dc_fields(cls)}
