"""Which of MuJoCo's integrators steps a rigid scene: the cheapest that gives implicit-fast's
result. Implicit-fast solves (M - h·∂f/∂v) for the new velocities, its velocity derivative
computed anew at every physics step; MuJoCo's Euler integrator solves (M + h·diag(dof damping))
the same way wherever a moving dof is damped. Where the dofs' damping is the only force that
depends on velocity (no actuators, no damped tendons, no fluid, no flex), the two matrices are
one, entry for entry, and Euler skips the derivative: the velocities agree to round-off (its
solve orders a few operations differently), and the corpus suturing set under `adfkit run`'s
options plays the same poses to the last bit for 10 s with 0.90-0.91x of mj_step's CPU time
(bench/mujoco_run_speed.py), the bundled suture's trajectory digest unchanged."""

from __future__ import annotations

import mujoco
import numpy as np


def integrator_for(model) -> int:
    """mjINT_EULER where it integrates as implicit-fast does (above), implicit-fast otherwise;
    a flex's discrete integrator is kept. Euler treats the damping implicitly only while a damped
    dof moves: with every awake dof undamped it takes the solver's accelerations, which
    implicit-fast would recompute from the same forces (equal to the solver's tolerance)."""
    if model.opt.integrator != mujoco.mjtIntegrator.mjINT_IMPLICITFAST:
        return int(model.opt.integrator)
    only_damping = (
        model.nu == 0
        and model.nflex == 0
        and not np.any(model.tendon_damping)
        and model.opt.density == 0.0
        and model.opt.viscosity == 0.0
        and np.any(model.dof_damping > 0.0)
    )
    return int(mujoco.mjtIntegrator.mjINT_EULER if only_damping else mujoco.mjtIntegrator.mjINT_IMPLICITFAST)
