"""Semantic rules on the scene model (adf-format.md §15): physics sanity, joint structure,
references, names, numbers and keys. File-existence rules live in :mod:`.paths_check`."""

from __future__ import annotations

import difflib
import math
from functools import cache
from typing import Any

from ..diagnostics import Diagnostic, Severity, SourceLocation
from ..model import Colors, InputDevices, Launch, ModelFile, Pose, Quat, Vec3, World
from ..model.semantics import (
    ACTUATOR_TYPES,
    SENSOR_TYPES,
    JointKind,
    body_joint_frames,
    collision_mesh_type,
    holds_no_joint,
    inertial_joint_twist,
    inertial_rotation,
    joint_kind,
    shape_kind,
)
from ..model.spec import Node
from ..model.spec import adf_fields as _adf_fields
from ..model.spec import adf_keys as _adf_keys
from . import softbody_rules
from .references import Registry, body_registry, camera_registry, merge_namespace
from .rules import RULES


@cache
def _fields_of(cls: type) -> tuple:
    return tuple(_adf_fields(cls))


@cache
def _keys_of(cls: type) -> frozenset:
    return frozenset(_adf_keys(cls))


def adf_fields(node: object) -> tuple:
    cls: Any = type(node)  # a class is hashable; mypy's view of type[object] is not
    return _fields_of(cls)


def adf_keys(node: object) -> frozenset:
    cls: Any = type(node)
    return _keys_of(cls)


SPRINGS = {JointKind.LINEAR_SPRING, JointKind.TORSION_SPRING}
ONE_DOF = {JointKind.REVOLUTE, JointKind.PRISMATIC, JointKind.LINEAR_SPRING, JointKind.TORSION_SPRING}
TREE_ONE_DOF = (JointKind.REVOLUTE, JointKind.PRISMATIC)
#: the joints whose two pivots always stand together (pivots_apart)
PIVOTS_HELD = (JointKind.FIXED, JointKind.P2P, JointKind.CONE_TWIST, JointKind.TORSION_SPRING)
POSE_TOLERANCE = 2e-3  # m, and rad for limits: beyond the add-on's 3-decimal rounding of locations and pivots
POSE_ANGLE_TOLERANCE = math.radians(1.0)
ABSURD = 1e6
# Keys whose magnitudes may legitimately be large (gains, impulses, stiffness, powers).
UNBOUNDED_KEYS = {
    "stiffness",
    "damping",
    "P",
    "I",
    "D",
    "max motor impulse",
    "max impulse",
    "max force",
    "max engine power",
    "max brake power",
    "contact stiffness",
    "contact damping",
    "compression",
    "linear",
    "angular",
    "max jerk",
    "far",
    "tau",
    "shininess",
}
# Keys AMBF 2.x reads nowhere (invariant 25), by element class name ("*" for every element).
IGNORED_KEYS = {
    "*": {"color", "detached", "redundant", "controller gains"},
    "Body": {"linear gain", "angular gain", "parent"},
    "SoftBody": {"linear gain", "angular gain"},
    "Joint": {"origin", "axis"},
    "Light": {"type"},
    "ShapeEntry": {"name"},
    "World": {"enclosure size"},
    "SoftBodyConfig": {"margin", "cutting"},
}
IGNORED_PREFIXES = ("resistive surface",)
# Keys the model declares (so they round-trip) although AMBF 2.x does not use them.
IGNORED_FIELDS = {
    "Body": {"color"},
    "SoftBody": {"color"},
    "Ghost": {"color"},
    "Volume": {"color"},
    "ModelFile": {"joint erp", "joint cfm"},
    "Camera": {"publish depth resolution"},
    # afResistanceSensor damps the change of a ray's depth from a last depth read after the ray
    # tracer has overwritten it: the term is always 0 (measured: runner/resistance.py)
    "Sensor": {"contact damping"},
}
PARSED_BUT_UNUSED = {"publish depth resolution", "contact damping"}
OBJECT_PREFIXES = ("BODY ", "JOINT ", "GHOST ", "SENSOR ", "ACTUATOR ", "SOFTBODY ", "SOFT BODY ")


