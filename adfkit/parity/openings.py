"""How far the joints stand open on each side of a parity run: a joint that holds its two pivots
together (fixed, revolute, p2p, cone twist, the springs and six-dof joints whose linear axes are
locked) leaves them apart by what its solver has not closed. AMBF's Bullet visits every
constraint row ten times a step and stops there, so a long chain's joints stand open under load
(the suture thread's first joint up to 2 mm, the thread as a whole several millimetres longer than
it is), where an engine that solves a tree exactly (MuJoCo) keeps them shut: the gap between two
traces that comes from it is read here, from each side's own body poses."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.semantics import JointKind, body_joint_frames, joint_kind
from ..runner.rotations import pose_to_matrix, quat_to_matrix
from .traces import Trace, ambf_name

#: the kinds whose pivots stay together whatever the joint's value
ALWAYS_SHUT = (JointKind.FIXED, JointKind.REVOLUTE, JointKind.P2P)
SPRING_FAMILY = (
    JointKind.CONE_TWIST,
    JointKind.SIX_DOF,
    JointKind.SIX_DOF_SPRING,
    JointKind.LINEAR_SPRING,
    JointKind.TORSION_SPRING,
)


@dataclass
class Pivots:
    """A joint's pivot in its parent's and in its child's body frame (by AMBF's names)."""

    name: str
    parent: str
    child: str
    in_parent: np.ndarray  # (3,)
    in_child: np.ndarray  # (3,)


def holds_pivots(joint) -> bool:
    """Whether ``joint`` keeps its two pivots together (its linear axes locked)."""
    kind = joint_kind(joint.type)
    if kind in ALWAYS_SHUT:
        return True
    if kind in SPRING_FAMILY:
        from ..runner.springs import spring_joint

        return spring_joint(joint, kind, None, None, np.eye(4), np.eye(4)).linear_constrained
    return False


def shut_pivots(world, made: dict[str, list[str]]) -> list[Pivots]:
    """The pivots of the world's joints that hold them together, named as AMBF names them
    (``made``: traces.made_by(world))."""
    out = []
    for (joint, parent, child), name in zip(world.joints_made, made["joint"]):
        if parent is None or child is None or not holds_pivots(joint):
            continue
        a, b = body_joint_frames(joint, parent.body, child.body)
        out.append(
            Pivots(
                name,
                ambf_name(parent.key, parent.body),
                ambf_name(child.key, child.body),
                pose_to_matrix(a)[:3, 3],
                pose_to_matrix(b)[:3, 3],
            )
        )
    return out


def openings(trace: Trace, pivots: list[Pivots]) -> np.ndarray:
    """(S, J) how far apart each joint's pivots stand at each sample, m; NaN where the trace
    lacks one of its bodies."""
    index = {}
    for i, n in enumerate(trace.body_names):
        index.setdefault(n, i)
    s = len(trace.times)
    out = np.full((s, len(pivots)), np.nan)
    if not s:
        return out
    rot = quat_to_matrix(trace.poses[..., 3:7].reshape(-1, 4)).reshape(s, -1, 3, 3)
    for k, p in enumerate(pivots):
        i, j = index.get(p.parent), index.get(p.child)
        if i is None or j is None:
            continue
        at_parent = trace.poses[:, i, :3] + rot[:, i] @ p.in_parent
        at_child = trace.poses[:, j, :3] + rot[:, j] @ p.in_child
        out[:, k] = np.linalg.norm(at_parent - at_child, axis=1)
    return out


@dataclass
class Opening:
    """One side's joints standing open over a run."""

    side: str
    widest: str  # the joint that stood widest open
    widest_m: float
    summed_m: float  # the most the openings summed to at one sample (a chain that long more)
    summed_end_m: float

    def as_json(self) -> dict:
        return {
            "widest": {"name": self.widest, "m": self.widest_m},
            "summed_m": self.summed_m,
            "summed_end_m": self.summed_end_m,
        }


def opening(trace: Trace, pivots: list[Pivots]) -> Opening | None:
    """How far ``trace``'s joints stood open; None without a joint whose pivots it carries."""
    o = openings(trace, pivots)
    have = ~np.all(np.isnan(o), axis=0)
    if not np.any(have):
        return None
    o = o[:, have]
    names = [p.name for p, h in zip(pivots, have) if h]
    widest = np.nanmax(o, axis=0)
    summed = np.nansum(o, axis=1)
    k = int(np.argmax(widest))
    return Opening(trace.side, names[k], float(widest[k]), float(summed.max()), float(summed[-1]))
