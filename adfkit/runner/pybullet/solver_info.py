"""AMBF's contact solver settings in PyBullet's world.

AMBF's world keeps Bullet 2.88's btContactSolverInfo as it is made; PyBullet's server changes
some of it when it makes its world (PhysicsServerCommandProcessor). Where AMBF's bodies are
asked for (Options.bodies "ambf") the runner gives back AMBF's values that PyBullet can set
(PyBulletWorld passes them to setPhysicsEngineParameter with its own).
"""

from __future__ import annotations

# btContactSolverInfo's values in AMBF (PyBullet's own in the comments)
AMBF_SOLVER_INFO: dict[str, float] = {
    "contactERP": 0.2,  # m_erp2, a contact's error reduction (0.08)
    "warmStartingFactor": 0.85,  # m_warmstartingFactor, a rigid body's rows start from it (0.1)
    "contactSlop": 0.0,  # m_linearSlop (1e-5 m)
    "solverResidualThreshold": 0.0,  # m_leastSquaresResidualThreshold (1e-7)
}
