"""Blender PropertyGroups for ADF data, generated from the tables in :mod:`.fields`.

Every optional ADF key gets a ``use_<name>`` switch: off means "not written" (AMBF uses
its default), which is not the same as writing the default value.
"""

from __future__ import annotations

import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)

from . import fields

KINDS = (
    ("NONE", "None", "Not part of the ADF model"),
    ("BODY", "Body", "Rigid body"),
    ("SOFT_BODY", "Soft body", "Bullet soft body (cloth, tissue): its nodes are the mesh's vertices"),
    ("GHOST", "Ghost", "Non-colliding trigger volume"),
    ("SENSOR", "Sensor", "Ray sensor"),
    ("ACTUATOR", "Actuator", "Constraint actuator"),
    ("CAMERA", "Camera", "ADF camera"),
    ("LIGHT", "Light", "ADF spot light"),
    ("JOINT", "Joint", "Joint (rigid body constraint on this object)"),
    ("COLLISION_SHAPE", "Collision primitive", "A primitive of its parent body's collision"),
    ("COLLISION_MESH", "Collision mesh", "A (convex) collision mesh part of its parent body"),
)
MESH_FORMATS = (
    ("OBJ", "OBJ", "Wavefront OBJ with its MTL: materials, textures, several collision parts (AMBF, PyBullet, MuJoCo)"),
    ("STL", "STL", "Binary STL: triangles only (AMBF, PyBullet, MuJoCo)"),
    ("PLY", "PLY", "Binary PLY: triangles only, as AMBF's own add-on offered (AMBF, PyBullet, MuJoCo do not read it)"),
    ("3DS", "3DS", "3D Studio: triangles, one object per part (AMBF; PyBullet and MuJoCo do not read it)"),
)
SHAPES = ("BOX", "SPHERE", "CYLINDER", "CAPSULE", "CONE")


def _prop(f: fields.Field, update=None):
    kw = {"name": f.label, "description": f.desc or f.label}
    if update is not None:
        kw["update"] = update
    if f.kind == "float":
        kw.update(default=f.default, precision=6)
        if f.min is not None:
            kw["min"] = f.min
        return FloatProperty(**kw)
    if f.kind == "int":
        return IntProperty(default=f.default, min=int(f.min or 0), **kw)
    if f.kind == "bool":
        return BoolProperty(default=f.default, **kw)
    if f.kind == "enum":
        return EnumProperty(items=[(i, i, i) for i in f.items], default=f.default, **kw)
    if f.kind in ("vec3", "inertia", "conelimits"):
        return FloatVectorProperty(size=3, default=f.default, precision=6, **kw)
    if f.kind == "pose":
        return FloatVectorProperty(size=6, default=f.default, precision=6, **kw)
    return StringProperty(default=str(f.default), **kw)


def _make_group(name: str, table: list[fields.Field], extra: dict | None = None, updates: dict | None = None):
    ann = {}
    updates = updates or {}
    for f in table:
        up = updates.get(f.prop)
        value_up, use_up = up if isinstance(up, tuple) else (up, up)
        ann[f.prop] = _prop(f, value_up)
        kw = {"update": use_up} if use_up is not None else {}
        ann["use_" + f.prop] = BoolProperty(
            name=f"Write {f.label}", default=False, description=f"Write '{' '.join(f.path)}' (off: AMBF default)", **kw
        )
    ann.update(extra or {})
    return type(name, (bpy.types.PropertyGroup,), {"__annotations__": ann})


class AdfRay(bpy.types.PropertyGroup):
    offset: FloatVectorProperty(name="Offset", size=3, precision=6)
    direction: FloatVectorProperty(name="Direction", size=3, default=(1.0, 0.0, 0.0), precision=6)


def _outline(self, context):
    from .outline import update_outline

    update_outline(self.id_data)


class AdfShape(bpy.types.PropertyGroup):
    shape: EnumProperty(name="Shape", items=[(s, s.title(), s.title()) for s in SHAPES], default="BOX", update=_outline)
    size: FloatVectorProperty(
        name="Box size",
        size=3,
        default=(0.1, 0.1, 0.1),
        min=0.0,
        precision=6,
        description="full edge lengths x, y, z (m)",
        update=_outline,
    )
    radius: FloatProperty(name="Radius", default=0.05, min=0.0, precision=6, update=_outline)
    height: FloatProperty(name="Height", default=0.1, min=0.0, precision=6, update=_outline)
    axis: EnumProperty(name="Axis", items=[(a, a, a) for a in "xyzXYZ"], default="z", update=_outline)


