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
    """The mass (kg·m², kg) a Bullet row along joint ``index``'s axis sees between the joint's two
    bodies alone, as AMBF's hinge or slider motor row does: 1 / (aᵀ I_p⁻¹ a + aᵀ I_c⁻¹ a) for a
    hinge, 1 / (1/m_p + 1/m_c) for a slider; a body welded to the world adds nothing. Infinite
    (no motor row) where AMBF's bodies are not asked for."""
    if world.opt.bodies != "ambf":
        return math.inf
    m, d = world.model, world.data
    jid = int(m.dof_jntid[art.vadr[index]])
    child = int(m.jnt_bodyid[jid])
    axis = d.xaxis[jid]
    slider = art.kinds[index] is JointKind.PRISMATIC
    inverse = 0.0
    for body in (int(m.body_parentid[child]), child):
        if m.body_weldid[body] == 0 or m.body_mass[body] <= 0.0:
            continue
        if slider:
            inverse += 1.0 / float(m.body_mass[body])
            continue
        a = d.ximat[body].reshape(3, 3).T @ axis  # the axis in the body's principal frame
        inertia = m.body_inertia[body]
        inverse += float(sum(a[i] ** 2 / inertia[i] for i in range(3) if inertia[i] > 0.0))
    return 1.0 / inverse if inverse > 0.0 else math.inf
