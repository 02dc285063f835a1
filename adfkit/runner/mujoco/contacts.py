"""Contacts in the MuJoCo world as the ADF scene's engine (Bullet) makes them: rigid, and with
the two bodies' frictions combined so that a frictionless body is frictionless to everything.

- **Stiffness.** MuJoCo's contacts are soft by default: a time constant of 0.02 s, 20 physics
  steps here. Bullet's are rigid. The runner gives every geom a time constant of
  CONTACT_TIMECONST_STEPS steps, the stiffest MuJoCo keeps stable. At 0.02 s the suture's thread
  (a 0.19 mm capsule) pulled over a hole's 0.6 mm boundary capsule with 2.4 N sank 0.77 mm into
  it and slipped through, out of the hole it had gone through; now 2.4 N sinks a 0.19 mm sphere
  0.036 mm into such a capsule. The price: a fast impact rebounds (a 0.5 kg box dropped 0.2 m
  onto the ground rises 8.5 mm again, where Bullet's does not; a damping ratio of 2 would stop
  that but soften the contact fourfold, as a time constant of 4 steps, at which the thread still
  slipped out of Exit1 at pair 1, seed 0).
- **Friction.** Bullet multiplies the two bodies' frictions; MuJoCo takes the larger, unless the
  geoms' priorities differ, when it takes the higher-priority geom's. It cannot multiply, so
  every geom gets a priority by its friction, the lowest highest: a pair takes the lower of
  the two, exactly Bullet's product where either is 0 or 1 and within a factor of the other
  otherwise (the suture's thread on the phantom: 0.5 against Bullet's 0.5 × 0.8 = 0.4). The
  suturing scene's hole boundaries are frictionless; with the larger (the thread's 0.5) the
  thread, drawn through two holes, held the pull with 50-80 N where Bullet's needs 2-3 N.
"""

from __future__ import annotations

import numpy as np

#: contacts' time constant in physics steps: 2, the stiffest MuJoCo keeps stable
CONTACT_TIMECONST_STEPS = 2


def set_contacts(model, dt: float) -> None:
    """Every geom's contact time constant and its friction priority (see the module docstring)."""
    model.geom_solref[:, 0] = CONTACT_TIMECONST_STEPS * dt
    mu = np.round(model.geom_friction[:, 0], 9)
    levels = np.unique(mu)  # ascending
    model.geom_priority[:] = len(levels) - 1 - np.searchsorted(levels, mu)
