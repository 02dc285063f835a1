"""The joints that close a multibody's loops (a parallelogram, the ECM's remote centre), read
for the chain step (chain.py) as the constraints AMBF makes of them: a hinge a
btHingeConstraint (its motor off), a p2p joint a btPoint2PointConstraint, solved with the
chain's own rows (runner/chain_rows.py). The runner builds them as PyBullet constraints between
two of the multibody's links (joints.py), which it closed at the start (loops.py): their pivots
are read where it closed them, so the rows push only what has come apart since; a hinge's
limits are read from its angle in the frames AMBF builds. A loop closed by another kind of
joint (a gripper's jaws joined by a slider) leaves the multibody to the joint-space rows:
played as a btSliderConstraint the corpus gripper3's velocity program went from 27 to 118 mm
off AMBF's, which is not understood."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...model.semantics import JointKind, joint_kind
from ..chain_rows import Joint, cross3, plane_space
from ..joint_commands import AMBF_JOINT_ERP, DEFAULT_JOINT_CFM, limits_of
from .joints import com_frames


@dataclass
class Loop:
    kind: str  # "revolute" or "p2p"
    joint: object
    parent: int  # the chain's body index (link + 1)
    child: int
    pivot_a: np.ndarray  # in the parent's COM frame, where the loop was closed
    pivot_b: np.ndarray  # in the child's
    axis_a: np.ndarray | None  # the hinge's axis, in the parent's COM frame
    frame_a: np.ndarray | None  # the joint's frames AMBF builds, in each COM frame (4x4)
    frame_b: np.ndarray | None

    @property
    def erp(self) -> float:
        return self.joint.joint_erp if self.joint.joint_erp is not None else AMBF_JOINT_ERP

    @property
    def cfm(self) -> float:
        return self.joint.joint_cfm if self.joint.joint_cfm is not None else DEFAULT_JOINT_CFM


def find_loops(world, art) -> list[Loop] | None:
    """The loops closed between two of ``art``'s links, or None where one is closed by a kind
    of joint the chain step does not read (a slider, a fixed or a spring joint)."""
    ends: dict[str, list] = {}
    for name, c, parent, child, pa, pbv, axis in world.constraints:
        if parent.articulation is art and child.articulation is art:
            ends.setdefault(name, []).append((c, parent, child, pa, pbv, axis))
    joints = {j.identifier: j for j, _p, _c in world.joints_made}
    loops = []
    for name, rows in ends.items():
        joint = joints.get(name)
        kind = joint_kind(joint.type) if joint is not None else None
        _c, parent, child, pa, pbv, axis = rows[0]
        a, b = parent.link + 1, child.link + 1
        if kind is JointKind.P2P and len(rows) == 1 and axis is None:  # one point constraint
            loops.append(Loop("p2p", joint, a, b, pa, pbv, None, None, None))
        elif kind is JointKind.REVOLUTE and len(rows) == 2 and axis is None:  # two points on its axis
            (pa1, pb1) = rows[1][3:5]
            fa, fb = com_frames(joint, parent, child)
            hinge = (pa1 - pa) / np.linalg.norm(pa1 - pa)
            loops.append(Loop("revolute", joint, a, b, (pa + pa1) / 2, (pbv + pb1) / 2, hinge, fa, fb))
        else:
            return None
    return loops


def loop_joints(loops: list[Loop], bodies, coms, rots, drift) -> list[Joint]:
    """The loops' joints for one step: their ends where the bodies and what the chain carries
    apart (``drift``: each body's displacement and small turn) put them."""
    out = []
    for lp in loops:
        a, b = lp.parent, lp.child
        ta, tb = drift[a, 3:], drift[b, 3:]
        pivot_a = _moved(coms[a] + rots[a] @ lp.pivot_a, coms[a], drift[a])
        pivot_b = _moved(coms[b] + rots[b] @ lp.pivot_b, coms[b], drift[b])
        if lp.kind == "p2p":
            jt = Joint("p2p", a, b, pivot_b, _X, _X, 0.0, 0.0, lp.erp, cfm=lp.cfm)
            jt.pivot_a = pivot_a
            out.append(jt)
            continue
        axis = _turned(rots[a] @ lp.axis_a, ta)
        axis_b = _turned(rots[b] @ lp.frame_b[:3, 2], tb)
        xa, xb = rots[a] @ lp.frame_a[:3, 0], rots[b] @ lp.frame_b[:3, 0]  # its angle, as the joint reads
        angle = math.atan2(float(cross3(xa, xb) @ axis), float(xa @ xb)) + float((tb - ta) @ axis)
        jt = Joint("revolute", a, b, pivot_b, axis, plane_space(axis)[0], angle, 0.0, lp.erp, limits_of(lp.joint))
        jt.pivot_a, jt.axis_b = pivot_a, axis_b
        jt.velocity = float((bodies[b].w - bodies[a].w) @ axis)
        out.append(jt)
    return out


def _moved(at: np.ndarray, com: np.ndarray, drift: np.ndarray) -> np.ndarray:
    """A body's point ``at`` where the body's drift (displacement, small turn) takes it."""
    return at + drift[:3] + cross3(drift[3:], at - com)


def _turned(v: np.ndarray, turn: np.ndarray) -> np.ndarray:
    v = v + cross3(turn, v)
    return v / math.sqrt(v @ v)  # np.linalg.norm's sum and root


_X = np.array([1.0, 0.0, 0.0])
