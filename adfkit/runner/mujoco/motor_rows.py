"""What AMBF's motor rows need of MuJoCo (runner/joint_commands.py: a position or velocity
command is AMBF's hinge or slider motor, a constraint row at the joint's cfm that pushes the
joint's two bodies apart; the runner plays it as the effort those rows settle on): the joints'
mobility, M⁻¹ over the driven joints, and the mass one row sees between the joint's two bodies
alone. Only where AMBF's bodies are asked for (Options.bodies "ambf": adfkit run, adfkit
parity); otherwise the row mass is infinite and a command keeps the joint's stiff drive."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from ...model.semantics import JointKind
from ..joint_commands import row_mass


def joint_mobility(world, art, idxs) -> np.ndarray:
    """(M⁻¹) over joints ``idxs`` (record indices) of ``art``, now: the velocity change of those
    joints per unit of impulse on each, the model's other joints free (MuJoCo's M, its
    armature included, solved for the joints' unit vectors)."""
    m, d = world.model, world.data
    dofs = [int(art.vadr[i]) for i in idxs]
    unit = np.zeros((len(dofs), m.nv))
    unit[np.arange(len(dofs)), dofs] = 1.0
    out = np.zeros_like(unit)
    mujoco.mj_solveM(m, d, out, unit)
    return out[:, dofs]


def joint_row_mass(world, art, index: int) -> float:
    """The mass AMBF's motor row along joint ``index`` sees between the joint's two bodies
    (joint_commands.row_mass; a body welded to the world adds nothing). Infinite (no motor row)
    where AMBF's bodies are not asked for."""
    if world.opt.bodies != "ambf":
        return math.inf
    m, d = world.model, world.data
    jid = int(m.dof_jntid[art.vadr[index]])
    child = int(m.jnt_bodyid[jid])
    ends = [
        (float(m.body_mass[b]), m.body_inertia[b], d.ximat[b].reshape(3, 3))
        for b in (int(m.body_parentid[child]), child)
        if m.body_weldid[b] != 0 and m.body_mass[b] > 0.0  # welded to the world: it cannot move
    ]
    return row_mass(d.xaxis[jid], ends, art.kinds[index] is JointKind.PRISMATIC)