class Checker:
    def __init__(self, doc, context_models=()):
        self.doc = doc
        self.file = str(doc.path) if doc.path else "<input>"
        self.context = list(context_models)  # models AMBF would have loaded before this one
        self.out: list[Diagnostic] = []

    def emit(self, rule: str, message: str, loc: SourceLocation | None, hint: str | None = None, severity=None):
        r = RULES[rule]
        self.out.append(
            Diagnostic(
                severity if severity is not None else r.severity,
                rule,
                message,
                loc or SourceLocation(self.file, 1, 1),
                hint,
            )
        )

    # --- entry ---------------------------------------------------------------------------
    def run(self) -> list[Diagnostic]:
        doc = self.doc
        if doc.adf_version is not None and doc.adf_version != "1.0":
            self.emit(
                "adf-version",
                f"'adf version' is {doc.adf_version!r}; AMBF only loads exactly 1.0",
                doc.where("adf version"),
                "write `adf version: 1.0` or remove the key",
            )
        self.numbers(doc)
        self.keys(doc, type(doc).__name__, top_level=True)
        if isinstance(doc, ModelFile):
            self.model(doc)
        elif isinstance(doc, World):
            self.world(doc)
        elif isinstance(doc, InputDevices):
            self.input_devices(doc)
        return self.out

    # --- numbers (NaN, inf, absurd magnitudes) --------------------------------------------
    def numbers(self, node: Node) -> None:
        """Non-finite and absurd numbers anywhere in the element (an explicit stack; plain
        floats, the common case, are checked without building lists)."""
        stack = [node]
        while stack:
            n = stack.pop()
            for f in adf_fields(n):
                value = getattr(n, f.name)
                if value is None:
                    continue
                cls = value.__class__
                key = f.metadata["adf_key"]
                if cls is float:
                    if value - value != 0.0 or (abs(value) > ABSURD and key not in UNBOUNDED_KEYS):
                        self._number(key, value, n.where(key))
                elif isinstance(value, Node):
                    stack.append(value)
                elif cls is list:
                    for item in value:
                        if isinstance(item, Node):
                            stack.append(item)
                        else:
                            self._number(key, item, n.where(key))
                else:
                    self._number(key, value, n.where(key))

    def _number(self, key: str, value, loc) -> None:
        if isinstance(value, bool):
            return
        if isinstance(value, Pose):
            values = [*value.position]
            quat = [*value.orientation]
        elif isinstance(value, Vec3):
            values, quat = [*value], []
        elif isinstance(value, Quat):
            values, quat = [], [*value]
        elif isinstance(value, (int, float)):
            values, quat = [value], []
        else:
            return
        if any(not math.isfinite(v) for v in values + quat):
            self.emit(
                "non-finite-number",
                f"'{key}' holds NaN or infinity",
                loc,
                "write a finite number; Bullet turns NaN into a broken simulation",
            )
        elif key not in UNBOUNDED_KEYS and any(abs(v) > ABSURD for v in values):
            self.emit(
                "absurd-value",
                f"'{key}' holds {max(values, key=abs):g}, an implausible magnitude",
                loc,
                "ADF uses metres, kilograms and radians; check the units",
            )

    # --- unknown and ignored keys ---------------------------------------------------------
    def keys(self, node: Node, cls_name: str, top_level: bool = False) -> None:
        known = adf_keys(node)
        for key in IGNORED_FIELDS.get(cls_name, ()):
            if key in node.key_sources:
                what = "parsed but unused" if key in PARSED_BUT_UNUSED else "not read"
                self.emit(
                    "ignored-key",
                    f"'{key}' is {what} by AMBF 2.x",
                    node.where(key),
                    "remove it, or move the value to a key AMBF reads",
                )
        for key in node.extras:
            if key in known:
                continue  # a read key whose value was null or failed to decode (reported elsewhere)
            loc = node.where(key)
            if key in IGNORED_KEYS["*"] | IGNORED_KEYS.get(cls_name, set()) or key.startswith(IGNORED_PREFIXES):
                self.emit(
                    "ignored-key",
                    f"'{key}' is not read by AMBF 2.x",
                    loc,
                    "remove it, or move the value to a key AMBF reads",
                )
                continue
            if top_level and isinstance(node.extras[key], dict):
                continue  # object mappings and anchor holders live at the top level
            near = difflib.get_close_matches(key, sorted(known), n=1, cutoff=0.8)
            if near:
                self.emit(
                    "unknown-key",
                    f"unknown key '{key}'; did you mean '{near[0]}'?",
                    loc,
                    f"rename it to '{near[0]}'; AMBF ignores unknown keys silently",
                    severity=Severity.WARNING,
                )
            elif not top_level:
                self.emit("unknown-key", f"'{key}' is not an ADF key of a {cls_name}; AMBF ignores it", loc)
        for f in adf_fields(node):
            value = getattr(node, f.name)
            items = value if isinstance(value, list) else [value]
            for item in items:
                if isinstance(item, Node):
                    self.keys(item, type(item).__name__)

    # --- model files ----------------------------------------------------------------------
    def model(self, m: ModelFile) -> None:
        listed = {o.identifier for o in m.all_objects()}
        for key in m.extras:
            if key.startswith(OBJECT_PREFIXES) and key not in listed and isinstance(m.extras[key], dict):
                self.emit(
                    "unlisted-object",
                    f"'{key}' is not listed in any object list; AMBF ignores it",
                    m.where(key),
                    "add it to its list (bodies:, joints:, ...) or delete it",
                )
        self.namespace(m)
        for obj in m.all_objects():
            self.names_and_namespace(obj)
        self.name_collisions(m)
        for b in m.bodies:
            self.body(b)
        for obj in [*m.bodies, *m.soft_bodies, *m.ghost_objects]:
            self.shapes(obj)
        for g in m.ghost_objects:
            if g.collision_groups:
                self.emit(
                    "collision-groups",
                    f"ghost '{g.identifier}' has collision groups; AMBF dereferences a null rigid body building them",
                    g.where("collision groups"),
                    "remove the groups",
                )
        own = body_registry([m])
        earlier = body_registry(self.context)
        for j in m.joints:
            self.joint(m, j, own, earlier)
        self.joint_poses(m, earlier)
        for s in [*m.sensors, *m.actuators]:
            self.sensor(s)
            self.reference(m, s, "parent", own, earlier, immediate=True)
        cameras = camera_registry([*self.context, m])
        for obj in [*m.ghost_objects, *m.cameras, *m.lights, *m.volumes]:
            self.reference(m, obj, "parent", own, earlier, immediate=False, cameras=cameras)
        for v in m.vehicles:
            self.reference(m, v, "chassis", own, earlier, immediate=True, world_only=True)
            for w in v.wheels or []:
                if w.body is not None:
                    self.reference(m, w, "body", own, earlier, immediate=True, world_only=True, owner=v)
        for light in m.lights:
            self.light(light)
        for c in m.cameras:
            self.camera(c)
        self.out += softbody_rules.check(m)
        for sb in m.soft_bodies:
            if sb.randomize_constraints is False:
                self.emit(
                    "randomize-constraints",
                    f"soft body '{sb.identifier}': 'randomize constraints: false' still turns randomisation on in AMBF",
                    sb.where("randomize constraints"),
                    "remove the key to keep constraints in order",
                )

    def namespace(self, obj) -> None:
        ns = getattr(obj, "namespace", None)
        if ns and not ns.endswith("/"):
            self.emit(
                "namespace-slash",
                f"namespace '{ns}' has no trailing '/'; AMBF glues it to identifiers ('{ns}BODY x')",
                obj.where("namespace"),
                "end prefixes with '/'",
            )

    def names_and_namespace(self, obj) -> None:
        if obj.name and " " in obj.name:
            self.emit(
                "name-spaces",
                f"name '{obj.name}' contains spaces; AMBF uses '{obj.name.replace(' ', '')}'",
                obj.where("name"),
                "remove the spaces",
            )
        self.namespace(obj)

    def name_collisions(self, m: ModelFile) -> None:
        for group in (
            m.bodies,
            m.joints,
            m.soft_bodies,
            m.ghost_objects,
            m.sensors,
            m.actuators,
            m.cameras,
            m.lights,
            m.vehicles,
            m.volumes,
        ):
            seen: dict[str, Any] = {}
            for obj in group:
                if not obj.name or not obj.defined:
                    continue
                stripped = merge_namespace(m.namespace, obj.namespace) + obj.name.replace(" ", "")
                first = seen.get(stripped)
                if first is not None and first is not obj:
                    self.emit(
                        "name-collision",
                        f"'{obj.identifier}' and '{first.identifier}' are both named "
                        f"'{stripped}' once AMBF strips spaces",
                        obj.where("name"),
                        "give each object a distinct name; ROS topics would clash",
                    )
                else:
                    seen[stripped] = obj

    def body(self, b) -> None:
        if not b.defined:
            return
        if b.mass is None:
            self.emit(
                "missing-mass",
                f"body '{b.identifier}' has no mass; AMBF uses 1 kg and ignores its inertia and inertial offset",
                b.where(),
                "add `mass:` (0 for a static body)",
            )
        elif b.mass < 0:
            self.emit(
                "negative-mass",
                f"body '{b.identifier}' has mass {b.mass:g}",
                b.where("mass"),
                "use a positive mass, or 0 for a static body",
            )
        if b.inertia is not None and b.mass is not None and b.mass > 0:
            moments = [b.inertia.ix, b.inertia.iy, b.inertia.iz]
            if all(v is not None for v in moments):
                ix, iy, iz = moments
                if min(moments) <= 0:
                    self.emit(
                        "inertia",
                        f"body '{b.identifier}' has a non-positive moment of inertia ({ix:g}, {iy:g}, {iz:g})",
                        b.where("inertia"),
                        "moments of a dynamic body are > 0 (AMBF cannot turn a body about an axis whose moment is 0, "
                        "and its pose turns NaN once a contact turns it)",
                    )
                elif any(a + c < e * (1 - 1e-6) for a, c, e in ((ix, iy, iz), (iy, iz, ix), (iz, ix, iy))):
                    self.emit(
                        "inertia",
                        f"body '{b.identifier}': moments ({ix:g}, {iy:g}, {iz:g}) violate the "
                        "triangle inequality (no rigid body has them)",
                        b.where("inertia"),
                        "each moment must be at most the sum of the other two",
                    )
        if b.scale is not None and math.isfinite(b.scale) and not 1e-3 <= b.scale <= 1e3:
            self.emit(
                "bad-scale",
                f"body '{b.identifier}' has scale {b.scale:g}",
                b.where("scale"),
                "scale multiplies meshes and pivots; use a positive value near 1",
            )

    def shapes(self, obj) -> None:
        entries = [
            ("shape", obj.shape, obj.where("shape")),
            ("collision shape", obj.collision_shape, obj.where("collision shape")),
        ]
        for key in ("compound shape", "compound collision shape"):
            for e in getattr(obj, key.replace(" ", "_")) or []:
                entries.append((key, e.shape, e.where("shape")))
        for key, text, loc in entries:
            if text is not None and shape_kind(text) is None:
                self.emit(
                    "shape-name",
                    f"'{key}' of '{obj.identifier}' is {text!r}; AMBF crashes on unknown shapes",
                    loc,
                    "use Box, Sphere, Cylinder, Capsule, Cone or Plane (or lower/upper case)",
                )
        if obj.collision_mesh_type is not None and not collision_mesh_type(obj.collision_mesh_type)[1]:
            self.emit(
                "collision-mesh-type",
                f"'collision mesh type' of '{obj.identifier}' is "
                f"{obj.collision_mesh_type!r}; AMBF prints an error and uses CONCAVE_MESH",
                obj.where("collision mesh type"),
                "use CONVEX_HULL, CONVEX_MESH, CONCAVE_MESH or POINT_CLOUD",
            )
        geoms = [obj.geometry, obj.collision_geometry] + [
            e.geometry for e in (obj.compound_shape or []) + (obj.compound_collision_shape or [])
        ]
        for g in geoms:
            if g is not None and g.axis is not None and g.axis not in ("x", "X", "y", "Y", "z", "Z"):
                self.emit(
                    "geometry-axis",
                    f"axis {g.axis!r} of '{obj.identifier}' is not x, y or z; AMBF uses z",
                    g.where("axis"),
                    "write x, y or z",
                )
        prims = [(obj.collision_shape, obj.collision_geometry)] + [
            (e.shape, e.geometry) for e in (obj.compound_collision_shape or [])
        ]
        for shape, g in prims:
            self.geometry_size(obj, shape, g)
        self.margin_size(obj)
        for grp in getattr(obj, "collision_groups", None) or []:
            if not 0 <= grp <= 999:
                self.emit(
                    "collision-groups",
                    f"collision group {grp} of '{obj.identifier}' is outside 0–999; AMBF drops it",
                    obj.where("collision groups"),
                    "use groups 0–999",
                )

    def geometry_size(self, obj, shape, g) -> None:
        """A collision primitive's sizes (adf-format.md §7.5): each > 0, and a capsule's height,
        caps included, at least its diameter."""
        kind = (shape or "").lower()
        if g is None or kind not in ("box", "sphere", "cylinder", "capsule", "cone"):
            return
        keys = ("x", "y", "z") if kind == "box" else ("radius",) if kind == "sphere" else ("radius", "height")
        for k in keys:
            v = getattr(g, k, None)
            if isinstance(v, (int, float)) and not isinstance(v, bool) and v <= 0:
                self.emit(
                    "geometry-size",
                    f"collision {kind} of '{obj.identifier}' has {k} {v:g}",
                    g.where(k),
                    "give every size a positive value",
                )
                return
        r, h = getattr(g, "radius", None), getattr(g, "height", None)
        if kind == "capsule" and isinstance(r, (int, float)) and isinstance(h, (int, float)) and h < 2 * r:
            self.emit(
                "geometry-size",
                f"collision capsule of '{obj.identifier}' is {h:g} m long with caps of radius {r:g}: AMBF "
                f"gives Bullet a cylinder part {h - 2 * r:g} m long",
                g.where("height"),
                "`height` is the capsule's whole length, caps included: at least twice the radius",
            )

    def margin_size(self, obj) -> None:
        """A moving body's collision cylinder whose `collision margin` is more than its radius or
        half its height: Bullet's cylinder then pushes off what it stands on (measured in AMBF: a
        0.02 m radius cylinder with margin 0.03 60 mm above where it rests by 0.5 s)."""
        m, g, mass = obj.collision_margin, obj.collision_geometry, getattr(obj, "mass", None)
        if (obj.collision_shape or "").lower() != "cylinder" or g is None or not isinstance(m, (int, float)):
            return
        if not isinstance(mass, (int, float)) or mass <= 0:
            return
        r, h = getattr(g, "radius", None), getattr(g, "height", None)
        sizes = [(k, v) for k, v in (("radius", r), ("half-height", h / 2 if isinstance(h, (int, float)) else None))]
        over = [(k, v) for k, v in sizes if isinstance(v, (int, float)) and 0 < v < m]
        if over:
            k, v = over[0]
            self.emit(
                "margin-size",
                f"collision margin {m:g} of '{obj.identifier}' is more than its cylinder's {k} ({v:g}): "
                "AMBF's cylinder pushes itself off what it stands on",
                obj.where("collision margin"),
                "keep the margin below the cylinder's radius and half its height (0.001 is AMBF's usual)",
            )

    def joint(self, m: ModelFile, j, own: Registry, earlier: Registry) -> None:
        if "enable motor" in j.key_sources and "enable feedback" not in j.key_sources:
            self.emit(
                "enable-motor-without-feedback",
                f"joint '{j.identifier}' has 'enable motor' without "
                "'enable feedback'; AMBF reads 'enable feedback' there and rejects the whole file",
                j.where("enable motor"),
                "add `enable feedback: false` (or remove `enable motor`)",
            )
        if not j.defined:
            return
        kind = joint_kind(j.type)
        if j.type is not None and kind is None:
            self.emit(
                "joint-type",
                f"joint '{j.identifier}' has type {j.type!r}; AMBF keeps the joint but creates no constraint",
                j.where("type"),
                "types are lower case: revolute, prismatic, "
                "fixed, continuous, linear spring, torsion spring, p2p, cone twist, six dof, six dof spring",
            )
        for key in ("parent axis", "child axis"):
            axis = getattr(j, key.replace(" ", "_"))
            if axis is not None and all(math.isfinite(c) for c in axis) and axis.norm() < 1e-12:
                self.emit(
                    "joint-zero-axis",
                    f"joint '{j.identifier}': '{key}' is the zero vector",
                    j.where(key),
                    "give a unit axis such as {x: 0, y: 0, z: 1}",
                )
        if j.parent is not None and j.parent == j.child:
            self.emit("joint-same-body", f"joint '{j.identifier}' joins '{j.parent}' to itself", j.where("child"))
        if kind in ONE_DOF or kind in (JointKind.FIXED, JointKind.P2P):
            self.static_parent(m, j)
        lim = j.joint_limits
        if kind in ONE_DOF and lim is not None:
            if (lim.low is None) != (lim.high is None):
                self.emit(
                    "joint-limits",
                    f"joint '{j.identifier}' has only one of low/high; AMBF then uses no limits",
                    j.where("joint limits"),
                    "write both low and high",
                )
            elif lim.low is not None and lim.high is not None and lim.low > lim.high:
                self.emit(
                    "joint-limits",
                    f"joint '{j.identifier}': low {lim.low:g} > high {lim.high:g}; Bullet treats the joint as free",
                    j.where("joint limits"),
                    "swap low and high",
                )
        if kind in (JointKind.SIX_DOF, JointKind.SIX_DOF_SPRING) and lim is not None:
            parts = [lim.linear, lim.angular]
            if any(p is None or p.low is None or p.high is None for p in parts):
                self.emit(
                    "joint-limits",
                    f"six-dof joint '{j.identifier}' limits lack the full "
                    "{linear, angular}{low, high}{x, y, z} structure; AMBF keeps the defaults (±1.2)",
                    j.where("joint limits"),
                    "write linear: {low: {x,y,z}, high: {x,y,z}} and the same for angular",
                )
        if kind is JointKind.CONE_TWIST and (lim is None or None in (lim.x, lim.y, lim.z)):
            self.emit(
                "joint-limits",
                f"cone-twist joint '{j.identifier}' needs joint limits {{x, y, z}}; AMBF prints an error and uses 0.7",
                j.where("joint limits") if lim else j.where("type"),
                "write joint limits: {x: ..., y: ..., z: ...} in radians",
            )
        if kind in SPRINGS and (lim is None or lim.low is None or lim.high is None):
            self.emit(
                "spring-without-limits",
                f"spring joint '{j.identifier}' has no limits; AMBF keeps its axis locked",
                j.where("type"),
                "add `joint limits: {low: ..., high: ...}`",
            )
        bodies = []
        for key in ("parent", "child"):
            bodies.append(self.reference(m, j, key, own, earlier, immediate=True))
        parent, child = bodies
        if parent is not None and child is not None and kind not in (None, JointKind.P2P):
            self.turned_inertial_frames(j, kind, parent, child)
        if parent is not None and child is not None and kind not in (None, JointKind.FIXED):
            pm, cm = parent.mass, child.mass
            if cm == 0 and pm == 0:
                self.emit(
                    "static-joint",
                    f"joint '{j.identifier}' joins two static bodies (mass 0); it cannot move",
                    j.where("type"),
                    "give the child a mass, or make the joint fixed",
                )
            elif cm == 0 and pm is not None and pm > 0:
                self.emit(
                    "static-joint",
                    f"joint '{j.identifier}': child '{j.child}' is static (mass 0) under a moving parent",
                    j.where("child"),
                    "give the child a mass",
                )

    def turned_inertial_frames(self, j, kind: JointKind, parent, child) -> None:
        """AMBF builds a joint's frames in its bodies' inertial frames (afJoint turns the axes
        and pivots into them and takes the shortest arc there): a turned `inertial offset`
        turns the joint's zero about its axis (semantics.inertial_joint_twist)."""
        twist = inertial_joint_twist(j, parent, child)
        if abs(twist) < 1e-6:
            return
        turned = [b for b in (child, parent) if inertial_rotation(b).angle_to(Quat()) > 1e-9]
        deg = math.degrees(twist)
        if kind in (JointKind.REVOLUTE, JointKind.TORSION_SPRING):
            what = (
                f"AMBF reads its value {deg:+.1f}° from what the bodies' frames give "
                "(its zero, its limits and every position command move with it)"
            )
        else:
            off = _held_off(j, parent, child)
            if off is not None and off < 1e-3:
                return  # placed as AMBF holds it (e.g. an `offset` that takes the turn back)
            what = f"AMBF holds the child turned {deg:+.1f}° about the joint's axis from where the body frames hold it"
            if off is not None:
                what += f", {math.degrees(off):.1f}° from where the file places it"
        names = " and ".join(f"'{b.identifier}'" for b in turned)
        frames = "frames of " + names + " are" if len(turned) > 1 else "frame of " + names + " is"
        # a revolute joint's turned zero is a note (adfkit reads it as AMBF does; `joint-pose`
        # warns where it puts the file's pose outside the limits); a child held off its
        # placement is a warning
        severity = Severity.INFO if kind in (JointKind.REVOLUTE, JointKind.TORSION_SPRING) else None
        self.emit(
            "inertial-frame-turns-joint",
            f"joint '{j.identifier}': the inertial {frames} turned, and AMBF builds the "
            f"joint's frames in the bodies' inertial frames: {what}",
            turned[0].where("inertial offset") if turned else j.where("type"),
            "write the inertial offset unturned (orientation 0) with the inertia in the body's axes, as "
            "AMBF's Blender add-on writes it",
            severity=severity,
        )

    def joint_poses(self, m: ModelFile, earlier: Registry | None = None) -> None:
        """Where the file's `location`s put each revolute/prismatic joint of the kinematic
        tree: within its limits, and with the child on the joint (its pose reproduced by the
        parent's location and one joint value); and each fixed, p2p, cone-twist or torsion-spring
        joint's two pivots together (a revolute joint's too where it joins a body of an earlier
        file, ``earlier``, which the tree of this file does not hold)."""
        self.pivots_apart(m, earlier)
        if not any(joint_kind(j.type) in TREE_ONE_DOF for j in m.joints):
            return
        from ..model.tree import build_tree, motion

        tree = build_tree(m)
        for link in tree.ordered():
            j, parent = link.joint, link.parent
            if link.kind not in TREE_ONE_DOF or j is None or parent is None or not j.defined:
                continue
            if link.body.location is None or parent.body.location is None:
                continue
            unit = "rad" if link.kind is JointKind.REVOLUTE else "m"
            lim = j.joint_limits
            if (
                lim is not None
                and lim.low is not None
                and lim.high is not None
                and lim.low <= lim.high
                and not _within(link.q0, lim.low, lim.high, link.kind is JointKind.REVOLUTE)
            ):
                self.emit(
                    "joint-pose",
                    f"the locations of '{parent.body.identifier}' and '{link.body.identifier}' put "
                    f"joint '{j.identifier}' at {link.q0:.4g} {unit}, outside its limits {lim.low:g}…{lim.high:g}; "
                    "AMBF's limit moves the child on the first step",
                    j.where("joint limits"),
                    "move the child body to a pose within the limits, or widen the limits",
                )
            fits = (
                parent.body.location
                * parent.frame_in_body
                * link.origin
                * motion(link.kind, link.q0)
                * link.frame_in_body.inverse()
            )
            off = (fits.position - link.body.location.position).norm()
            turn = fits.orientation.angle_to(link.body.location.orientation)
            if off > POSE_TOLERANCE or turn > POSE_ANGLE_TOLERANCE:
                self.emit(
                    "joint-pose",
                    f"'{link.body.identifier}' is not where joint '{j.identifier}' puts it: "
                    f"{off * 1000:.1f} mm and {math.degrees(turn):.1f}° away at the best joint value "
                    f"({link.q0:.4g} {unit}); AMBF snaps it onto the joint on the first step",
                    link.body.where("location"),
                    "fix the body's location or the joint's pivots and axes "
                    "(the Blender add-on writes both from the scene)",
                )

    def static_parent(self, m: ModelFile, j) -> None:
        """A hinge, slider, spring, fixed or p2p joint whose parent is static (mass 0) with no
        collision shape of any kind and no `inertia`: AMBF prints "COLLISION TYPE NOT UNDERSTOOD"
        and the joint holds nothing in place (measured: a hinged, fixed or p2p child falls freely,
        unturned; a spring's child falls, pulled to the spring's equilibrium, past its limits;
        given `inertia`, the post holds; runner/plan.py holds_nothing)."""
        from ..model.tree import find_body

        p: Any = find_body(m, j.parent, j)
        if p is None or p is find_body(m, j.child, j) or not holds_no_joint(p):
            return
        self.emit(
            "joint-static-parent",
            f"joint '{j.identifier}': its parent '{j.parent}' is static with no collision shape and no inertia; "
            "AMBF keeps the joint and it holds nothing in place (the child falls free)",
            j.where("parent"),
            "give the parent a `collision shape` or an `inertia` (it stays static) for the joint to hold",
        )

    def pivots_apart(self, m: ModelFile, earlier: Registry | None = None) -> None:
        """A joint that holds its pivots together (fixed, p2p, cone twist, torsion spring; a
        revolute joint to a body of an earlier file) whose bodies' `location`s put its pivots
        apart: AMBF starts the bodies there and its constraint pulls them together over the first
        steps (the MuJoCo engine starts the child on the joint)."""
        from ..model.tree import find_body

        for j in m.joints:
            kind = joint_kind(j.type)
            if not j.defined or kind not in (*PIVOTS_HELD, JointKind.REVOLUTE):
                continue
            parent: Any = find_body(m, j.parent, j)
            child: Any = find_body(m, j.child, j)
            crossing = False
            if earlier is not None and (parent is None or child is None):
                jns = merge_namespace(m.namespace, j.namespace)
                found: list[Any] = []
                for ref, mine in ((j.parent, parent), (j.child, child)):
                    if mine is None and ref:
                        verdict, keys = earlier.lookup(ref, jns + ref)
                        if verdict == "found":
                            mine, crossing = earlier.keys[keys[0]], True
                    found.append(mine)
                parent, child = found
            if kind not in PIVOTS_HELD and not crossing:
                continue  # a revolute joint within this file: joint_poses reads it through the tree
            if parent is None or child is None or parent is child:
                continue
            if parent.location is None or child.location is None:
                continue
            try:
                a, b = body_joint_frames(j, parent, child)
            except (TypeError, ValueError, ZeroDivisionError):
                continue  # incomplete pivots or axes: the schema says so
            gap = ((parent.location * a).position - (child.location * b).position).norm()
            if gap > POSE_TOLERANCE:
                self.emit(
                    "joint-pose",
                    f"the locations of '{parent.identifier}' and '{child.identifier}' put the pivots of "
                    f"{j.type} joint '{j.identifier}' {gap * 1000:.1f} mm apart; AMBF starts them there "
                    "and its joint pulls them together over the first steps",
                    child.where("location"),
                    "fix the child's location or the joint's pivots (the Blender add-on writes both from the scene)",
                )

    def reference(
        self,
        m,
        obj,
        key: str,
        own: Registry,
        earlier: Registry,
        *,
        immediate: bool,
        world_only: bool = False,
        owner=None,
        cameras: Registry | None = None,
    ):
        text = getattr(obj, key)
        label = (owner or obj).identifier
        if text is None or text == "":
            return None
        loc = obj.where(key)
        prefixed = None if world_only else merge_namespace(m.namespace, getattr(obj, "namespace", None)) + text
        for registry in ([] if world_only else [own]) + [earlier]:
            status, hits = registry.lookup(text, prefixed)
            if status == "found":
                return registry.keys[hits[0]]
            if status == "missing" and registry is earlier and cameras is not None:
                status, found = cameras.lookup(text, prefixed)
                if status == "found":
                    return cameras.keys[found[0]]
            if status == "ambiguous":
                self.emit(
                    "ambiguous-reference",
                    f"'{key}' of '{label}' ({text!r}) matches {len(hits)} bodies: "
                    f"{', '.join(hits[:4])}{' ...' if len(hits) > 4 else ''}",
                    loc,
                    "write the full identifier so exactly one body matches",
                )
                return None
        if self.context or (immediate and not world_only):
            where = "this file or the models loaded before it" if self.context else "this file"
            hint = (
                "check the spelling; AMBF skips the object. If the body lives in another model, "
                "validate the launch file so the models loaded earlier are searched"
            )
            if world_only:
                where = "the models loaded before this one"
                if own.lookup(text, None)[0] == "found":
                    hint = (
                        "AMBF finds a vehicle's bodies only among the models loaded before the vehicle's: "
                        "move the vehicle to a file listed after its bodies' file"
                    )
            self.emit(
                "dangling-reference", f"'{key}' of '{label}' is {text!r}, which names no body in {where}", loc, hint
            )
        else:
            self.emit(
                "external-reference",
                f"'{key}' of '{label}' ({text!r}) is not in this file; AMBF looks for it in the models loaded with it",
                loc,
                "validate the launch file to check it",
            )
        return None

    def sensor(self, s) -> None:
        if not s.defined:
            return
        types = SENSOR_TYPES if type(s).__name__ == "Sensor" else ACTUATOR_TYPES
        what = type(s).__name__.lower()
        if s.type is None:
            self.emit(
                "missing-type",
                f"{what} '{s.identifier}' has no type; AMBF skips it",
                s.where(),
                f"add `type: {next(iter(types))}`",
            )
        elif s.type not in types:
            self.emit(
                "sensor-type",
                f"{what} '{s.identifier}' has type {str(s.type)[:60]!r}, unknown to AMBF 2.0 "
                "(which crashes on it; later AMBF versions and plugins define more types)",
                s.where("type"),
                f"for AMBF 2.0 use one of {', '.join(types)}",
            )
        if s.parent is None or s.parent == "":
            self.emit(
                "missing-parent",
                f"{what} '{s.identifier}' has no parent; AMBF attaches it to nothing and skips it",
                s.where(),
                "add `parent: BODY ...`",
            )
        if type(s).__name__ == "Sensor":
            forms = [k for k in ("array", "mesh", "parametric") if getattr(s, k) is not None]
            if len(forms) != 1:
                self.emit(
                    "sensor-rays",
                    f"sensor '{s.identifier}' has {len(forms)} ray forms "
                    f"({', '.join(forms) or 'none'}); AMBF needs exactly one",
                    s.where(),
                    "give exactly one of array, mesh or parametric",
                )
            if s.range is not None and s.range < 0:
                self.emit(
                    "sensor-rays",
                    f"sensor '{s.identifier}' has a negative range {s.range:g}",
                    s.where("range"),
                    "range is a length in metres, >= 0",
                )
            if s.parametric is not None and s.parametric.resolution is not None and s.parametric.resolution < 2:
                self.emit(
                    "sensor-rays",
                    f"sensor '{s.identifier}': parametric resolution {s.parametric.resolution} < 2",
                    s.parametric.where("resolution"),
                    "use 2 or more",
                )

    def camera(self, c) -> None:
        if not c.defined:
            return
        loc = c.location or Vec3(0.0, 0.0, 0.0)
        look = c.look_at or Vec3(0.0, 0.0, 0.0)
        up = c.up or Vec3(0.0, 0.0, 1.0)
        view = look - loc
        if not all(math.isfinite(v) for v in (*view, *up)):
            return
        if view.norm() < 1e-12:
            self.emit(
                "camera-view",
                f"camera '{c.identifier}': 'look at' equals 'location'; AMBF silently does not set the view",
                c.where("look at"),
                "look at a point away from the camera",
            )
        elif up.norm() < 1e-12 or view.cross(up).norm() < 1e-9 * view.norm() * up.norm():
            self.emit(
                "camera-view",
                f"camera '{c.identifier}': 'up' is parallel to the view direction; AMBF silently does not set the view",
                c.where("up"),
                "choose an up vector across the view direction",
            )

    def light(self, light) -> None:
        if light.defined and light.shadow_quality is None:
            self.emit(
                "light-shadow",
                f"light '{light.identifier}' has no 'shadow quality'; AMBF leaves it uninitialised",
                light.where(),
                "add `shadow quality:` 0 (none) to 5",
            )
        elif light.shadow_quality is not None and light.shadow_quality > 5:
            self.emit(
                "light-shadow",
                f"light '{light.identifier}': shadow quality {light.shadow_quality} > 5",
                light.where("shadow quality"),
                "use 0 (none) to 5",
            )

    # --- worlds and input devices ---------------------------------------------------------
    def world(self, w: World) -> None:
        if not w.environment:
            self.emit(
                "no-environment",
                "the world has no 'environment' model; AMBF then uses an uninitialised model pointer",
                w.where(),
                "add `environment: <model file>` (enclosure size is not read)",
            )
        for obj in [*w.lights, *w.cameras]:
            self.names_and_namespace(obj)
        for light in w.lights:
            self.light(light)
        for c in w.cameras:
            self.camera(c)

    def input_devices(self, d: InputDevices) -> None:
        for dev in d.input_devices:
            if dev.defined and not dev.hardware_name:
                self.emit(
                    "input-device",
                    f"input device '{dev.identifier}' has no 'hardware name'; AMBF skips it",
                    dev.where(),
                    "add `hardware name:` with the CHAI3D driver's model name",
                )