def _mass_typed(self, context):
    self.mass_typed = True


def _joint_limits(self, context):
    from .constraints import mirror_limits

    mirror_limits(self.id_data)


_LIMIT_PROPS = (
    "type",
    "limit_low",
    "limit_high",
    "cone_limits",
    "linear_low",
    "linear_high",
    "angular_low",
    "angular_high",
)
_TYPED = {
    "mass_typed": BoolProperty(
        name="Mass typed by hand", default=False, description="off: mass follows density × mesh volume"
    ),
    "mass_note": StringProperty(
        name="Mass note", options={"HIDDEN"}, description="why the mass could not be taken from density × volume"
    ),
}
BodyProps = _make_group("AdfBodyProps", fields.BODY, dict(_TYPED), {"mass": (_mass_typed, None)})
SoftProps = _make_group(
    "AdfSoftProps",
    fields.SOFT,
    {
        **_TYPED,
        "fixed_group": StringProperty(
            name="Fixed nodes group",
            default="fixed nodes",
            description="vertex group whose vertices are the soft body's fixed nodes",
        ),
    },
    {"mass": (_mass_typed, None)},
)
GhostProps = _make_group("AdfGhostProps", fields.GHOST)
JOINT_AXES = (
    ("DEFAULT", "Type's own", "the Empty's Z for hinges and springs, X for prismatic joints (AMBF's reference axis)"),
    ("X", "X", "the Empty's X axis"),
    ("Y", "Y", "the Empty's Y axis"),
    ("Z", "Z", "the Empty's Z axis"),
)
JointProps = _make_group(
    "AdfJointProps",
    fields.JOINT,
    {
        "axis": EnumProperty(
            name="Axis",
            items=JOINT_AXES,
            default="DEFAULT",
            description="which axis of the joint's Empty the joint turns about or slides along",
        )
    },
    {k: _joint_limits for k in _LIMIT_PROPS},
)
SensorProps = _make_group("AdfSensorProps", fields.SENSOR, {"rays": CollectionProperty(type=AdfRay)})
ActuatorProps = _make_group("AdfActuatorProps", fields.ACTUATOR)
CameraProps = _make_group("AdfCameraProps", fields.CAMERA)
LightProps = _make_group("AdfLightProps", fields.LIGHT)
GROUP_OF = {
    "BODY": "body",
    "SOFT_BODY": "soft",
    "GHOST": "ghost",
    "JOINT": "joint",
    "SENSOR": "sensor",
    "ACTUATOR": "actuator",
    "CAMERA": "camera",
    "LIGHT": "light",
}


def _density(self, context):
    if self.kind in ("BODY", "SOFT_BODY"):
        from .elements import mass_from_density

        mass_from_density(self.id_data)


class AdfObjectProps(bpy.types.PropertyGroup):
    kind: EnumProperty(name="ADF kind", items=KINDS, default="NONE")
    identifier: StringProperty(name="Identifier", description="ADF mapping key; empty: '<KIND> <object name>'")
    body: PointerProperty(type=BodyProps)
    soft: PointerProperty(type=SoftProps)
    ghost: PointerProperty(type=GhostProps)
    joint: PointerProperty(type=JointProps)
    sensor: PointerProperty(type=SensorProps)
    actuator: PointerProperty(type=ActuatorProps)
    camera: PointerProperty(type=CameraProps)
    light: PointerProperty(type=LightProps)
    shape: PointerProperty(type=AdfShape)
    # exact state at import/export time (see fields.py): ADF text and the world matrix then
    snapshot: StringProperty(options={"HIDDEN"})
    snapshot_matrix: StringProperty(options={"HIDDEN"})
    mesh_source: StringProperty(name="Mesh source", description="file the visual mesh came from")
    mesh_hash: StringProperty(options={"HIDDEN"})
    collision_source: StringProperty(name="Collision source", description="file the collision mesh came from")
    collision_hash: StringProperty(options={"HIDDEN"})
    density: FloatProperty(
        name="Density",
        default=1000.0,
        min=0.0,
        update=_density,
        description="kg/m³: the mass is density × mesh volume unless typed by hand",
    )


