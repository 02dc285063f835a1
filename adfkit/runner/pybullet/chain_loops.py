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

import numpy as np

from ...model.semantics import JointKind, joint_kind
from ..loop_rows import Loop
from .joints import com_frames


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
