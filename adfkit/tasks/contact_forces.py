"""The suture's force limits in the newtons of the engine it runs in.

Every world reports a contact's normal force in newtons (``contacts``, ``contacts_among``;
PyBullet's reading multiplied back by the physics steps a stepSimulation split into,
``PyBulletWorld.physics_steps_a_call``). The suture's limits (``verdicts.force_limits``,
``motions.GUARD_N``) were set on each engine's measured runs: MuJoCo's in newtons, PyBullet's on
its reading at the default ``control_substeps`` (4), a quarter of the force. In newtons
PyBullet's are therefore 4x the figures written there (a tool pressing 200 N fails a pair, the
needle 160 N). The factor is a power of two, so the scaled forces and limits compare exactly as
the readings and the written figures did."""

from __future__ import annotations

#: the suture's limits in an engine's newtons, as a multiple of the figures written in verdicts.py
#: and motions.py (an engine not named: 1)
LIMIT_SCALE = {"pybullet": 4.0}


def limit_scale(world) -> float:
    """What the suture's written force limits are multiplied by in ``world``'s newtons."""
    return LIMIT_SCALE.get(getattr(world, "engine", "") or "", 1.0)
