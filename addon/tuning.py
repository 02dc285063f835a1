"""Joint controller gains, joint visibility and clean-up (what the original AMBF add-on
offered beside export): Blender-level walks over the scene, arithmetic in plain functions."""

from __future__ import annotations

import math

import bpy


def pd_gains(inertia: float, frequency_hz: float = 2.0, damping_ratio: float = 1.0) -> tuple[float, float]:
    """(P, D) that make a load of ``inertia`` (kg·m², or kg for a prismatic joint) a second-
    order system of natural frequency ``frequency_hz`` and damping ratio ``damping_ratio``:
    P = I·ω², D = 2·ζ·I·ω."""
    w = 2.0 * math.pi * frequency_hz
    return inertia * w * w, 2.0 * damping_ratio * inertia * w


def _joint_bodies(scene):
    """{parent body: [(joint object, child body)]} from the ADF joints' constraints."""
    out: dict = {}
    for o in scene.objects:
        rbc = o.rigid_body_constraint if o.adf.kind == "JOINT" else None
        if rbc is not None and rbc.object1 is not None and rbc.object2 is not None:
            out.setdefault(rbc.object1, []).append((o, rbc.object2))
    return out


def subtree(scene, child) -> list:
    """The child body and every body jointed below it (no body twice)."""
    tree, seen, stack = _joint_bodies(scene), [], [child]
    while stack:
        b = stack.pop()
        if b in seen:
            continue
        seen.append(b)
        stack.extend(c for _, c in tree.get(b, []))
    return seen


def _own_inertia(b, m: float) -> float:
    """A body's largest principal moment: as given, else that of its bounding box (an upper
    bound; a body just marked has no inertia yet)."""
    if b.adf.body.use_inertia:
        return max(b.adf.body.inertia)
    return m * sum(d * d for d in b.dimensions) / 12.0


def load_about(scene, joint, axis_local=(0.0, 0.0, 1.0), linear: bool = False) -> float:
    """What the joint moves: along an axis (``linear``) the subtree's mass (kg); about the
    joint frame's axis ``axis_local`` its inertia (kg·m²): each body's mass times its squared
    distance from the axis plus its largest principal moment (an upper bound of its own term)."""
    from mathutils import Vector

    bodies = subtree(scene, joint.rigid_body_constraint.object2)
    masses = [(b, b.adf.body.mass if b.adf.body.use_mass else 1.0) for b in bodies]
    if linear:
        return sum(m for _, m in masses)
    origin = joint.matrix_world.translation
    axis = (joint.matrix_world.to_3x3() @ Vector(axis_local)).normalized()
    total = 0.0
    for b, m in masses:
        r = b.matrix_world.translation - origin
        d2 = (r - axis * r.dot(axis)).length_squared
        total += m * d2 + _own_inertia(b, m)
    return total


def load_about_joint(scene, joint) -> float:
    """What the joint moves: for a prismatic joint (or linear spring) the subtree's mass (kg);
    otherwise its inertia about the joint axis (the axis chosen in its panel, else Z) in kg·m²,
    :func:`load_about`."""
    from adfkit.model.semantics import JointKind, joint_kind

    p = joint.adf.joint
    kind = joint_kind(p.type) if p.use_type else JointKind.REVOLUTE
    axis = tuple(1.0 if a == p.axis else 0.0 for a in "XYZ") if p.axis != "DEFAULT" else (0.0, 0.0, 1.0)
    return load_about(scene, joint, axis, linear=kind in (JointKind.PRISMATIC, JointKind.LINEAR_SPRING))


def estimate_gains(scene, joints, frequency_hz: float = 2.0, damping_ratio: float = 1.0) -> dict:
    """Set the PID controller (P, I = 0, D) of each joint; returns {joint name: (P, D)}."""
    done = {}
    for j in joints:
        rbc = j.rigid_body_constraint
        if j.adf.kind != "JOINT" or rbc is None or rbc.object2 is None:
            continue
        pgain, dgain = pd_gains(max(load_about_joint(scene, j), 1e-9), frequency_hz, damping_ratio)
        p = j.adf.joint
        p.use_controller_p, p.controller_p = True, pgain
        p.use_controller_i, p.controller_i = True, 0.0
        p.use_controller_d, p.controller_d = True, dgain
        done[j.name] = (pgain, dgain)
    return done


#: A new spring joint's natural frequency and damping ratio: stiff enough that its child sags by
#: g/ω² = 2.5 mm (or 2.5 mm·m/d rad at a distance d) under gravity, critically damped.
SPRING_HZ, SPRING_DAMPING_RATIO = 10.0, 1.0
#: A new spring's range: a linear spring ±1 cm, a torsion spring and a six-dof spring's
#: rotations ±0.5 rad; a six-dof spring's translations held (the joints of AMBF's threads).
SPRING_TRAVEL, SPRING_TURN = 0.01, 0.5


