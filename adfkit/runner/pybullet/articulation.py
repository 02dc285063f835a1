"""Trees of revolute/prismatic(/fixed) joints as PyBullet multibodies: exact joints with
native limits and position motors; no constraint drift. Loops stay outside (joints.py).

A `torsion spring` or `linear spring` with limits joins the tree as a revolute or prismatic
joint about or along its frame's z axis: AMBF builds it as a btGeneric6DofSpring2Constraint whose
other five axes are locked and whose z axis is limited to the joint's limits (afJoint::
createFromAttribs), a hinge or slider with limits; its spring is a force (spring_forces.py). One
without limits has all six axes locked in AMBF: a fixed joint of the tree."""

from __future__ import annotations

from collections import defaultdict, deque

import numpy as np
import pybullet as pb

from ...model.semantics import DEFAULT_JOINT_MAX_MOTOR_IMPULSE, JointKind, ReversedJoint, body_joint_frames
from ...model.tree import left_for_last
from ..rotations import invert, matrix_to_pq, pose_matrix

TREE_KINDS = (JointKind.REVOLUTE, JointKind.PRISMATIC, JointKind.TORSION_SPRING, JointKind.LINEAR_SPRING)
#: the tree joints that turn about their frame's z axis (the others slide)
ROTARY = (JointKind.REVOLUTE, JointKind.TORSION_SPRING)
#: the axis of each tree joint in its frame: a prismatic joint slides along x (Bullet's slider), a
#: linear spring along z (the spring axis AMBF gives its btGeneric6DofSpring2Constraint)
AXIS = {JointKind.PRISMATIC: 0}


def tree_kind(record) -> JointKind | None:
    """The joint a (joint, kind, parent, child) record is in a multibody, None if it joins none:
    a revolute or prismatic joint as it is, a torsion or linear spring as one when it has both
    limits and as a fixed joint without them (AMBF locks all six axes of such a spring)."""
    joint, kind = record[0], record[1]
    if kind in (JointKind.TORSION_SPRING, JointKind.LINEAR_SPRING):
        lim = joint.joint_limits
        return kind if lim is not None and lim.low is not None and lim.high is not None else JointKind.FIXED
    return kind if kind in TREE_KINDS else None


def components(joints):
    """Group (joint, kind, parent SimBody, child SimBody) records joined by revolute/prismatic
    joints (and torsion and linear springs, tree_kind) into trees. Returns [(root, [records in BFS order])]
    and the leftover records."""
    joints = list(joints)
    tree_ids = {id(r) for r in joints if tree_kind(r) is not None}
    adj = defaultdict(list)
    for r in joints:
        if id(r) in tree_ids:
            adj[id(r[2])].append(r)
            adj[id(r[3])].append(r)
    seen_bodies: set[int] = set()
    used: set[int] = set()
    trees = []
    children = {id(r[3]) for r in joints if id(r) in tree_ids}
    into = defaultdict(list)  # the tree joints into each body
    for r in joints:
        if id(r) in tree_ids:
            into[id(r[3])].append(r)
    for r in joints:
        if id(r) not in tree_ids or id(r[2]) in seen_bodies:
            continue
        # walk up to a root: a body that is no tree joint's child
        root = r[2]
        guard = 0
        while id(root) in children and guard < 1000:
            root = next(x[2] for x in joints if id(x) in tree_ids and x[3] is root)
            guard += 1
        if id(root) in seen_bodies:
            continue
        order, queue, later = [], deque([root]), deque()
        seen_bodies.add(id(root))
        while queue or later:
            if not queue:  # a joint left for last (tree.left_for_last) where nothing else reached its child
                rec = later.popleft()
                if id(rec[3]) not in seen_bodies:
                    used.add(id(rec))
                    seen_bodies.add(id(rec[3]))
                    order.append(rec)
                    queue.append(rec[3])
                continue
            b = queue.popleft()
            for rec in adj[id(b)] + [x for x in joints if x[1] is JointKind.FIXED and x[2] is b]:
                if id(rec) in used:
                    continue
                free_parent = id(rec[2]) not in seen_bodies and id(rec[2]) not in children and not rec[2].static
                if rec[3] is b and free_parent and rec[2] is not b:
                    # the file's child reached first and its parent no tree joint's child: the parent
                    # hangs on it by the joint reversed (a free body jointed into a tree, written
                    # from the free body's side), where it was a root of its own and the joint a loop
                    used.add(id(rec))
                    seen_bodies.add(id(rec[2]))
                    order.append((ReversedJoint(rec[0]), rec[1], b, rec[2]))
                    queue.append(rec[2])
                    continue
                if rec[2] is not b or id(rec[3]) in seen_bodies:
                    continue
                if rec[3].static:
                    continue
                if left_for_last(rec, into[id(rec[3])]):
                    later.append(rec)
                    continue
                used.add(id(rec))
                seen_bodies.add(id(rec[3]))
                order.append(rec)
                queue.append(rec[3])
        if order:
            trees.append((root, order))
    leftover = [r for r in joints if id(r) not in used]
    return trees, leftover


