"""The joints that close a chain's loops (a parallelogram, the ECM's remote centre) as AMBF's
solver reads them for the chain step (runner/chain_step.py): a hinge a btHingeConstraint (its
motor off, its limits read from its angle in the frames AMBF builds), a p2p joint a
btPoint2PointConstraint at the joint's erp and cfm, solved with the chain's own rows
(runner/chain_rows.py). Each engine finds its loops (runner/pybullet/chain_loops.py,
runner/mujoco/chain.py); this reads them each step. Engine-neutral: numpy only."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .chain_rows import Joint, cross3, plane_space
from .joint_commands import AMBF_JOINT_ERP, DEFAULT_JOINT_CFM, limits_of


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