class AdfSceneProps(bpy.types.PropertyGroup):
    snapshot: StringProperty(options={"HIDDEN"}, description="model-level ADF keys at import")
    namespace: StringProperty(name="Namespace", default="")
    use_namespace: BoolProperty(name="Write namespace", default=False)
    ignore_inter_collision: BoolProperty(name="Ignore inter-collision", default=False)
    use_gravity: BoolProperty(
        name="Model gravity",
        default=False,
        description="write the model's own gravity (bodies without one of their own use it)",
    )
    gravity: FloatVectorProperty(name="Gravity", default=(0.0, 0.0, -9.81), size=3, subtype="ACCELERATION")
    use_ignore_inter_collision: BoolProperty(name="Write ignore inter-collision", default=False)
    findings: StringProperty(name="Findings", description="last export's validation findings")
    rope_count: IntProperty(name="Elements", default=20, min=2, max=500)
    rope_length: FloatProperty(name="Length", default=0.2, min=0.001, precision=4)
    rope_radius: FloatProperty(name="Radius", default=0.001, min=0.0001, precision=5)
    rope_mass: FloatProperty(name="Total mass", default=0.002, min=0.0, precision=5)
    precision: IntProperty(
        name="Float digits",
        default=9,
        min=3,
        max=17,
        description="significant digits of exported floats (values Blender stores in single "
        "precision print as 0.005, not 0.004999999888241291)",
    )
    apply_modifiers: BoolProperty(
        name="Apply modifiers", default=True, description="export the evaluated mesh (modifiers applied) of each body"
    )
    mesh_format: EnumProperty(
        name="Mesh format",
        items=MESH_FORMATS,
        default="OBJ",
        description="file format of the meshes export writes (meshes imported and left unchanged are copied as they are)",
    )
    meshes_path: StringProperty(
        name="Meshes folder",
        subtype="DIR_PATH",
        default="",
        description="folder of the high_res/ and low_res/ mesh folders: relative to the model file's folder, "
        "or absolute (empty: meshes/ beside the model file)",
    )
    save_high_res: BoolProperty(
        name="High res",
        default=True,
        description="write the visual (high-res) meshes; off: the model still names them, the files there are kept",
    )
    save_low_res: BoolProperty(
        name="Low res",
        default=True,
        description="write the collision (low-res) meshes; off: the model still names them, the files there are kept",
    )
    save_textures: BoolProperty(
        name="Textures", default=True, description="copy the images the meshes' materials use beside them"
    )
    low_res_ratio: FloatProperty(
        name="Low-res ratio",
        default=1.0,
        min=0.01,
        max=1.0,
        description="collision (low-res) meshes made from the visual one are decimated to "
        "this share of its faces (1: same mesh)",
    )


CLASSES = (
    AdfRay,
    AdfShape,
    BodyProps,
    SoftProps,
    GhostProps,
    JointProps,
    SensorProps,
    ActuatorProps,
    CameraProps,
    LightProps,
    AdfObjectProps,
    AdfSceneProps,
)


def register() -> None:
    for c in CLASSES:
        bpy.utils.register_class(c)
    bpy.types.Object.adf = PointerProperty(type=AdfObjectProps)
    bpy.types.Scene.adf = PointerProperty(type=AdfSceneProps)


def unregister() -> None:
    del bpy.types.Scene.adf
    del bpy.types.Object.adf
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)


def group(obj):
    """The kind-specific PropertyGroup of an object (None for other kinds)."""
    name = GROUP_OF.get(obj.adf.kind)
    return getattr(obj.adf, name) if name else None


def read_group(pg, table) -> dict:
    """{prop: value or None} from a PropertyGroup (None where the use_ switch is off)."""
    out = {}
    for f in table:
        if not getattr(pg, "use_" + f.prop):
            out[f.prop] = None
            continue
        v = getattr(pg, f.prop)
        out[f.prop] = tuple(v) if f.kind in ("vec3", "inertia", "pose", "conelimits") else v
    return out


def write_group(pg, table, values: dict) -> None:
    for f in table:
        v = values.get(f.prop)
        setattr(pg, "use_" + f.prop, v is not None)
        if v is None:
            continue
        if f.kind == "enum" and v not in f.items:
            setattr(pg, "use_" + f.prop, False)  # unusual spelling: kept exact in the snapshot
            continue
        setattr(pg, f.prop, v)