class Articulation:
    """One multibody: its joints, their position targets, their motors: off until something
    drives them (``free``), as AMBF leaves a joint's motor until the joint is commanded."""

    def __init__(self, uid, root, records, cid):
        self.uid, self.root, self.records, self.cid = uid, root, records, cid
        self.joint_names = [r[0].identifier for r in records]
        self.kinds = [r[1] for r in records]
        self.targets = [0.0] * len(records)
        self.forces = []
        self.held = False  # the position motors hold the targets (drive), or every motor is off (free)

    def joint_values(self) -> list[float]:
        return [s[0] for s in pb.getJointStates(self.uid, list(range(len(self.records))), physicsClientId=self.cid)]

    def drive(self) -> None:
        pb.setJointMotorControlArray(
            self.uid,
            list(range(len(self.records))),
            pb.POSITION_CONTROL,
            targetPositions=self.targets,
            forces=self.forces,
            physicsClientId=self.cid,
        )
        self.held = True

    def free(self) -> None:
        """Every joint's motor off: the joints move as their bodies' forces and contacts move them.
        AMBF builds each revolute and prismatic joint with its motor disabled
        (afJoint::createFromAttribs) and turns it on only for a position or velocity command;
        it applies no joint damping (afJoint::applyDamping is not called)."""
        n = len(self.records)
        pb.setJointMotorControlArray(
            self.uid, list(range(n)), pb.VELOCITY_CONTROL, forces=[0.0] * n, physicsClientId=self.cid
        )
        self.held = False


def depth_first(root, records):
    """The records in depth-first pre-order (children in their given order): the link order
    PyBullet's createMultiBody gives links, whatever order the lists are passed in (it builds
    a URDF-like tree and numbers links depth-first). With any other order link n of the
    multibody is not record n."""
    kids = defaultdict(list)
    for r in records:
        kids[id(r[2])].append(r)
    out, stack = [], list(reversed(kids[id(root)]))
    while stack:
        r = stack.pop()
        out.append(r)
        stack.extend(reversed(kids[id(r[3])]))
    return out