def spring_defaults(scene, joint) -> None:
    """Limits, stiffness, damping and equilibrium for a new spring joint, from what it moves
    (stiffness = load·ω², damping = 2ζ·load·ω at :data:`SPRING_HZ`): AMBF keeps a spring without
    limits locked, and a six-dof spring's defaults (±1.2, stiffness 1) let its child fall."""
    from adfkit.model.semantics import JointKind, joint_kind

    p = joint.adf.joint
    kind = joint_kind(p.type)

    def gains(load: float) -> tuple[float, float]:
        return pd_gains(max(load, 1e-9), SPRING_HZ, SPRING_DAMPING_RATIO)

    def put(**values) -> None:
        for k, v in values.items():
            setattr(p, "use_" + k, True)
            setattr(p, k, v)

    if kind in (JointKind.LINEAR_SPRING, JointKind.TORSION_SPRING):
        linear = kind is JointKind.LINEAR_SPRING
        k, c = gains(load_about(scene, joint, linear=linear))
        r = SPRING_TRAVEL if linear else SPRING_TURN
        put(limit_low=-r, limit_high=r, stiffness=k, damping=c, equilibrium=0.0)
    elif kind is JointKind.SIX_DOF_SPRING:
        lin = gains(load_about(scene, joint, linear=True))
        ang = [gains(load_about(scene, joint, a)) for a in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))]
        put(
            linear_low=(0.0,) * 3,
            linear_high=(0.0,) * 3,
            angular_low=(-SPRING_TURN,) * 3,
            angular_high=(SPRING_TURN,) * 3,
            stiffness_linear=(lin[0],) * 3,
            damping_linear=(lin[1],) * 3,
            stiffness_angular=tuple(k for k, _ in ang),
            damping_angular=tuple(c for _, c in ang),
            equilibrium_linear=(0.0,) * 3,
            equilibrium_angular=(0.0,) * 3,
        )


def show_joints(scene, show: bool, passive_only: bool = False) -> int:
    """Hide or show every ADF joint (and its constraint empty) in the viewport; with
    ``passive_only`` only the joints marked passive (AMBF's add-on: "hide passive joints")."""
    n = 0
    for o in scene.objects:
        if o.adf.kind == "JOINT" and (not passive_only or _passive(o)):
            o.hide_set(not show)
            n += 1
    return n


def _passive(joint_obj) -> bool:
    j = joint_obj.adf.joint
    return bool(getattr(j, "use_passive", False) and getattr(j, "passive", False))


COLLISION = ("COLLISION_SHAPE", "COLLISION_MESH")


def show_collision(scene, show: bool, objects=None) -> int:
    """Hide or show the collision shapes and collision meshes of every body and ghost, or of
    ``objects`` only (bodies: their collision children; collision objects: themselves)."""
    if objects is None:
        targets = [o for o in scene.objects if o.adf.kind in COLLISION]
    else:
        targets = [o for o in objects if o.adf.kind in COLLISION]
        targets += [c for o in objects for c in o.children if c.adf.kind in COLLISION and c not in targets]
    for o in targets:
        o.hide_set(not show)
    return len(targets)


def rename_joints(scene, objects=None) -> list[str]:
    """Name every joint (or the joints among ``objects``) after its bodies, 'parent-child'
    (AMBF's add-on convention), keeping names unique; returns the new names."""
    done = []
    pool = scene.objects if objects is None else objects
    for o in sorted((o for o in pool if o.adf.kind == "JOINT"), key=lambda o: o.name):
        rbc = o.rigid_body_constraint
        if rbc is None or rbc.object1 is None or rbc.object2 is None:
            continue
        want = f"{rbc.object1.name}-{rbc.object2.name}"
        if o.name != want:
            o.name = want  # Blender appends .001 when the name is taken
        done.append(o.name)
    return done


def cleanup(scene) -> list[str]:
    """Remove what no longer makes an ADF element: joints whose constraint lost a body,
    collision children whose parent is not a body or ghost, and empty ADF snapshots of
    objects marked None. Returns what was removed or cleared, one line each."""
    said = []
    for o in list(scene.objects):
        k = o.adf.kind
        if k == "JOINT":
            rbc = o.rigid_body_constraint
            ok = rbc is not None and all(
                b is not None and b.adf.kind in ("BODY", "SOFT_BODY") for b in (rbc.object1, rbc.object2)
            )
            if not ok and not o.adf.snapshot:
                said.append(f"removed joint {o.name} (no parent or child body)")
                bpy.data.objects.remove(o, do_unlink=True)
        elif k in ("COLLISION_SHAPE", "COLLISION_MESH"):
            if o.parent is None or o.parent.adf.kind not in ("BODY", "GHOST", "SOFT_BODY"):
                said.append(f"removed collision {o.name} (not under a body)")
                bpy.data.objects.remove(o, do_unlink=True)
        elif k == "NONE" and (o.adf.snapshot or o.adf.identifier):
            o.adf.snapshot = o.adf.snapshot_matrix = o.adf.identifier = ""
            said.append(f"cleared ADF data of {o.name}")
    return said


def strip(objs) -> int:
    """Make objects plain Blender objects again (kind None, no ADF snapshot)."""
    n = 0
    for o in objs:
        o.adf.kind = "NONE"
        o.adf.snapshot = o.adf.snapshot_matrix = o.adf.identifier = ""
        n += 1
    return n
