"""Scene model → MJCF (format-mapping.md).

Each ADF body becomes an MJCF body whose frame is its link frame (``tree.py``: the joint
frame B; the body frame for a root). Bodies sit where the ADF `location`s put them: a hinge
or slide is written with ``ref`` = the initial joint value and the child placed at that
value, so MuJoCo's qpos0 reproduces the file and ``qpos`` is the ADF joint value. A static
root (mass 0) is welded to the world; a dynamic root gets a free joint. Joints outside the
tree become ``equality/connect`` at the child pivot (their axis is lost, and reported).
Inertials are written explicitly (``inertiafromgeom="false"``); visual meshes are geoms in
group 1 that do not collide; collision primitives and meshes are geoms in group 3.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..adf.paths import collision_mesh_path, visual_mesh_path
from ..adf.writer import atomic_write_text
from ..diagnostics import AdfError, error
from ..model.files import ModelFile
from ..model.pose import Pose, Quat, Vec3
from ..model.semantics import (
    JointKind,
    ShapeKind,
    body_joint_frames,
    collision_mesh_pose,
    collision_primitives,
    cone_vertices,
    effective_mass,
    inertial_offset,
    plane_pose,
)
from ..model.tree import Link, build_tree, joint_ends, motion
from . import inertia as inertia_math
from .engine_fit import MeshFiles, concave_parts, flat_box, joint_range, split_objects, usable_scales
from .losses import Loss
from .mjcf_cameras import write_cameras_lights
from .mjcf_soft import write_soft_bodies
from .mjcf_volumes import write_mjcf_volumes
from .safexml import to_text
from .urdf import (
    _AXIS_TO_Z,
    _BODY_ONLY,
    INITIAL_VALUE_TOLERANCE,
    _joint_name,
    _link_name,
    _material,
    _num,
    _unique,
    _vec,
)

# MuJoCo's XML parser (tinyxml2) refuses elements nested deeper than ~500: <mujoco>,
# <worldbody>, the bodies, and a body's own geoms and joints.
MAX_BODY_DEPTH = 496

# Moving bodies need mass and inertia above MuJoCo's mjMINVAL; massless ADF links get this.
MIN_MASS = 1e-6
MIN_INERTIA = 1e-9
#: m along a hinge's axis to the second point of the two connects that close it to a static body
HINGE_LEVER = 0.1
#: joints closing a loop that MJCF can write: an equality (a weld, or a connect at the pivot)
LOOP_KINDS = (JointKind.REVOLUTE, JointKind.PRISMATIC, JointKind.FIXED, JointKind.P2P, JointKind.TORSION_SPRING)

_LOSSY_OBJECTS = (
    ("ghost_objects", "ghost object"),
    ("sensors", "sensor"),
    ("actuators", "actuator"),
    ("vehicles", "vehicle"),
)


def _place(el: ET.Element, pose: Pose) -> None:
    if pose.position.norm() > 1e-15:
        el.set("pos", _vec(pose.position))
    q = pose.orientation
    if abs(q.w - 1.0) > 1e-15 or abs(q.x) + abs(q.y) + abs(q.z) > 1e-15:
        el.set("quat", _vec((q.w, q.x, q.y, q.z)))


class _Assets:
    def __init__(self, root: ET.Element, out_dir: Path, stem: str, tree=None):
        self.el = ET.SubElement(root, "asset")
        self.out_dir = out_dir
        self.names: dict[tuple[str, float], str] = {}
        self.used: set[str] = set()
        self.files = MeshFiles("mjcf", out_dir, stem, tree)

    def fit(self, path: Path, who: str, losses: list[Loss]):
        """(a file MuJoCo reads or None, the mesh when it is flat): engine_fit.MeshFiles."""
        return self.files.fit(path, who, losses, check_flat=True)

    def cone(self, radius: float, height: float) -> str:
        """A mesh asset of the cone's vertices (model.semantics.cone_vertices), which MuJoCo hulls."""
        key = (f"cone:{radius!r}:{height!r}", 1.0)
        if key not in self.names:
            name = _unique("cone", self.used)
            pts = cone_vertices(radius, height)
            ET.SubElement(self.el, "mesh", name=name, vertex=" ".join(_num(c) for p in pts for c in p))
            self.names[key] = name
        return self.names[key]

    def mesh(self, path: Path, scale: float, flat: bool = False) -> str:
        key = (str(path.resolve()), scale)
        if key not in self.names:
            name = _unique(path.stem.replace(" ", "_"), self.used)
            m = ET.SubElement(
                self.el,
                "mesh",
                name=name,
                file=Path(os.path.relpath(path.resolve(), self.out_dir.resolve())).as_posix(),
            )
            if scale != 1.0:
                m.set("scale", _vec((scale,) * 3))
            if flat:  # zero volume: MuJoCo computes its (unused) inertia as a shell
                m.set("inertia", "shell")
            self.names[key] = name
        return self.names[key]