def build(root, records, shapes_for, dt: float, cid: int, self_collision: bool) -> Articulation:
    """Create the multibody. ``shapes_for(simbody, frame_in_body) -> (collision, visual)``."""
    records = [(j, tree_kind((j, k)) or k, p, c) for j, k, p, c in depth_first(root, records)]
    idx = {id(root): -1}
    for n, r in enumerate(records):
        idx[id(r[3])] = n
    lm, lc, lv, lp, lo, lip, lio, lpi, lt, la = ([] for _ in range(10))
    for joint, kind, parent, child in records:
        a, b = body_joint_frames(joint, parent.body, child.body)
        fa, fb = pose_matrix(*_pose(a)), pose_matrix(*_pose(b))
        child.ref_in_body = fb  # link frame = joint frame B
        rel = invert(parent.ref_in_body) @ fa  # joint frame in the parent's link frame
        col, vis = shapes_for(child, fb)
        pos, orn = matrix_to_pq(rel)
        ipos, iorn = matrix_to_pq(invert(fb) @ child.com_in_body)
        lm.append(child.mass)
        lc.append(col)
        lv.append(vis)
        lp.append(pos)
        lo.append(orn)
        lip.append(ipos)
        lio.append(iorn)
        lpi.append(idx[id(parent)] + 1)
        lt.append(
            pb.JOINT_FIXED if kind not in TREE_KINDS else pb.JOINT_REVOLUTE if kind in ROTARY else pb.JOINT_PRISMATIC
        )
        la.append([1, 0, 0] if kind is JointKind.PRISMATIC else [0, 0, 1])
    bcol, bvis = shapes_for(root, root.ref_in_body)
    world = root.body_world_matrix
    bpos, born = matrix_to_pq(world @ root.ref_in_body)
    flags = pb.URDF_USE_SELF_COLLISION | pb.URDF_USE_SELF_COLLISION_EXCLUDE_PARENT if self_collision else 0
    if self_collision and any(r[0].ignore_inter_collision is False for r in records):
        # a joint whose bodies AMBF lets collide (`ignore inter-collision: false`): links meet
        # their parents, and every other joint's pair is filtered out (assemble._collision_filters)
        flags = pb.URDF_USE_SELF_COLLISION | pb.URDF_USE_SELF_COLLISION_INCLUDE_PARENT
    uid = pb.createMultiBody(
        root.mass,
        bcol,
        bvis,
        bpos,
        born,
        linkMasses=lm,
        linkCollisionShapeIndices=lc,
        linkVisualShapeIndices=lv,
        linkPositions=lp,
        linkOrientations=lo,
        linkInertialFramePositions=lip,
        linkInertialFrameOrientations=lio,
        linkParentIndices=lpi,
        linkJointTypes=lt,
        linkJointAxis=la,
        flags=flags,
        physicsClientId=cid,
    )
    # PyBullet names joint n "joint{n+1}" after the position in our lists; check the link order
    order = [int(pb.getJointInfo(uid, n, physicsClientId=cid)[1].decode()[5:]) - 1 for n in range(len(records))]
    if order != list(range(len(records))):
        raise RuntimeError(f"PyBullet reordered the links of {root.key}: {order}")
    art = Articulation(uid, root, records, cid)
    root.uid, root.link, root.articulation = uid, -1, art
    for n, r in enumerate(records):
        r[3].uid, r[3].link, r[3].articulation = uid, n, art
    # start where the files place the bodies: the joint value that best matches `location`
    for n, (joint, kind, parent, child) in enumerate(records):
        q = 0.0
        if kind in TREE_KINDS:
            rel = invert(parent.body_world_matrix @ parent.ref_in_body) @ (child.body_world_matrix @ child.ref_in_body)
            rel = invert(pose_matrix(lp[n], lo[n])) @ rel
            q = float(np.arctan2(rel[1, 0], rel[0, 0])) if kind in ROTARY else float(rel[AXIS.get(kind, 2), 3])
            lim = joint.joint_limits
            if lim is not None and lim.low is not None and lim.high is not None and lim.low <= lim.high:
                pb.changeDynamics(uid, n, jointLowerLimit=lim.low, jointUpperLimit=lim.high, physicsClientId=cid)
        pb.resetJointState(uid, n, q, physicsClientId=cid)
        art.targets[n] = q
        impulse = joint.max_motor_impulse if joint.max_motor_impulse is not None else DEFAULT_JOINT_MAX_MOTOR_IMPULSE
        art.forces.append(impulse / dt)
    art.free()
    return art


def _pose(p):
    return p.position, p.orientation
