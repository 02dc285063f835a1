"""Scene model → URDF (format-mapping.md): the spanning tree of ``tree.py``; each URDF link
frame is the ADF joint frame B of its body (the body frame for the root), so a URDF joint
rotates about its child link's origin as ADF's does about the child pivot. Visual, collision
and inertial data move from the ADF body frame into that link frame. A static root (mass 0)
is welded to a `world` link by a fixed joint that carries its `location`."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

from ..adf.paths import collision_mesh_path, visual_mesh_path
from ..adf.writer import atomic_write_text
from ..diagnostics import AdfError, error
from ..model.common import Geometry
from ..model.files import ModelFile
from ..model.objects import Body, Joint
from ..model.pose import Pose, Quat, Vec3
from ..model.semantics import (
    JointKind,
    ShapeKind,
    collision_primitives,
    effective_mass,
    inertial_offset,
)
from ..model.tree import Link, build_tree
from . import inertia as inertia_math
from .engine_fit import MeshFiles, concave_parts, joint_range, usable_scales
from .losses import Loss
from .safexml import to_text
from .urdf_volumes import write_urdf_volumes
from .urdf_xml import _material, _mesh_element, _mesh_ref, _num, _origin, _unique, _vec  # noqa: F401 - re-exported

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
)


def _link_name(body: Body) -> str:
    return body.name or body.identifier.removeprefix("BODY ").strip()


def _joint_name(joint: Joint) -> str:
    return joint.name or joint.identifier.removeprefix("JOINT ").strip()


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
        stand_in = concave_parts(model, body, cmesh, files.folder, losses) if cmesh is not None else None
        for part in stand_in or ([cmesh] if cmesh is not None else []):
            _mesh_element(el, "collision", to_link, part, scale, out_dir)
        if cmesh is not None and not stand_in and body.collision_mesh_type is not None:
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
    if not roots and any(v.defined for v in model.volumes):
        return _volumes_only(model, robot, out_dir, name, losses)
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
    # every root's link frame is the world frame (a world link, a bare root at the origin, or a
    # floating root moved there by _root_frame_at_world): volumes hang from it at their location
    write_urdf_volumes(model, robot, world if static_root else names[id(main)], out_dir, name, used, losses)
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


def _volumes_only(model: ModelFile, robot: ET.Element, out_dir: Path, name: str, losses: list[Loss]):
    """A model file with volumes and no body: a `world` link holding the volumes' meshes."""
    used = {"world"}
    ET.SubElement(robot, "link", name="world")
    write_urdf_volumes(model, robot, "world", out_dir, name, used, losses)
    for attr, label in _LOSSY_OBJECTS:
        for obj in getattr(model, attr):
            losses.append(Loss(obj.identifier, label, "URDF has no element for it"))
    return '<?xml version="1.0"?>\n' + to_text(robot) + "\n", sorted(set(losses))


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
