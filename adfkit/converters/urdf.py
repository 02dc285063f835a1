"""URDF ⇄ scene model (format-mapping.md).

Writing: the spanning tree of ``tree.py``; each URDF link frame is the ADF joint frame B
of its body (the body frame for the root), so a URDF joint rotates about its child link's
origin as ADF's does about the child pivot. Visual, collision and inertial data move from the
ADF body frame into that link frame. A static root (mass 0) is welded to a `world` link by a
fixed joint that carries its `location`.

Reading: each link becomes a body whose frame is the link frame times its (first) visual
origin, because ADF has no visual offset; joints get pivots and axes in both body frames and
the ADF `offset` that reproduces the URDF origin's twist about the axis.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from pathlib import Path

from ..adf.paths import collision_mesh_path, visual_mesh_path
from ..adf.writer import atomic_write_text
from ..diagnostics import AdfError, error
from ..model.common import RGBA, Friction, Geometry, ShapeEntry
from ..model.files import ModelFile
from ..model.objects import Body, Inertia, Joint, JointLimits
from ..model.pose import Pose, Quat, Vec3
from ..model.semantics import (
    JointKind,
    ShapeKind,
    collision_primitives,
    effective_mass,
    inertial_offset,
    shortest_arc,
)
from ..model.tree import Link, build_tree
from . import inertia as inertia_math
from .engine_fit import MeshFiles, joint_range, usable_scales
from .losses import Loss
from .safexml import XmlDocument, parse_xml, to_text

# --- writing ------------------------------------------------------------------------------

_AXIS_TO_Z = {  # rotation taking URDF's z-axis primitive onto ADF's `axis`
    "x": Quat.from_axis_angle(Vec3(0.0, 1.0, 0.0), math.pi / 2),
    "y": Quat.from_axis_angle(Vec3(1.0, 0.0, 0.0), -math.pi / 2),
    "z": Quat(0.0, 0.0, 0.0, 1.0),
}

# Joint values below this (rad or m) come from rounding in the file's poses, not an intent.
INITIAL_VALUE_TOLERANCE = 1e-4

# Body keys URDF has no element for (reported when the file sets them).
_BODY_ONLY = {
    "friction": "friction",
    "restitution": "restitution",
    "damping": "damping",
    "collision_groups": "collision groups",
    "collision_margin": "collision margin",
    "controller": "controller",
    "gravity": "gravity",
    "shaders": "shaders",
    "plugins": "plugins",
    "publish_frequency": "publish frequency",
    "passive": "passive",
}
_LOSSY_OBJECTS = (
    ("ghost_objects", "ghost object"),
    ("sensors", "sensor"),
    ("actuators", "actuator"),
    ("cameras", "camera"),
    ("lights", "light"),
    ("soft_bodies", "soft body"),
    ("vehicles", "vehicle"),
    ("volumes", "volume"),
)


def _num(v: float) -> str:
    v = 0.0 if abs(v) < 1e-15 else float(v)
    return repr(v)


def _vec(v) -> str:
    return " ".join(_num(x) for x in v)


def _origin(parent: ET.Element, pose: Pose) -> None:
    if pose.position.norm() < 1e-15 and pose.orientation.angle_to(Quat(0.0, 0.0, 0.0, 1.0)) < 1e-15:
        return
    ET.SubElement(parent, "origin", xyz=_vec(pose.position), rpy=_vec(pose.rpy()))


def _link_name(body: Body) -> str:
    return body.name or body.identifier.removeprefix("BODY ").strip()


def _joint_name(joint: Joint) -> str:
    return joint.name or joint.identifier.removeprefix("JOINT ").strip()


def _unique(name: str, used: set[str]) -> str:
    out, n = name, 1
    while out in used:
        n += 1
        out = f"{name}_{n}"
    used.add(out)
    return out


def _mesh_ref(mesh: Path, out_dir: Path) -> str:
    return Path(os.path.relpath(mesh.resolve(), out_dir.resolve())).as_posix()


def _primitive_geometry(kind: ShapeKind, g: Geometry, el: ET.Element) -> list[tuple[ET.Element, Pose]] | None:
    """URDF geometry elements (each with a pose in the primitive frame) for one ADF primitive."""
    if kind is ShapeKind.BOX:
        geo = ET.Element("geometry")
        ET.SubElement(geo, "box", size=_vec((g.x or 0.0, g.y or 0.0, g.z or 0.0)))
        return [(geo, Pose())]
    if kind is ShapeKind.SPHERE:
        geo = ET.Element("geometry")
        ET.SubElement(geo, "sphere", radius=_num(g.radius or 0.0))
        return [(geo, Pose())]
    turn = Pose(Vec3(), _AXIS_TO_Z.get((g.axis or "z").lower(), _AXIS_TO_Z["z"]))
    if kind is ShapeKind.CYLINDER:
        geo = ET.Element("geometry")
        ET.SubElement(geo, "cylinder", radius=_num(g.radius or 0.0), length=_num(g.height or 0.0))
        return [(geo, turn)]
    if kind is ShapeKind.CAPSULE:  # ADF height = total incl. caps: a cylinder and two spheres
        r, h = g.radius or 0.0, g.height or 0.0
        body_len = max(h - 2 * r, 0.0)
        out = []
        geo = ET.Element("geometry")
        ET.SubElement(geo, "cylinder", radius=_num(r), length=_num(body_len))
        out.append((geo, turn))
        for s in (-1.0, 1.0):
            geo = ET.Element("geometry")
            ET.SubElement(geo, "sphere", radius=_num(r))
            out.append((geo, turn * Pose(Vec3(0.0, 0.0, s * body_len / 2))))
        return out
    return None


def _material(body: Body) -> tuple[float, float, float, float] | None:
    if body.color_rgba is not None:
        c = body.color_rgba
        return (c.r or 0.0, c.g or 0.0, c.b or 0.0, 1.0 if c.a is None else c.a)
    cc = body.color_components
    if cc is not None and cc.diffuse is not None:
        d = cc.diffuse
        a = cc.transparency if cc.transparency is not None else 1.0  # chai3d: 1 = opaque
        return (d.r or 0.0, d.g or 0.0, d.b or 0.0, a)
    return None


def _mesh_element(link_el: ET.Element, tag: str, pose: Pose, mesh: Path, scale: float, out_dir: Path) -> ET.Element:
    """A <visual> or <collision> holding a mesh at ``pose`` in the link frame."""
    el = ET.SubElement(link_el, tag)
    _origin(el, pose)
    m = ET.SubElement(ET.SubElement(el, "geometry"), "mesh", filename=_mesh_ref(mesh, out_dir))
    if scale != 1.0:
        m.set("scale", _vec((scale,) * 3))
    return el


def _write_link(
    robot: ET.Element, model: ModelFile, link: Link, name: str, out_dir: Path, losses: list[Loss], files: MeshFiles
) -> None:
    body = link.body
    el = ET.SubElement(robot, "link", name=name)
    who = body.identifier
    scale = body.scale if body.scale is not None else 1.0
    mass = effective_mass(body)
    inertial = ET.SubElement(el, "inertial")
    _origin(inertial, link.in_link(inertial_offset(body)))
    ET.SubElement(inertial, "mass", value=_num(mass))
    ix, iy, iz = inertia_math.adf_principal(body)
    if body.inertia is None and mass > 0:
        est = inertia_math.estimate_from_collision(model, body, mass)
        if est is None:
            losses.append(
                Loss(who, "inertia", "not in the ADF file and no collision shape to estimate it from; written as 0")
            )
        else:
            ix, iy, iz = est
            losses.append(
                Loss(
                    who,
                    "inertia",
                    "not in the ADF file: written as Bullet's estimate "
                    "(box inertia of the collision shape's bounding box)",
                )
            )
    ET.SubElement(inertial, "inertia", ixx=_num(ix), ixy="0.0", ixz="0.0", iyy=_num(iy), iyz="0.0", izz=_num(iz))
    to_link = link.frame_in_body.inverse()
    mesh = visual_mesh_path(model, body)
    if mesh is not None:
        mesh = files.fit(mesh, who, losses)[0]
    if mesh is not None:
        vis = _mesh_element(el, "visual", to_link, mesh, scale, out_dir)
        rgba = _material(body)
        if rgba is not None:
            mat = ET.SubElement(vis, "material", name=f"{name}_material")
            ET.SubElement(mat, "color", rgba=_vec(rgba))
    elif body.shape or body.compound_shape:
        losses.append(Loss(who, "visual primitive shape", "written only as collision geometry"))
    prims = collision_primitives(body)
    if prims is None:
        cmesh = collision_mesh_path(model, body)
        if cmesh is not None:
            cmesh = files.fit(cmesh, who, losses)[0]
        if cmesh is not None:
            _mesh_element(el, "collision", to_link, cmesh, scale, out_dir)
            if body.collision_mesh_type is not None:
                losses.append(Loss(who, "collision mesh type", "URDF has none; PyBullet uses the convex hull"))
    else:
        for prim in prims:
            parts = _primitive_geometry(prim.kind, prim.geometry, el)
            if parts is None:
                losses.append(Loss(who, f"collision {prim.kind.value}", "URDF has no such primitive"))
                continue
            if prim.kind is ShapeKind.CAPSULE:
                losses.append(
                    Loss(who, "collision capsule", "URDF has no capsule: written as a cylinder and two spheres")
                )
            for geo, local in parts:
                col = ET.SubElement(el, "collision")
                _origin(col, to_link * prim.pose * local)
                col.append(geo)
    _body_only_losses(body, losses)


def _body_only_losses(body: Body, losses: list[Loss]) -> None:
    for attr, key in _BODY_ONLY.items():
        if getattr(body, attr, None) not in (None, [], False):
            losses.append(Loss(body.identifier, key, "URDF has no element for it"))


def _is_bare(model: ModelFile, body: Body) -> bool:
    """A static body with nothing to show, collide or weigh, at the world origin: an empty
    URDF link (what a URDF's `world` link reads as)."""
    loc = body.location or Pose()
    return (
        visual_mesh_path(model, body) is None
        and not body.shape
        and not body.compound_shape
        and collision_primitives(body) is None
        and collision_mesh_path(model, body) is None
        and body.inertia is None
        and loc.position.norm() < 1e-12
        and loc.orientation.angle_to(Quat(0.0, 0.0, 0.0, 1.0)) < 1e-12
    )


def _write_joint(robot: ET.Element, link: Link, name: str, parent: str, child: str, losses: list[Loss]) -> None:
    j = link.joint
    limits = joint_range(j, losses) if link.kind in (JointKind.REVOLUTE, JointKind.PRISMATIC) else None
    has_limits = limits is not None
    if link.kind is JointKind.REVOLUTE:
        jtype = "revolute" if has_limits else "continuous"
    elif link.kind is JointKind.PRISMATIC:
        jtype = "prismatic"
        if not has_limits:
            losses.append(
                Loss(j.identifier, "unlimited prismatic", "URDF prismatic joints need limits; written as ±1e3 m")
            )
    else:
        jtype = "fixed"
    el = ET.SubElement(robot, "joint", name=name, type=jtype)
    _origin(el, link.origin)
    ET.SubElement(el, "parent", link=parent)
    ET.SubElement(el, "child", link=child)
    if jtype != "fixed":
        ET.SubElement(el, "axis", xyz=_vec(link.axis))
    if jtype in ("revolute", "prismatic"):
        low, high = limits if has_limits else (-1e3, 1e3)
        ET.SubElement(el, "limit", lower=_num(low), upper=_num(high), effort="0.0", velocity="0.0")
    if isinstance(j.damping, float) and jtype != "fixed":
        ET.SubElement(el, "dynamics", damping=_num(j.damping))
    if abs(link.q0) > INITIAL_VALUE_TOLERANCE:
        losses.append(
            Loss(
                j.identifier,
                "initial value",
                f"the bodies' locations put the joint at {link.q0:.6g}; URDF starts every joint at 0",
            )
        )
    for attr, key in (
        ("controller", "controller"),
        ("max_motor_impulse", "max motor impulse"),
        ("stiffness", "stiffness"),
        ("equilibrium_point", "equilibrium point"),
        ("controller_output_type", "controller output type"),
    ):
        if getattr(j, attr, None) is not None:
            losses.append(Loss(j.identifier, key, "URDF has no element for it"))
    if j.damping is not None and not isinstance(j.damping, float):
        losses.append(Loss(j.identifier, "damping", "per-axis damping has no URDF form"))


def to_urdf(model: ModelFile, out_dir: Path, robot_name: str | None = None) -> tuple[str, list[Loss]]:
    """The URDF text for ``model`` (mesh paths relative to ``out_dir``) and the losses.
    Meshes PyBullet cannot read are converted to STL in ``<robot name>_meshes/`` there."""
    losses: list[Loss] = []
    model = usable_scales(model, losses)
    files = MeshFiles("urdf", out_dir, robot_name or model.name, getattr(model, "tree", None))
    tree = build_tree(model)
    name = robot_name or model.name
    robot = ET.Element("robot", name=name)
    roots = [r for r in tree.roots]
    if not roots:
        raise AdfError(
            error(
                "convert-empty",
                "the model has no bodies; there is nothing to write as URDF",
                model.where(),
                "convert a model file with at least one body",
            )
        )
    # URDF holds one tree: the one with the most bodies (the first of equals, in file order)
    sizes = {id(r): sum(1 for lk in tree.ordered() if _root_of(lk) is r) for r in roots}
    main = max(roots, key=lambda r: sizes[id(r)])
    for other in [r for r in roots if r is not main]:
        stack = [other]
        while stack:
            lk = stack.pop()
            losses.append(
                Loss(
                    lk.body.identifier,
                    "body",
                    "not joined to the root by revolute/prismatic/fixed joints; URDF holds one tree",
                )
            )
            if lk.joint is not None:
                losses.append(Loss(lk.joint.identifier, "joint", "its bodies are outside the URDF tree"))
            stack.extend(lk.children)
    used: set[str] = set()
    names: dict[int, str] = {}
    order = [lk for lk in tree.ordered() if _root_of(lk) is main]
    static_root = effective_mass(main.body) == 0.0
    bare_root = static_root and _is_bare(model, main.body)
    if bare_root:  # a shapeless static body at the origin is the world link itself
        static_root = False
    elif static_root:
        world = _unique("world", used)
        ET.SubElement(robot, "link", name=world)
    else:
        _root_frame_at_world(main)
    for lk in order:
        names[id(lk)] = _unique(_link_name(lk.body), used)
        if bare_root and lk is main:
            ET.SubElement(robot, "link", name=names[id(lk)])
            _body_only_losses(lk.body, losses)
        else:
            _write_link(robot, model, lk, names[id(lk)], out_dir, losses, files)
    if static_root:
        el = ET.SubElement(robot, "joint", name=_unique(f"world_to_{names[id(main)]}", used), type="fixed")
        _origin(el, main.origin)
        ET.SubElement(el, "parent", link=world)
        ET.SubElement(el, "child", link=names[id(main)])
    for lk in order:
        if lk.parent is not None:
            _write_joint(robot, lk, _unique(_joint_name(lk.joint), used), names[id(lk.parent)], names[id(lk)], losses)
    for j, kind, _p, _c in tree.loops:
        why = (
            "closes a loop; URDF is a tree"
            if kind in (JointKind.REVOLUTE, JointKind.PRISMATIC, JointKind.FIXED)
            else f"URDF has no {kind.value} joint"
        )
        losses.append(Loss(j.identifier, "joint", why))
    for j in tree.unresolved:
        losses.append(Loss(j.identifier, "joint", "unknown type or parent/child body not in this file"))
    for attr, label in _LOSSY_OBJECTS:
        for obj in getattr(model, attr):
            losses.append(Loss(obj.identifier, label, "URDF has no element for it"))
    text = '<?xml version="1.0"?>\n' + to_text(robot) + "\n"
    return text, sorted(set(losses))


def _root_frame_at_world(root: Link) -> None:
    """A floating URDF root has no world pose, so its link frame is put where the world frame
    is when the bodies stand at their `location`s: loaded at the origin (PyBullet's default
    base pose) the robot stands where the ADF file puts it, and reading the URDF back gives
    the same `location`s. Visual, collision and inertial origins carry the root's location."""
    shift = root.origin
    root.frame_in_body = shift.inverse()
    root.origin = Pose()
    for child in root.children:
        child.origin = shift * child.origin


def _root_of(link: Link) -> Link:
    while link.parent is not None:
        link = link.parent
    return link


def write(model: ModelFile, path: Path) -> list[Loss]:
    path = Path(path)
    text, losses = to_urdf(model, path.parent, path.stem)
    atomic_write_text(path, text)
    return losses


# --- reading ------------------------------------------------------------------------------


def _floats(doc: XmlDocument, el: ET.Element, attr: str, n: int, default=None) -> tuple[float, ...]:
    raw = el.get(attr)
    if raw is None:
        if default is None:
            raise AdfError(
                error(
                    "urdf-attribute",
                    f"<{el.tag}> lacks '{attr}'",
                    doc.where(el),
                    f'add {attr}="..." with {n} number(s)',
                )
            )
        return default
    try:
        vals = tuple(float(x) for x in raw.split())
    except ValueError:
        vals = ()
    if len(vals) != n or not all(math.isfinite(v) for v in vals):
        raise AdfError(
            error(
                "urdf-number",
                f'<{el.tag} {attr}="{raw}">: expected {n} finite number(s)',
                doc.where(el),
                f"write {attr} as {n} space-separated numbers",
            )
        )
    return vals


def _pose_of(doc: XmlDocument, el: ET.Element | None) -> Pose:
    o = el.find("origin") if el is not None else None
    if o is None:
        return Pose()
    return Pose.from_rpy(_floats(doc, o, "xyz", 3, (0.0, 0.0, 0.0)), _floats(doc, o, "rpy", 3, (0.0, 0.0, 0.0)))


def _twist(a: Vec3, q: Quat) -> float:
    """The angle of a rotation ``q`` about the unit axis ``a`` (q must be a rotation about a)."""
    return 2.0 * math.atan2(q.x * a[0] + q.y * a[1] + q.z * a[2], q.w)


def _geometry_entry(doc: XmlDocument, geo: ET.Element, pose: Pose, who: str, losses: list[Loss]) -> ShapeEntry | None:
    kid = next(iter(geo), None)
    if kid is None:
        raise AdfError(
            error("urdf-geometry", "<geometry> is empty", doc.where(geo), "add box, cylinder, sphere or mesh")
        )
    if kid.tag == "box":
        x, y, z = _floats(doc, kid, "size", 3)
        return ShapeEntry(shape="box", geometry=Geometry(x=x, y=y, z=z), offset=pose)
    if kid.tag == "sphere":
        (r,) = _floats(doc, kid, "radius", 1)
        return ShapeEntry(shape="sphere", geometry=Geometry(radius=r), offset=pose)
    if kid.tag == "cylinder":
        (r,) = _floats(doc, kid, "radius", 1)
        (h,) = _floats(doc, kid, "length", 1)
        return ShapeEntry(shape="cylinder", geometry=Geometry(radius=r, height=h, axis="z"), offset=pose)
    losses.append(Loss(who, f"collision {kid.tag}", "no ADF primitive for it"))
    return None


def _mesh_file(doc: XmlDocument, mesh: ET.Element) -> tuple[str, float | None]:
    fn = mesh.get("filename")
    if not fn:
        raise AdfError(error("urdf-attribute", "<mesh> lacks 'filename'", doc.where(mesh), "name the mesh file"))
    if fn.startswith("file://"):
        fn = fn[len("file://") :]
    if fn.startswith("package://"):
        p = _package_file(doc, fn)
        if p is None:
            raise AdfError(
                error(
                    "urdf-package-uri",
                    f"cannot find {fn!r} near the URDF file",
                    doc.where(mesh),
                    "replace package:// URIs with paths relative to the URDF file",
                )
            )
        fn = str(p)
    p = Path(fn)
    if not p.is_absolute() and doc.path is not None:
        p = (doc.path.parent / p).resolve()
    scale = None
    if mesh.get("scale") is not None:
        s = _floats(doc, mesh, "scale", 3)
        if not (abs(s[0] - s[1]) < 1e-12 and abs(s[1] - s[2]) < 1e-12):
            raise AdfError(
                error(
                    "urdf-scale",
                    f"non-uniform mesh scale {mesh.get('scale')!r}",
                    doc.where(mesh),
                    "ADF scales a body uniformly; rescale the mesh file",
                )
            )
        scale = s[0]
    return str(p), scale


def _package_file(doc: XmlDocument, uri: str) -> Path | None:
    """Resolve ``package://PKG/REST`` without ROS the way PyBullet does: look for REST (and
    PKG/REST) beside the URDF file and in its parent folders."""
    rest = uri[len("package://") :]
    pkg, _, tail = rest.partition("/")
    base = doc.path.parent if doc.path is not None else Path.cwd()
    for root in [base, *list(base.parents)[:3]]:
        for cand in (root / tail, root / rest, root / pkg / tail):
            if cand.is_file():
                return cand.resolve()
    return None


def read(path: Path) -> tuple[ModelFile, list[Loss]]:
    doc = parse_xml(path)
    return from_urdf(doc)


def from_urdf(doc: XmlDocument) -> tuple[ModelFile, list[Loss]]:
    root = doc.root
    if root.tag != "robot":
        raise AdfError(
            error(
                "urdf-root",
                f"the root element is <{root.tag}>, not <robot>",
                doc.where(root),
                "a URDF file holds one <robot>",
            )
        )
    losses: list[Loss] = []
    links: dict[str, ET.Element] = {}
    for el in root.findall("link"):
        name = el.get("name")
        if not name:
            raise AdfError(error("urdf-attribute", "<link> without a name", doc.where(el), 'add name="..."'))
        if name in links:
            raise AdfError(error("urdf-duplicate", f"link {name!r} defined twice", doc.where(el), "rename one of them"))
        links[name] = el
    if not links:
        raise AdfError(
            error("urdf-empty", "the robot has no links", doc.where(root), "a URDF robot needs at least one <link>")
        )
    joints = root.findall("joint")
    parent_of: dict[str, tuple[str, ET.Element]] = {}
    for j in joints:
        jn = j.get("name") or "?"
        p, c = j.find("parent"), j.find("child")
        if p is None or c is None or not p.get("link") or not c.get("link"):
            raise AdfError(
                error(
                    "urdf-joint", f"joint {jn!r} lacks <parent link> or <child link>", doc.where(j), "name both links"
                )
            )
        for end in (p, c):
            if end.get("link") not in links:
                raise AdfError(
                    error(
                        "urdf-reference",
                        f"joint {jn!r} names link {end.get('link')!r}, which is not defined",
                        doc.where(end),
                        "define the link or fix the name",
                    )
                )
        child = c.get("link")
        if child in parent_of:
            raise AdfError(
                error(
                    "urdf-tree",
                    f"link {child!r} has two parent joints",
                    doc.where(j),
                    "URDF is a tree: each link has at most one parent joint",
                )
            )
        parent_of[child] = (p.get("link"), j)
    for name in links:  # cycles
        seen, cur = set(), name
        while cur in parent_of:
            if cur in seen:
                raise AdfError(
                    error(
                        "urdf-tree",
                        f"the joints form a cycle through link {cur!r}",
                        doc.where(parent_of[cur][1]),
                        "URDF is a tree; remove one joint of the cycle",
                    )
                )
            seen.add(cur)
            cur = parent_of[cur][0]
    for tag in ("transmission", "gazebo"):
        for el in root.findall(tag):
            losses.append(Loss(el.get("name") or tag, tag, "ADF has no element for it"))

    # world pose of every link frame at joint value 0
    world: dict[str, Pose] = {}

    def link_world(name: str) -> Pose:  # up the chain to a known pose, then down: no recursion
        path = []
        while name not in world and name in parent_of:
            path.append(name)
            name = parent_of[name][0]
        world.setdefault(name, Pose())
        for kid in reversed(path):
            world[kid] = world[parent_of[kid][0]] * _pose_of(doc, parent_of[kid][1])
        return world[path[0]] if path else world[name]

    # an empty root whose joints are all fixed is the world frame: its children are welded to
    # the world (static ADF bodies); an empty root with moving joints stays, as a static body
    fixed_only = {n: all(jel.get("type") == "fixed" for _c, (p, jel) in parent_of.items() if p == n) for n in links}
    ground = {
        n
        for n, el in links.items()
        if n not in parent_of and _is_empty(el) and fixed_only[n] and any(p == n for p, _j in parent_of.values())
    }
    colors = _named_colors(doc, root)
    model = ModelFile()
    bodies: dict[str, Body] = {}
    frame_in_link: dict[str, Pose] = {}
    for name, el in links.items():
        if name in ground:
            continue
        who = f"BODY {name}"
        visuals = el.findall("visual")
        frame = _pose_of(doc, visuals[0]) if visuals else Pose()
        frame_in_link[name] = frame
        body = Body(identifier=who, name=name, location=link_world(name) * frame)
        if visuals:
            geo = visuals[0].find("geometry")
            mesh = geo.find("mesh") if geo is not None else None
            if mesh is not None:
                body.mesh, body.scale = _mesh_file(doc, mesh)
            else:
                losses.append(Loss(who, "visual primitive", "ADF visual shapes are not read from URDF; collision kept"))
            mat = visuals[0].find("material")
            col = mat.find("color") if mat is not None else None
            if col is not None:
                r, g, b, a = _floats(doc, col, "rgba", 4)
                body.color_rgba = RGBA(r=r, g=g, b=b, a=a)
            elif mat is not None and mat.get("name") in colors:
                r, g, b, a = colors[mat.get("name")]
                body.color_rgba = RGBA(r=r, g=g, b=b, a=a)
            if mat is not None and (mat.find("texture") is not None or (col is None and mat.get("name") not in colors)):
                losses.append(Loss(who, "material", "URDF textures (and materials without a colour) are not carried"))
            for _extra in visuals[1:]:
                losses.append(Loss(who, "visual", "ADF has one visual mesh per body; extra visuals dropped"))
        _read_inertial(doc, el, frame, body, losses, quiet=name not in parent_of and _is_empty(el) and name == "world")
        _read_contact(doc, el, body, losses)
        _read_collisions(doc, el, frame, body, losses)
        if parent_of.get(name, ("",))[0] in ground:
            if (body.mass or 0.0) != 0.0:
                losses.append(
                    Loss(who, "mass", "welded to the world: an ADF body fixed to the world is static (mass 0)")
                )
            body.mass = 0.0
        bodies[name] = body
        model.bodies.append(body)
    for j in joints:
        _read_joint(doc, j, links, ground, bodies, frame_in_link, world, model, losses)
    model.present_lists.update({"bodies", "joints"})
    return model, sorted(set(losses))


def _named_colors(doc: XmlDocument, root: ET.Element) -> dict[str, tuple[float, ...]]:
    """The robot-level <material name=...><color rgba/></material> definitions."""
    out = {}
    for mat in root.findall("material"):
        col = mat.find("color")
        if mat.get("name") and col is not None:
            out[mat.get("name")] = _floats(doc, col, "rgba", 4)
    return out


# PyBullet's <contact> extension (inside <link>) -> ADF body keys
_CONTACT_KEPT = ("lateral_friction", "rolling_friction", "restitution", "inertia_scaling")


def _read_contact(doc: XmlDocument, el: ET.Element, body: Body, losses: list[Loss]) -> None:
    contact = el.find("contact")
    if contact is None:
        return
    values = {}
    for kid in contact:
        if kid.tag in _CONTACT_KEPT:
            values[kid.tag] = _floats(doc, kid, "value", 1)[0]
        else:
            losses.append(
                Loss(body.identifier, f"contact {kid.tag}", "PyBullet's <contact> extension: ADF has no such key")
            )
    if "lateral_friction" in values or "rolling_friction" in values:
        body.friction = Friction(static=values.get("lateral_friction"), rolling=values.get("rolling_friction"))
    if "restitution" in values:
        body.restitution = values["restitution"]
    k = values.get("inertia_scaling")
    if k is not None and k != 1.0 and body.inertia is not None:
        i = body.inertia
        body.inertia = Inertia(ix=i.ix * k, iy=i.iy * k, iz=i.iz * k)
        losses.append(
            Loss(
                body.identifier,
                "contact inertia_scaling",
                f"PyBullet's inertia scaling ({k!r}) is folded into the ADF inertia",
            )
        )


def _is_empty(el: ET.Element) -> bool:
    return el.find("inertial") is None and el.find("visual") is None and el.find("collision") is None


def _read_inertial(doc, el, frame: Pose, body: Body, losses, quiet: bool = False) -> None:
    inertial = el.find("inertial")
    if inertial is None:
        body.mass = 0.0
        if not quiet:  # an empty root link named world: static in PyBullet too
            losses.append(
                Loss(
                    body.identifier,
                    "inertial",
                    "no <inertial>: mass 0 as ROS reads it (PyBullet assumes 1 kg), which makes the ADF body static",
                )
            )
        return
    m = inertial.find("mass")
    body.mass = _floats(doc, m, "value", 1)[0] if m is not None else 0.0
    it = inertial.find("inertia")
    tensor = [[0.0] * 3 for _ in range(3)]
    if it is not None:
        vals = {k: _floats(doc, it, k, 1, (0.0,))[0] for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
        tensor = [
            [vals["ixx"], vals["ixy"], vals["ixz"]],
            [vals["ixy"], vals["iyy"], vals["iyz"]],
            [vals["ixz"], vals["iyz"], vals["izz"]],
        ]
    (ix, iy, iz), rot = inertia_math.principal(tensor)
    body.inertia = Inertia(ix=ix, iy=iy, iz=iz)
    problem = inertia_math.physical_problem((ix, iy, iz))
    if problem:
        losses.append(
            Loss(
                body.identifier,
                "inertia",
                f"principal moments {_vec((ix, iy, iz))} {problem}: "
                "kept as written; PyBullet sets such an inertia to zero",
            )
        )
    offset = frame.inverse() * _pose_of(doc, inertial) * Pose(Vec3(), rot)
    body.inertial_offset = offset


def _read_collisions(doc, el, frame: Pose, body: Body, losses) -> None:
    entries: list[ShapeEntry] = []
    meshes = []
    for col in el.findall("collision"):
        geo = col.find("geometry")
        if geo is None:
            raise AdfError(error("urdf-geometry", "<collision> without <geometry>", doc.where(col), "add one"))
        pose = frame.inverse() * _pose_of(doc, col)
        mesh = geo.find("mesh")
        if mesh is not None:
            meshes.append((mesh, pose, col))
            continue
        e = _geometry_entry(doc, geo, pose, body.identifier, losses)
        if e is not None:
            entries.append(e)
    if meshes and entries:
        losses.append(
            Loss(body.identifier, "collision meshes", "ADF takes primitives or a mesh, not both; meshes dropped")
        )
        meshes = []
    if entries:
        body.compound_collision_shape = entries
    elif meshes:
        mesh, pose, col = meshes[0]
        fn, scale = _mesh_file(doc, mesh)
        if fn != body.mesh or scale != body.scale:
            if body.mesh is None:
                body.mesh, body.scale = fn, scale
                losses.append(Loss(body.identifier, "collision mesh", "no visual mesh: the collision mesh is shown"))
            else:
                body.collision_mesh = fn
                if scale != body.scale:
                    losses.append(
                        Loss(body.identifier, "collision mesh scale", "ADF scales visual and collision alike")
                    )
        if pose.position.norm() > 1e-9 or pose.orientation.angle_to(Quat(0, 0, 0, 1)) > 1e-9:
            losses.append(Loss(body.identifier, "collision mesh origin", "ADF collision meshes share the body frame"))
        for _extra in meshes[1:]:
            losses.append(Loss(body.identifier, "collision mesh", "ADF has one collision mesh per body; extra dropped"))


def _read_joint(doc, j, links, ground, bodies, frame_in_link, world, model: ModelFile, losses) -> None:
    jn = j.get("name") or "joint"
    who = f"JOINT {jn}"
    jtype = j.get("type")
    pname, cname = j.find("parent").get("link"), j.find("child").get("link")
    if pname in ground:
        return  # welded to the world: the child is static
    kinds = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic", "fixed": "fixed"}
    if jtype not in kinds:
        if jtype in ("floating", "planar"):
            losses.append(Loss(who, f"{jtype} joint", "ADF has none; the child body floats free"))
            return
        raise AdfError(
            error(
                "urdf-joint-type",
                f"joint {jn!r} has unknown type {jtype!r}",
                doc.where(j),
                "use revolute, continuous, prismatic, fixed, floating or planar",
            )
        )
    parent, child = bodies[pname], bodies[cname]
    u = (
        Vec3(0.0, 0.0, 1.0)
        if jtype == "fixed"
        else Vec3(*_floats(doc, j.find("axis"), "xyz", 3))
        if j.find("axis") is not None
        else Vec3(1.0, 0.0, 0.0)
    )
    if u.norm() < 1e-12:
        raise AdfError(error("urdf-axis", f"joint {jn!r} has a zero axis", doc.where(j), "give a unit axis"))
    u = u.normalized()
    joint_in_parent_body = frame_in_link[pname].inverse() * _pose_of(doc, j)  # J in the parent body frame
    joint_in_child_body = frame_in_link[cname].inverse()  # J (= child link) in the child body
    a = joint_in_parent_body.orientation.rotate(u)
    b = joint_in_child_body.orientation.rotate(u)
    # AMBF's shortest arc is the identity below 1e-3 rad (§8.2): an axis that close to the
    # reference axis, or to the other body's axis, is snapped onto it
    d = Vec3(1.0, 0.0, 0.0) if kinds[jtype] == "prismatic" else Vec3(0.0, 0.0, 1.0)
    tilt = sum(
        t for t in (d.cross(a.normalized()).norm(), a.normalized().cross(b.normalized()).norm()) if 1e-12 < t < 1e-3
    )
    if tilt:
        losses.append(
            Loss(
                who,
                "axis tilt",
                f"an axis differs by {tilt:.3g} rad from one AMBF snaps it to "
                "(shortest arcs below 1e-3 rad are the identity): ADF rounds it away",
            )
        )
    rel = parent.location.inverse() * child.location
    twist = rel.orientation * shortest_arc(b, a).inverse()
    offset = _twist(a.normalized(), twist)
    joint = Joint(
        identifier=who,
        name=jn,
        parent=parent.identifier,
        child=child.identifier,
        type=kinds[jtype],
        parent_pivot=joint_in_parent_body.position,
        parent_axis=a,
        child_pivot=joint_in_child_body.position,
        child_axis=b,
    )
    if abs(offset) > 1e-12:
        joint.offset = offset
    lim = j.find("limit")
    if jtype in ("revolute", "prismatic") and lim is not None:
        low = _floats(doc, lim, "lower", 1, (0.0,))[0]
        high = _floats(doc, lim, "upper", 1, (0.0,))[0]
        joint.joint_limits = JointLimits(low=low, high=high)
    if lim is not None and any(_floats(doc, lim, k, 1, (0.0,))[0] != 0.0 for k in ("effort", "velocity")):
        losses.append(Loss(who, "effort/velocity limit", "ADF has no joint effort or velocity limit"))
    dyn = j.find("dynamics")
    if dyn is not None:
        d = _floats(doc, dyn, "damping", 1, (0.0,))[0]
        if d != 0.0:
            joint.damping = d
        if _floats(doc, dyn, "friction", 1, (0.0,))[0] != 0.0:
            losses.append(Loss(who, "friction", "ADF joints have no Coulomb friction"))
    for tag in ("mimic", "safety_controller", "calibration"):
        if j.find(tag) is not None:
            losses.append(Loss(who, tag, "ADF has no element for it"))
    model.joints.append(joint)
