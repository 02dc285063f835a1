"""The contact forces the suture reads (its force rules, tasks/metrics.py, and its guards,
tasks/motions.py), in the reading its limits were set and accepted on: PyBullet's where a control
step is one stepSimulation of four 1 ms physics steps, which reports the last physics step's
impulse over the whole 4 ms, a quarter of the force (``contact_force_scale`` of the PyBullet
world). A world that steps its physics steps one by one (AMBF's springs, ghosts or bodies, the
Options ``adfkit parity --suture`` may record under) reports the whole force; read as it is, the
needle lying on the corpus phantom pressed with 5.3 N there against 1.3 N, and the pick-up's
grasp with 45-67 N against 11-17 N, past the suture's 40 N (``pressed-on-tissue``). MuJoCo
reports the force as it is and is read so."""

from __future__ import annotations


def contacts_among(world, bodies) -> list:
    """``world.contacts_among(bodies)``, each force in the suture's reading."""
    found = world.contacts_among(bodies)
    scale = getattr(world, "contact_force_scale", 1.0)
    if scale == 1.0:
        return found
    return [(sb, other, f * scale, at) for sb, other, f, at in found]