def _geom_primitive(body_el: ET.Element, kind: ShapeKind, g, pose: Pose, name: str, assets=None) -> bool:
    """Write one primitive as a geom in group 3; False for a shape MJCF cannot hold here (a
    cone without ``assets`` to hold its hull, a plane: see _write_geoms)."""
    if kind is ShapeKind.BOX:
        el = ET.SubElement(
            body_el, "geom", name=name, type="box", size=_vec(((g.x or 0) / 2, (g.y or 0) / 2, (g.z or 0) / 2))
        )
        _place(el, pose)
    elif kind is ShapeKind.SPHERE:
        el = ET.SubElement(body_el, "geom", name=name, type="sphere", size=_num(g.radius or 0.0))
        _place(el, pose)
    elif kind in (ShapeKind.CYLINDER, ShapeKind.CAPSULE):
        turn = Pose(Vec3(), _AXIS_TO_Z.get((g.axis or "z").lower(), _AXIS_TO_Z["z"]))
        r, h = g.radius or 0.0, g.height or 0.0
        half = h / 2 if kind is ShapeKind.CYLINDER else max(h / 2 - r, 0.0)
        el = ET.SubElement(body_el, "geom", name=name, type=kind.value, size=_vec((r, half)))
        _place(el, pose * turn)
    elif kind is ShapeKind.CONE and assets is not None:  # MuJoCo has no cone: its hull
        turn = Pose(Vec3(), _AXIS_TO_Z.get((g.axis or "z").lower(), _AXIS_TO_Z["z"]))
        el = ET.SubElement(body_el, "geom", name=name, type="mesh", mesh=assets.cone(g.radius or 0.0, g.height or 0.0))
        _place(el, pose * turn)
    elif kind is ShapeKind.PLANE:  # infinite; drawn as an infinite grid (size 0 0)
        el = ET.SubElement(body_el, "geom", name=name, type="plane", size="0 0 1")
        _place(el, pose * plane_pose(g))
    else:
        return False
    el.set("group", "3")
    return True