def _held_off(j, parent, child) -> float | None:
    """How far (rad) AMBF holds the child of a joint that locks the turn about its axis (fixed,
    prismatic, ...) from the turn the file's `location`s give it; None without both locations."""
    if parent.location is None or child.location is None:
        return None
    a, b = body_joint_frames(j, parent, child)
    held = a.orientation * b.orientation.inverse()
    placed = parent.location.orientation.inverse() * child.location.orientation
    return held.angle_to(placed)


def _within(q: float, low: float, high: float, angular: bool) -> bool:
    """q within [low, high] (to POSE_TOLERANCE), for an angle at any turn."""
    turns = (-1, 0, 1) if angular else (0,)
    return any(low - POSE_TOLERANCE <= q + 2 * math.pi * k <= high + POSE_TOLERANCE for k in turns)


def check(doc, context_models=()) -> list[Diagnostic]:
    if isinstance(doc, (Launch, Colors)):
        checker = Checker(doc)
        checker.numbers(doc)
        if doc.adf_version is not None and doc.adf_version != "1.0":
            checker.emit(
                "adf-version",
                f"'adf version' is {doc.adf_version!r}; AMBF only loads exactly 1.0",
                doc.where("adf version"),
            )
        if isinstance(doc, Launch):
            checker.keys(doc, "Launch", top_level=True)
        return checker.out
    return Checker(doc, context_models).run()
