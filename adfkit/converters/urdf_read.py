"""URDF → scene model (format-mapping.md): each link becomes a body whose frame is the link
frame times its (first) visual origin, because ADF has no visual offset; joints get pivots and
axes in both body frames and the ADF `offset` that reproduces the URDF origin's twist about
the axis."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

from ..diagnostics import AdfError, error
from ..model.common import RGBA, Friction, Geometry, ShapeEntry
from ..model.files import ModelFile
from ..model.objects import Body, Inertia, Joint, JointLimits
from ..model.pose import Pose, Quat, Vec3
from ..model.semantics import inertial_joint_twist, shortest_arc
from . import inertia as inertia_math
from .losses import Loss, axis_tilt
from .safexml import XmlDocument, parse_xml
from .urdf_write import _vec

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
    # AMBF builds the joint's frames in the bodies' inertial frames: a turned one turns the
    # joint's zero, which the offset takes back
    offset += inertial_joint_twist(joint, parent, child)
    tilt = axis_tilt(joint, parent, child)
    if tilt is not None:
        losses.append(tilt)
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