def _write_body(
    parent_el: ET.Element,
    model: ModelFile,
    link: Link,
    names: dict,
    assets: _Assets,
    losses: list[Loss],
    used: dict[str, set[str]],
) -> ET.Element:
    body = link.body
    who = body.identifier
    el = ET.SubElement(parent_el, "body", name=names[id(link)])
    q0 = link.q0 if abs(link.q0) > INITIAL_VALUE_TOLERANCE else 0.0
    _place(el, link.origin if link.parent is None else link.origin * motion(link.kind, q0))
    mass = effective_mass(body)
    if link.parent is None and mass > 0.0 and _has_plane(body):
        losses.append(
            Loss(who, "mass", "a body with a PLANE collision shape is static (MuJoCo collides a plane only then)")
        )
        mass = 0.0
    moving = not (link.parent is None and mass == 0.0)
    if link.parent is None and mass > 0.0:
        ET.SubElement(el, "freejoint", name=_unique(f"{names[id(link)]}_free", used["joint"]))
    elif link.parent is not None and link.kind in (JointKind.REVOLUTE, JointKind.PRISMATIC):
        j = link.joint
        jel = ET.SubElement(
            el,
            "joint",
            name=_unique(_joint_name(j), used["joint"]),
            type="hinge" if link.kind is JointKind.REVOLUTE else "slide",
            axis=_vec(link.axis),
        )
        if q0:
            jel.set("ref", _num(q0))
        lim = joint_range(j, losses)
        if lim is not None:
            jel.set("limited", "true")
            jel.set("range", _vec(lim))
        if isinstance(j.damping, float):
            jel.set("damping", _num(j.damping))
        for attr, key in (("controller", "controller"), ("max_motor_impulse", "max motor impulse")):
            if getattr(j, attr, None) is not None:
                losses.append(Loss(j.identifier, key, "no MJCF actuator is written for it"))
    if moving:
        ix, iy, iz = inertia_math.adf_principal(body)
        if body.inertia is None and mass > 0:
            est = inertia_math.estimate_from_collision(model, body, mass)
            if est is not None:
                ix, iy, iz = est
                losses.append(
                    Loss(
                        who,
                        "inertia",
                        "not in the ADF file: written as Bullet's estimate "
                        "(box inertia of the collision shape's bounding box)",
                    )
                )
        if mass < MIN_MASS or min(ix, iy, iz) < MIN_INERTIA:
            losses.append(
                Loss(
                    who,
                    "mass",
                    f"a moving MuJoCo body needs mass and inertia: written as at least "
                    f"{MIN_MASS:g} kg and {MIN_INERTIA:g} kg·m²",
                )
            )
            mass, ix, iy, iz = max(mass, MIN_MASS), max(ix, MIN_INERTIA), max(iy, MIN_INERTIA), max(iz, MIN_INERTIA)
        if inertia_math.physical_problem((ix, iy, iz)) == "break the triangle inequality":
            ix, iy, iz = _triangle(ix, iy, iz)
            losses.append(
                Loss(
                    who,
                    "inertia",
                    "breaks the triangle inequality (Bullet, so AMBF, plays it; MuJoCo refuses it): "
                    f"written with its largest moment lowered to the sum of the other two, {_vec((ix, iy, iz))}",
                )
            )
        com = link.in_link(inertial_offset(body))
        inertial = ET.SubElement(el, "inertial", pos=_vec(com.position))
        _place(inertial, Pose(Vec3(), com.orientation))
        inertial.set("mass", _num(mass))
        inertial.set("diaginertia", _vec((ix, iy, iz)))
    _write_geoms(el, model, link, names[id(link)], assets, losses, used, _static(link))
    for attr, key in _BODY_ONLY.items():
        if attr in ("friction", "damping"):
            continue
        if getattr(body, attr, None) not in (None, [], False):
            losses.append(Loss(who, key, "MJCF has no element for it"))
    if body.friction is not None:
        losses.append(Loss(who, "friction", "not written (MuJoCo's friction is per geom, sliding/torsional/rolling)"))
    if body.damping is not None:
        losses.append(Loss(who, "damping", "MuJoCo has no body velocity damping"))
    return el


def _triangle(ix: float, iy: float, iz: float) -> tuple[float, float, float]:
    """Principal moments with the one larger than the sum of the other two lowered to that sum."""
    m = [ix, iy, iz]
    k = int(np.argmax(m))
    m[k] = m[(k + 1) % 3] + m[(k + 2) % 3]
    return m[0], m[1], m[2]


def _is_world(link: Link) -> bool:
    b = link.body
    return (
        link.parent is None
        and b.name == "world"
        and effective_mass(b) == 0.0
        and link.origin.position.norm() < 1e-12
        and link.origin.orientation.angle_to(Quat(0, 0, 0, 1)) < 1e-12
    )


def _has_plane(body) -> bool:
    return any(p.kind is ShapeKind.PLANE for p in collision_primitives(body) or [])


