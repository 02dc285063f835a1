"""ADF body damping (`damping: {linear, angular}`) as AMBF applies it, for every engine: each
AMBF body is a btRigidBody, whose velocities Bullet scales by (1 - d)^dt every physics step, a
decay at the rate -ln(1 - d) per second (the KUKA's 0.95: 3.0/s). An engine that damps otherwise
(MuJoCo has no body damping; PyBullet damps a multibody's links as forces m·v·(d + d·|v|)) is
given each control step the force and torque that decay a body's velocity as AMBF does over
that step."""

from __future__ import annotations

import math

import numpy as np

from ..model.semantics import DEFAULT_ANGULAR_DAMPING, DEFAULT_LINEAR_DAMPING


def _rate(d: float | None, default: float) -> float:
    """Bullet clamps a damping to [0, 1] (btRigidBody::setDamping); at 1 it zeroes the velocity
    each physics step: an infinite rate, which stops the body within the step it is applied over."""
    d = default if d is None else float(d)
    if d >= 1.0:
        return math.inf
    return -math.log(1.0 - d) if d > 0.0 else 0.0


def decay_rates(body) -> tuple[float, float]:
    """(linear, angular) decay rates of the body's velocities, per second (0: none)."""
    dmp = body.damping
    return (
        _rate(getattr(dmp, "linear", None), DEFAULT_LINEAR_DAMPING),
        _rate(getattr(dmp, "angular", None), DEFAULT_ANGULAR_DAMPING),
    )


def gains(rates, control_dt: float) -> np.ndarray:
    """k per rate, the force being k·m·v (the torque k·I·ω): the velocity decays over the control
    step as exp(-rate·t), exactly, as the hole ghosts' viscous friction does."""
    return (np.exp(-np.asarray(rates, dtype=float) * control_dt) - 1.0) / control_dt
