"""The kinematic tree of an ADF model: what URDF and MJCF need, and what the validator checks.

ADF places every body in the world (`location`) and joins bodies by joints whose frames
A (in the parent body) and B (in the child body) coincide at joint value zero
(adf-format.md §8.2, ``semantics.joint_frames``). Tree formats place each child *relative to
its parent through the joint*. This module chooses a spanning tree, gives every body a
**link frame** (its joint frame B; the body frame for a root), the joint origin in the
parent's link frame, the initial joint value that reproduces the file's `location`s, and
forward kinematics. The converters and the validator build on it; nothing here knows a file
format.
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass, field

from .files import ModelFile
from .objects import Body, Joint
from .pose import Pose, Quat, Vec3
from .semantics import JointKind, ReversedJoint, body_joint_frames, effective_mass, joint_kind, reference_axis

ONE_DOF = (JointKind.REVOLUTE, JointKind.PRISMATIC)
#: the joints whose `joint limits` bound one axis: the one-DOF joints and the torsion and linear
#: springs (a limited spring is a hinge or a slider with its limits, runner.md)
LIMITED_KINDS = ONE_DOF + (JointKind.TORSION_SPRING, JointKind.LINEAR_SPRING)


@dataclass(eq=False)
class Link:
    """One body in the tree. ``frame_in_body``: the link frame in the ADF body frame (joint
    frame B; identity for a root). ``origin``: the joint frame at value 0 in the parent's link
    frame (for a root: the link's world pose). ``axis``: the joint axis in the link frame."""

    body: Body
    parent: Link | None = None
    joint: Joint | None = None
    kind: JointKind | None = None
    frame_in_body: Pose = field(default_factory=Pose)
    origin: Pose = field(default_factory=Pose)
    q0: float = 0.0
    children: list[Link] = field(default_factory=list)

    @property
    def name(self) -> str:
        return self.body.name or self.body.identifier

    @property
    def axis(self) -> Vec3:
        return reference_axis(self.kind) if self.kind is not None else Vec3(0.0, 0.0, 1.0)

    def in_link(self, pose_in_body: Pose) -> Pose:
        """A pose given in the ADF body frame, expressed in the link frame."""
        return self.frame_in_body.inverse() * pose_in_body


@dataclass
class KinematicTree:
    roots: list[Link]
    links: dict[str, Link]  # body identifier -> link
    loops: list[tuple[Joint, JointKind, Body, Body]]  # joints left out of the tree
    unresolved: list[Joint]  # joints whose parent or child is not a body here

    def ordered(self) -> list[Link]:
        """Every link, parents before children (depth first from each root)."""
        out: list[Link] = []
        stack = list(reversed(self.roots))
        while stack:
            link = stack.pop()
            out.append(link)
            stack.extend(reversed(link.children))
        return out

    def fk(self, q: dict[str, float] | None = None) -> dict[str, Pose]:
        """World pose of every body frame for joint values ``q`` (joint identifier -> value;
        missing joints take their initial value ``q0``). Joints other than revolute and
        prismatic are rigid at their zero."""
        q = q or {}
        world: dict[str, Pose] = {}
        link_world: dict[int, Pose] = {}
        for link in self.ordered():
            if link.parent is None or link.joint is None:
                lw = link.origin
            else:
                value = q.get(link.joint.identifier, link.q0)
                lw = link_world[id(link.parent)] * link.origin * motion(link.kind, value)
            link_world[id(link)] = lw
            world[link.body.identifier] = lw * link.frame_in_body.inverse()
        return world


def motion(kind: JointKind | None, value: float) -> Pose:
    """The child link frame in the joint frame at ``value`` (rad or m)."""
    if kind is JointKind.REVOLUTE:
        return Pose(Vec3(), Quat.from_axis_angle(Vec3(0.0, 0.0, 1.0), value))
    if kind is JointKind.PRISMATIC:
        return Pose(Vec3(value, 0.0, 0.0))
    return Pose()


def _merge_namespace(parent: str | None, child: str | None) -> str:
    """§12.1: a child namespace starting with '/' replaces the parent; else the two are joined."""
    parent, child = parent or "", child or ""
    out = child if child.startswith("/") else parent + child
    while "//" in out:
        out = out.replace("//", "/")
    return out


def find_body(model: ModelFile, ref: str | None, joint=None) -> Body | None:
    """A `parent`/`child` (of ``joint``, whose namespace then counts) as AMBF resolves it in one
    file (§12.1, §12.2): among the bodies' keys (namespace + identifier, not their `name`s), the
    key equal to the text, else the one key containing it; then the same with the joint's
    namespace before the text. An ambiguous text (`Entry1` beside `Entry10`) finds nothing."""
    if not ref:
        return None
    ns = model.namespace or ""
    keys = [(_merge_namespace(ns, b.namespace) + b.identifier, b) for b in model.bodies]
    texts = [ref]
    if joint is not None:
        texts.append(_merge_namespace(ns, getattr(joint, "namespace", None)) + ref)
    for text in texts:
        exact = [b for k, b in keys if k == text]
        if exact:
            return exact[0]
        hits = [b for k, b in keys if text in k]
        if len(hits) == 1:
            return hits[0]
    return None


def joint_ends(model: ModelFile, joint) -> set[str | None]:
    """The identifiers of the bodies a joint's `parent` and `child` name (None for one not found)."""
    return {getattr(find_body(model, ref, joint), "identifier", None) for ref in (joint.parent, joint.child)}


def build_tree(
    model: ModelFile,
    tree_kinds=(JointKind.REVOLUTE, JointKind.PRISMATIC, JointKind.FIXED),
    slides_first: bool = False,
    breadth_first: bool = False,
    static_roots: bool = False,
    reversible: bool = False,
) -> KinematicTree:
    """Spanning tree over the joints whose kind is in ``tree_kinds``.

    Roots, in file order: bodies that are no joint's child (static ones, mass 0, first), then
    the rest;
    a body reached twice closes a loop (that joint goes to ``loops``); bodies no joint reaches
    are roots of their own. ``slides_first``: a prismatic joint into a body keeps its place in
    the tree before a revolute one into it (left_for_last), for a format that closes a loop only
    at a point (MJCF's connect, which would lock a slide). ``breadth_first``: bodies reached
    nearest the root first (the PyBullet runner's multibodies: a loop is closed at the same joint
    in both engines), else depth first. ``static_roots``: a static body is a root even where a
    joint names it as its child (a format whose tree moves every body under its root: MJCF, where
    the body would be carried by its dynamic parent; the joint then closes a loop to it, as the
    PyBullet runner's constraint does). ``reversible``: a joint whose child the tree reaches
    first takes its dynamic parent, one no tree joint has as its child, into the tree through the
    joint reversed (ReversedJoint), as the PyBullet runner's multibodies do, where it would
    otherwise close a loop to a root of its own."""
    records, unresolved = [], []
    for j in model.joints:
        kind = joint_kind(j.type)
        parent, child = find_body(model, j.parent, j), find_body(model, j.child, j)
        if kind is None or parent is None or child is None or parent is child:
            unresolved.append(j)
            continue
        records.append((j, kind, parent, child))
    edges = defaultdict(list)
    back = defaultdict(list)  # the tree joints into each body, taken from the child's side (reversible)
    is_child = set()
    for r in records:
        if r[1] in tree_kinds:
            edges[id(r[2])].append(r)
            is_child.add(id(r[3]))
    for r in records:  # a dynamic parent no tree joint reaches (else it closes a loop, as before)
        if reversible and r[1] in tree_kinds and effective_mass(r[2]) != 0.0 and id(r[2]) not in is_child:
            back[id(r[3])].append(r)
    into = defaultdict(list)
    for r in records:
        if r[1] in tree_kinds:
            into[id(r[3])].append(r)
    if static_roots:
        order = sorted(model.bodies, key=lambda b: (effective_mass(b) != 0.0, id(b) in is_child))
    else:
        order = sorted(model.bodies, key=lambda b: (id(b) in is_child, effective_mass(b) != 0.0))
    links: dict[str, Link] = {}
    roots: list[Link] = []
    used: set[int] = set()

    def attach(link: Link, r, file_record=None) -> Link:
        j, kind, parent, child = r
        used.add(id(file_record if file_record is not None else r))
        a, b = body_joint_frames(j, parent, child)
        node = Link(child, parent=link, joint=j, kind=kind, frame_in_body=b, origin=link.in_link(a))
        node.q0 = _initial_value(link, node)
        link.children.append(node)
        links[child.identifier] = node
        return node

    for start in order:
        if start.identifier in links:
            continue
        root = Link(start, origin=_location(start))
        links[start.identifier] = root
        roots.append(root)
        stack: list[Link] = [root]
        later: list[tuple[Link, tuple]] = []
        while stack or later:
            if not stack:  # a joint left for last reaches its child only if nothing else did
                link, r = later.pop(0)
                if r[3].identifier not in links:
                    stack.append(attach(link, r))
                continue
            link = stack.pop(0) if breadth_first else stack.pop()
            for r in edges[id(link.body)]:
                if r[3].identifier in links:
                    continue
                if left_for_last(r, into[id(r[3])], slides_first):
                    later.append((link, r))
                    continue
                stack.append(attach(link, r))
            for r in back[id(link.body)]:
                if id(r) not in used and r[2].identifier not in links:
                    stack.append(attach(link, (ReversedJoint(r[0]), r[1], r[3], r[2]), r))
    loops = [r for r in records if id(r) not in used]
    return KinematicTree(roots, links, loops, unresolved)


def limited(joint) -> bool:
    """Whether AMBF enables the joint's limits (both `low` and `high` given)."""
    lim = joint.joint_limits
    return lim is not None and lim.low is not None and lim.high is not None


def left_for_last(record, into, slides_first: bool = False) -> bool:
    """Whether a spanning tree should reach a body through the joint of ``record`` (joint,
    kind, parent, child) only when no other joint of ``into`` (the tree joints into the same
    child) does: a revolute or prismatic joint without limits, where another into its child has
    them. The joint a tree leaves out closes the loop as a constraint, which plays no limits: a
    limited one left out loses them (the corpus parallel structure's l3-l4 swung past its -1.047
    rad, where AMBF's stops, while l1-l4, a continuous joint, held a place in the tree).
    ``slides_first``: also a revolute joint where a prismatic one (not itself left for last)
    goes into the same child, the revolute closing the loop at its pivot: the corpus gripper3's
    slider between its jaws, closing the loop as a point, locked the slide AMBF's jaws take
    (117 mm in 0.3 s)."""
    if _without_limits_last(record, into):
        return True
    return (
        slides_first
        and record[1] is JointKind.REVOLUTE
        and any(x[1] is JointKind.PRISMATIC and not _without_limits_last(x, into) for x in into if x is not record)
    )


def _without_limits_last(record, into) -> bool:
    joint, kind = record[0], record[1]
    if kind not in ONE_DOF or limited(joint):
        return False
    return any(limited(x[0]) for x in into if x is not record and x[1] in LIMITED_KINDS)


def _location(b: Body) -> Pose:
    return b.location if b.location is not None else Pose()


def _initial_value(parent: Link, link: Link) -> float:
    """The joint value that puts the child where its `location` says, given the parent's."""
    if link.kind not in ONE_DOF:
        return 0.0
    parent_link_world = _location(parent.body) * parent.frame_in_body
    child_link_world = _location(link.body) * link.frame_in_body
    rel = (parent_link_world * link.origin).inverse() * child_link_world
    if link.kind is JointKind.PRISMATIC:
        return rel.position[0]
    m = rel.orientation.matrix()
    return math.atan2(m[1][0], m[0][0])