def _static(link: Link) -> bool:
    """The link is welded to the world: a static root and fixed joints all the way down to it
    (a root with a PLANE is written static, _write_body)."""
    while link.parent is not None:
        if link.kind is not JointKind.FIXED:
            return False
        link = link.parent
    return effective_mass(link.body) == 0.0 or _has_plane(link.body)


def _write_geoms(
    el: ET.Element, model: ModelFile, link: Link, name: str, assets: _Assets, losses, used, static: bool = True
) -> None:
    body = link.body
    who = body.identifier
    scale = body.scale if body.scale is not None else 1.0
    to_link = link.frame_in_body.inverse()
    mesh = visual_mesh_path(model, body)
    flat = None
    if mesh is not None:
        mesh, flat = assets.fit(mesh, who, losses)
    if mesh is not None:
        g = ET.SubElement(
            el,
            "geom",
            name=_unique(f"{name}_visual", used["geom"]),
            type="mesh",
            mesh=assets.mesh(mesh, scale, flat is not None),
            contype="0",
            conaffinity="0",
            group="1",
        )
        _place(g, to_link)
        rgba = _material(body)
        if rgba is not None:
            g.set("rgba", _vec(rgba))
    prims = collision_primitives(body)
    if prims is None:
        to_mesh = to_link * collision_mesh_pose(body)
        cmesh = collision_mesh_path(model, body)
        flat = None
        if cmesh is not None:
            cmesh, flat = assets.fit(cmesh, who, losses)
        if cmesh is not None and flat is not None:  # MuJoCo cannot hull a flat mesh: a thin box
            centre, rot, sizes = flat_box(flat, scale)
            g = ET.SubElement(
                el, "geom", name=_unique(f"{name}_collision", used["geom"]), type="box", size=_vec(sizes / 2), group="3"
            )
            _place(g, to_mesh * Pose(Vec3(*centre), Quat.from_matrix(rot.tolist())))
            losses.append(
                Loss(
                    who,
                    "collision mesh",
                    f"{cmesh.name} is flat (no volume): MuJoCo cannot take its "
                    "convex hull, so it collides as a thin box around it",
                )
            )
        elif cmesh is not None:
            # an OBJ of several objects (a convex decomposition) collides as one hull per object,
            # as in PyBullet, not as the hull of them all (a curved needle's would fill its arc);
            # a moving concave mesh whose hull is a poor stand-in, as its convex parts (geometry.concave)
            stand_in = concave_parts(model, body, cmesh, assets.files.folder, losses)
            parts = stand_in or split_objects(cmesh, assets.files.folder)
            for n, part in enumerate(parts):
                g = ET.SubElement(
                    el,
                    "geom",
                    name=_unique(f"{name}_collision" + (f"{n}" if len(parts) > 1 else ""), used["geom"]),
                    type="mesh",
                    mesh=assets.mesh(part, scale),
                    group="3",
                )
                _place(g, to_mesh)
            if not stand_in:
                losses.append(
                    Loss(
                        who,
                        "collision mesh",
                        "MuJoCo collides with the convex hull of a mesh"
                        + (f" (here of each of its {len(parts)} objects)" if len(parts) > 1 else ""),
                    )
                )
    else:
        if not prims:  # a `collision shape` spelled as AMBF spells none (`Ball`): nothing to collide with
            losses.append(Loss(who, "collision shape", "no usable collision primitive: the body collides with nothing"))
        for n, p in enumerate(prims):
            pose = p.pose
            if p.kind is ShapeKind.PLANE:
                if not static:
                    losses.append(
                        Loss(who, "collision plane", "MuJoCo collides a plane only on a static body: left out")
                    )
                    continue
                if body.collision_shape:  # a lone PLANE is the Bullet body's own shape: no offset (§7.4)
                    pose = inertial_offset(body)
            if not _geom_primitive(
                el, p.kind, p.geometry, to_link * pose, _unique(f"{name}_collision{n}", used["geom"]), assets
            ):
                losses.append(Loss(who, f"collision {p.kind.value}", "MJCF has no such primitive"))
    for n, e in enumerate(body.compound_shape or []):
        from ..model.semantics import pose_or_identity, shape_kind

        k = shape_kind(e.shape)
        g = ET.Element("g")
        if (
            k is None
            or e.geometry is None
            or (k is ShapeKind.PLANE and not static)
            or not _geom_primitive(
                g,
                k,
                e.geometry,
                to_link * pose_or_identity(e.offset),
                _unique(f"{name}_visual{n}", used["geom"]),
                assets,
            )
        ):
            losses.append(Loss(who, f"visual {e.shape}", "MJCF has no such primitive"))
            continue
        geom = g[0]
        geom.set("contype", "0"), geom.set("conaffinity", "0"), geom.set("group", "1")
        el.append(geom)


