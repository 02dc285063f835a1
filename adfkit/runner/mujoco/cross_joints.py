"""Joints between bodies of different model files. AMBF looks a joint's parent and child up in its
own model, then in every body loaded before it (adf-format.md §12.2), so a model can hang a body
on another model's; the MJCF writer builds each model's tree alone and leaves such a joint out.
Here each is closed the way a joint closing a loop is: a weld for a `fixed` joint, a connect at
its pivot for the other kinds MJCF can close (LOOP_KINDS; a hinge's or slider's axis is then not
held, as for a loop). The others are warned about and not played."""

from __future__ import annotations

import mujoco
import numpy as np

from ...converters.mjcf_write import LOOP_KINDS
from ...model.semantics import JointKind, body_joint_frames, joint_kind
from ..names import Registry
from ..plan import holds_nothing, joint_ends, warn_unheld


def cross_model_joints(world, spec, plans_by_model, body_type) -> list[tuple]:
    """The joints of ``plans_by_model`` ([(model, {identifier: BodyPlan}, tree | None)]) whose two
    ends AMBF finds in different models, each added to ``spec`` as an equality: [(joint, kind,
    parent plan, child plan, pivot A in the parent's MJCF body, pivot B in the child's)]."""
    out = []
    for m, mine, tree in plans_by_model:
        made = set() if tree is None else {id(lk.joint) for lk in tree.ordered() if lk.parent is not None}
        made |= set() if tree is None else {id(r[0]) for r in tree.loops}
        local = Registry()
        for bp in mine.values():
            local.items[bp.key] = bp
        for j in m.joints:
            kind = joint_kind(j.type)
            if kind is None or id(j) in made:
                continue
            parent, child = joint_ends(world.registry, local, m.namespace or "", j)
            if not (isinstance(parent, body_type) and isinstance(child, body_type)) or parent is child:
                continue
            if parent.model is child.model:
                continue  # within one model: its tree had its reasons
            if holds_nothing(parent.body, j):  # AMBF keeps it, holding nothing (plan.holds_nothing)
                warn_unheld(world, j, parent.key)
                continue
            if kind not in LOOP_KINDS:
                world._warn(
                    "runner-loop",
                    f"{j.identifier}: a {kind.value} joint to another model's body is not played by the MuJoCo "
                    "engine; skipped",
                    j,
                )
                continue
            a, b = body_joint_frames(j, parent.body, child.body)
            pa = np.array(parent.link.in_link(a).position, float)
            pb = np.array(child.link.in_link(b).position, float)
            fixed = kind is JointKind.FIXED
            eq = spec.add_equality(
                type=mujoco.mjtEq.mjEQ_WELD if fixed else mujoco.mjtEq.mjEQ_CONNECT,
                name=f"cross:{parent.key}->{child.key}:{j.identifier}",
                name1=parent.mjname,
                name2=child.mjname,
                objtype=mujoco.mjtObj.mjOBJ_BODY,
            )
            # a connect's anchor is in body1's frame; a weld's in body2's, at its origin as MJCF's
            # default (MjSpec's puts it 1 m along y), keeping the two bodies' poses at qpos0
            eq.data[:3] = np.zeros(3) if fixed else pa
            out.append((j, kind, parent, child, pa, pb))
    return out


def stiff_static_hinges(spec, loops, dt: float, timeconst_steps: float, damping_ratio: float) -> None:
    """The two connects that close a hinge to a static body (the MJCF writer's, a static body
    being a root of its own) held as stiffly as a grasp's weld: at MuJoCo's default 0.02 s a
    0.3 kg arm swinging from a static post drifted 1.2 mm along its axis (0.02 mm so)."""
    from ...model.semantics import JointKind, effective_mass

    for _j, kind, parent, child, _pa, _pb in loops:
        if kind is not JointKind.REVOLUTE or (effective_mass(parent.body) and effective_mass(child.body)):
            continue
        for eq in spec.equalities:
            if eq.type == mujoco.mjtEq.mjEQ_CONNECT and {eq.name1, eq.name2} == {parent.mjname, child.mjname}:
                eq.solref = [timeconst_steps * dt, damping_ratio]


def file_anchors(m, loops) -> None:
    """Each connect that closes a joint of ``loops`` holds the child's pivot the file gives, as
    AMBF's btPoint2PointConstraint and btHingeConstraint hold both pivots: MuJoCo computes a
    connect's second anchor from where the bodies start, so where a file places a child off its
    joint MuJoCo held the two pivots that far apart for good (a p2p from a free box to a static
    one, the child's pivot 100 mm off: 100.4 mm open after 1 s, AMBF's 0.010 mm). The second
    connect of a hinge to a static body (a point on its axis) moves with it. Not a loop within
    one tree (a joint between two links of one multibody): its bodies start where the file puts
    them, and what the file leaves open across a planar loop no joint of the tree can close, so
    the connect keeps it, as the PyBullet runner anchors it (pybullet/loops.py). Held at the
    file's pivot, corpus gripper 3's jaw loop (0.37 mm open) twisted the jaws 19.6 mm from AMBF's
    (7.98 mm kept open; the parallel structure 9.97 and 9.26 mm)."""
    connects = [e for e in range(m.neq) if m.eq_type[e] == mujoco.mjtEq.mjEQ_CONNECT]
    for _j, kind, parent, child, pa, pb in loops:
        if kind is JointKind.FIXED:
            continue
        ids = (
            mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, parent.mjname),
            mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, child.mjname),
        )
        if m.body_rootid[ids[0]] == m.body_rootid[ids[1]] != 0:  # a loop within one tree: see above
            continue
        pair = [e for e in connects if (int(m.eq_obj1id[e]), int(m.eq_obj2id[e])) == ids]
        pivot = [e for e in pair if np.linalg.norm(m.eq_data[e, :3] - pa) < 1e-9]
        if len(pivot) != 1:
            continue
        shift = np.asarray(pb, float) - m.eq_data[pivot[0], 3:6]
        if np.linalg.norm(shift) <= 1e-9:  # the file's placement sits on the joint: kept bit for bit
            continue
        for e in pair:
            m.eq_data[e, 3:6] += shift
