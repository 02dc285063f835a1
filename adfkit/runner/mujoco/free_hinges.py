"""The hinges of a six-dof-family joint with neither stiffness nor damping about their axis, on
a light body (every principal moment under LIGHT_INERTIA): the bundled suture thread's without its
springs (30 g capsules of 1.5e-8 kg·m² across and 1e-9 along, joined by their ±30° limits alone;
the springs are what AMBF cannot play on elements this light, parity.md). MuJoCo's tree
plays them with an armature, a damping and limits of their own (below); every other joint is
built as the file gives it (the corpus thread's elements, 5e-5 kg·m² and sprung, the parity
scenes' pendulums, 1e-3 kg·m²: their digests and figures unchanged).

Measured on the bundled suture without the thread's springs in MuJoCo (`adfkit suture --engine
mujoco`, seed 0), which went unstable 3.9 s into carry 1 (a NaN at the 34th element) with the
hinges as the file gives them:

- **The limits gave way.** A MuJoCo limit is soft: pressed with an unconstrained acceleration
  a0 it settles (1 - d)/d · a0/k past its range (d the impedance, 0.95 by default; k = 1/(d·τ)²,
  τ 20 ms by default), and a0 is the load over the joint's inertia: the hanging thread's weight
  on the first joint, 0.014 N·m over 5.8e-8 kg·m², is 2.4e5 rad/s², about 2 rad past the stop.
  The first joint turned to 1.7-2.2 rad (the stop at 0.52) as psm1 lifted the needle, and its
  three hinges, R = Rx·Ry·Rz, met their gimbal lock at 90° about y, where the x and z hinges'
  mass matrix is singular but for their armature: NaN. With d = 0.99 and τ = 4 physics steps
  the joints stay within 0.58 rad through pair 1 (τ = 2 steps with d = 0.999: unstable in carry 1).
- **The chain whipped.** With the limits held, the light elements still swung at 50-150 rad/s
  through carry 1 (the thread's whole kinetic energy 1e-3 J) and the state blew up at 3.95-4.7 s,
  whatever the limits' time constant (2-10 steps); MuJoCo's implicit integrator (2.7 s) and RK4
  (3.5 s) did no better, nor stiffer contacts, nor none. An armature of 1e-8 kg·m² on each hinge
  (a sixth of an element's inertia about its joint) with a damping of 5e-6 N·m·s/rad carried
  seed 0 through pairs 1 and 2 and blew up lifting the needle for carry 3 (51.5 s); with
  2e-5 N·m·s/rad (the hinge's relative motion relaxed in about 3 physics steps; MuJoCo's joint
  damping is implicit) seed 0 passes all four pairs. Either alone went unstable in carry 1
  (armature 3.98 s, damping 4.69 s).

AMBF's Bullet joins such elements with constraint rows between bodies of their own inertia,
solved by a few iterations, which neither leak under load nor keep a whip going. At rest for 1 s
(`adfkit parity SCENE --seconds 1 --engine mujoco`) the bundled scene without the thread's
springs stands 0.53 mm from AMBF (0.52 mm without these).
"""

from __future__ import annotations

import mujoco

#: kg·m²: a body whose principal moments are all below it is light (the bundled thread's elements)
LIGHT_INERTIA = 1e-6
#: kg·m² on each free hinge of a light body (build.SPRING_HINGE_ARMATURE, 1e-9, on the others)
FREE_HINGE_ARMATURE = 1e-8
#: N·m·s/rad on each free hinge of a light body
FREE_HINGE_DAMPING = 2e-5
#: their limits: time constant in physics steps and impedance (MuJoCo's solref, solimp)
LIMIT_TIMECONST_STEPS = 4
LIMIT_IMPEDANCE = 0.99


def is_free_hinge(joint, tag: str, stiffness: float, damping: float) -> bool:
    """MjsJoint ``joint`` is a hinge of a six-dof-family joint with neither stiffness nor damping
    about its axis, on a light body."""
    if tag != "hinge" or stiffness != 0.0 or damping != 0.0:
        return False
    return bool(max(joint.parent.inertia) < LIGHT_INERTIA)


def hold_free_hinge(joint, dt: float) -> None:
    """Give MjsJoint ``joint`` (is_free_hinge) the armature, the damping and, where it is
    limited, the limits above."""
    joint.armature = FREE_HINGE_ARMATURE
    joint.damping = [FREE_HINGE_DAMPING, 0.0, 0.0]  # (MuJoCo 4: a polynomial in the velocity)
    if joint.limited == mujoco.mjtLimited.mjLIMITED_TRUE:
        joint.solref_limit = [LIMIT_TIMECONST_STEPS * dt, 1.0]
        joint.solimp_limit = [LIMIT_IMPEDANCE, LIMIT_IMPEDANCE, 0.001, 0.5, 2.0]