def to_mjcf(
    model: ModelFile,
    out_dir: Path,
    name: str | None = None,
    *,
    tree_kinds=None,
    names_out: dict | None = None,
    volumes: bool = True,
    leave_out: frozenset[str] = frozenset(),
    lights: bool = True,
    flexes_out: dict | None = None,
    breadth_first: bool = False,
) -> tuple[str, list[Loss]]:
    """MJCF text and losses. ``tree_kinds``: joint kinds that join the tree (default revolute,
    prismatic, fixed); a link joined by another kind is written welded to its parent, for the
    caller to add its joints (the MuJoCo runner's six-dof springs). ``names_out`` receives
    {body identifier: (MJCF body name, tree Link)}; the key "" holds the KinematicTree.
    ``volumes``: write each volume as its iso-surface mesh (volume_mesh.py); False leaves them
    out, for a caller that places them itself (the MuJoCo runner). ``leave_out``: identifiers of
    bodies not written, with the joints that name them (bodies AMBF does not create: the MuJoCo
    runner's ``plan.uncreated_bodies``). ``lights``: False leaves the lights to the caller (the
    MuJoCo runner places them under parents in other files and under cameras). ``flexes_out``
    receives {soft body identifier: the name of its flexcomp}."""
    losses: list[Loss] = []
    if leave_out:
        kept = [j for j in model.joints if not joint_ends(model, j) & leave_out]
        model = replace(model, bodies=[b for b in model.bodies if b.identifier not in leave_out], joints=kept)
    model = usable_scales(model, losses)
    # a loop is closed at a point (connect) or welded: a slide closing one would be locked
    kinds = tree_kinds if tree_kinds is not None else (JointKind.REVOLUTE, JointKind.PRISMATIC, JointKind.FIXED)
    tree = build_tree(model, kinds, True, breadth_first, static_roots=True, reversible=True)
    has_volume = volumes and any(v.defined for v in model.volumes)
    if not tree.roots and not any(sb.defined for sb in model.soft_bodies) and not has_volume:
        raise AdfError(
            error(
                "convert-empty",
                "the model has no bodies or soft bodies; there is nothing to write as MJCF",
                model.where(),
                "convert a model file with at least one body",
            )
        )
    root = ET.Element("mujoco", model=name or model.name)
    ET.SubElement(root, "compiler", angle="radian", inertiafromgeom="false", autolimits="true")
    assets = _Assets(root, out_dir, name or model.name, getattr(model, "tree", None))
    world = ET.SubElement(root, "worldbody")
    # MuJoCo keeps one namespace per element type; "world" is the world body's name
    used: dict[str, set[str]] = {"body": {"world"}, "joint": set(), "geom": set(), "equality": set()}
    names: dict[int, str] = {}
    elements: dict[int, ET.Element] = {}
    depth: dict[int, int] = {}
    for lk in tree.ordered():
        names[id(lk)] = _unique(_link_name(lk.body), used["body"])
        depth[id(lk)] = 1 if lk.parent is None else depth[id(lk.parent)] + 1
        if depth[id(lk)] == MAX_BODY_DEPTH + 1:
            losses.append(
                Loss(
                    lk.body.identifier,
                    "body nesting",
                    f"MJCF nests each child body in its parent and "
                    f"MuJoCo's XML parser refuses more than {MAX_BODY_DEPTH} levels: the file will not "
                    "load in MuJoCo",
                )
            )
    for lk in tree.ordered():
        parent_el = world if lk.parent is None else elements[id(lk.parent)]
        if _is_world(lk):  # ADF's stand-in for the world: its geoms and children go in <worldbody>
            elements[id(lk)] = world
            _write_geoms(world, model, lk, names[id(lk)], assets, losses, used)
            continue
        elements[id(lk)] = _write_body(parent_el, model, lk, names, assets, losses, used)
        if lk.parent is not None and lk.kind is JointKind.FIXED and lk.joint.damping is not None:
            losses.append(Loss(lk.joint.identifier, "damping", "a fixed joint has nothing to damp"))
    by_body = {lk.body.identifier: lk for lk in tree.ordered()}
    if names_out is not None:
        names_out[""] = tree
        for lk in tree.ordered():
            names_out[lk.body.identifier] = ("world" if elements[id(lk)] is world else names[id(lk)], lk)
    eq = None
    for j, kind, parent, child in tree.loops:
        if kind in LOOP_KINDS:
            eq = eq if eq is not None else ET.Element("equality")
            a, _b = body_joint_frames(j, parent, child)
            pl = by_body[parent.identifier]
            anchor = pl.in_link(a).position
            tag = "weld" if kind is JointKind.FIXED else "connect"
            e = ET.SubElement(
                eq,
                tag,
                name=_unique(_joint_name(j), used["equality"]),
                body1=names[id(pl)],
                body2=names[id(by_body[child.identifier])],
            )
            if tag == "connect":
                e.set("anchor", _vec(anchor))
            if kind is JointKind.REVOLUTE and (effective_mass(parent) == 0.0 or effective_mass(child) == 0.0):
                # a hinge to a static body (one the tree keeps a root: static_roots): a second point
                # on its axis makes the two connects a hinge
                axis_point = pl.in_link(a).transform(Vec3(0.0, 0.0, HINGE_LEVER))
                e2 = ET.SubElement(
                    eq,
                    "connect",
                    name=_unique(_joint_name(j) + "_axis", used["equality"]),
                    body1=names[id(pl)],
                    body2=names[id(by_body[child.identifier])],
                )
                e2.set("anchor", _vec(axis_point))
                continue
            if kind in (JointKind.REVOLUTE, JointKind.PRISMATIC, JointKind.TORSION_SPRING):
                spring = "; its limits and spring are not written" if kind is JointKind.TORSION_SPRING else ""
                losses.append(
                    Loss(
                        j.identifier,
                        "joint axis",
                        f"a {kind.value} joint closing a loop is written as "
                        f"equality/connect: a ball joint at the pivot{spring}",
                    )
                )
        else:
            losses.append(Loss(j.identifier, "joint", f"no MJCF form for a {kind.value} joint here"))
    if eq is not None:
        root.append(eq)
    write_cameras_lights(model, tree, elements, world, used, losses, lights)
    write_soft_bodies(model, world, used, losses, flexes_out)
    if volumes:
        write_mjcf_volumes(model, world, assets, name or model.name, used, losses)
    for j in tree.unresolved:
        losses.append(Loss(j.identifier, "joint", "unknown type or parent/child body not in this file"))
    for attr, label in _LOSSY_OBJECTS:
        for obj in getattr(model, attr):
            losses.append(Loss(obj.identifier, label, "not written to MJCF"))
    if not len(assets.el):
        root.remove(assets.el)
    return to_text(root) + "\n", sorted(set(losses))


def write(model: ModelFile, path: Path) -> list[Loss]:
    path = Path(path)
    text, losses = to_mjcf(model, path.parent, path.stem)
    atomic_write_text(path, text)
    return losses


__all__ = ["to_mjcf", "write", "LOOP_KINDS", "MIN_MASS", "MIN_INERTIA"]
