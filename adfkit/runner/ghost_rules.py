"""What ghost objects do to the bodies inside them, for every engine (Options.ghosts): AMBF's own
rule, or the challenge paper's viscous friction inside hole ghosts."""

from __future__ import annotations

import math
from itertools import repeat
from operator import le, sub

import numpy as np

#: what ghosts do (Options.ghosts): AMBF's own rule, or the paper's viscous friction in holes
GHOST_RULES = ("ambf", "hole-friction")
#: AMBF's afGhostObject::update, after every physics step, for each penetrating contact point
#: between a ghost and a rigid body (measured in AMBF 2.0): the body's gravity is switched off for
#: the next step, its velocity across the ghost parent's keeps this share (along the parent's
#: velocity it takes the parent's), its angular velocity too; leaving, it gets the world's gravity
AMBF_GHOST_KEEP = 0.9
#: the contact points a Bullet manifold holds (btPersistentManifold's MANIFOLD_CACHE_SIZE): AMBF's ghost
#: acts at most this many times a step for one pair of shapes
MANIFOLD_POINTS = 4
#: m (and quaternion or rotation-matrix entries): a ghost and the bodies near it that moved no more
#: than this since the engine's last collision pass for it keep that pass's contact points
SAME_PLACE = 1e-9
#: m/s: a ghost's parent slower than this takes nothing along its velocity (ghost_velocity)
ALONG_FROM = 1e-5
#: m/s: a free body near a ghost that moved slower than this keeps the rule once a control step;
#: a faster one has its control step played a physics step at a time (the engines' ghost_steps.py)
SLOW = 1e-3


def in_same_place(a: list, b: list, within: float = SAME_PLACE) -> bool:
    """Whether every number of the (position, quaternion) pairs ``b`` lies within ``within`` of
    ``a``'s (NaN never does); the first that does not ends the search (something near a ghost
    moves almost every step). A pair equal as it stands (a body read again where it rests) is
    skipped at the cost of one tuple comparison: a NaN read afresh is unequal to any other."""
    for pq_a, pq_b in zip(a, b):
        if pq_a == pq_b:
            continue
        for va, vb in zip(pq_a, pq_b):  # |x - y| <= within for each number, iterated in C
            if not all(map(le, map(abs, map(sub, va, vb)), repeat(within))):
                return False
    return True


def ghost_velocity(v, w, v_parent, points: int):
    """(linear, angular) velocity of a body after ``points`` of AMBF's ghost updates (one per
    penetrating contact point and physics step): keep^points of what is across the parent's
    velocity, plus the parent's."""
    kept = kept_under_slow_parent(v, w, v_parent, points)
    if kept is not None:
        return np.array(kept[0], dtype=float), np.array(kept[1], dtype=float)
    keep = AMBF_GHOST_KEEP**points
    v, w, va = np.asarray(v, float), np.asarray(w, float), np.asarray(v_parent, float)
    mag = float(np.linalg.norm(va))
    along = va * (float(v @ va) / (mag * mag)) if mag > ALONG_FROM else np.zeros(3)
    return keep * (v - along) + va, keep * w


def kept_under_slow_parent(v, w, v_parent, points: int) -> tuple[list[float], list[float]] | None:
    """ghost_velocity, as lists, where the parent is slower than ALONG_FROM (nothing is taken
    along its velocity: a static phantom's hole ghosts, a resting arm's finger ghosts): the same
    sums, keep·(v - 0) + v_parent and keep·w, in floats, without numpy's cost; None where the
    parent is faster, or so near ALONG_FROM that numpy's norm, rounded its own way, decides."""
    x, y, z = v_parent
    if x * x + y * y + z * z > ALONG_FROM * ALONG_FROM * (1.0 - 1e-9):  # sum()'s order, without its generator
        return None
    keep = AMBF_GHOST_KEEP**points
    return [keep * (x - 0.0) + p for x, p in zip(v, v_parent)], [keep * x for x in w]


def ghost_accelerations(v, w, v_parent, points: int, cdt: float):
    """(linear, angular) accelerations that, held over a control step ``cdt``, take a body's
    velocities where ``points`` of AMBF's ghost updates set them (ghost_velocity): a jointed
    body's velocities cannot be set, so the engines give it the force m·a at its centre of mass
    and the torque I·α (the links' damping is given the same way, damping.gains). Under a slow
    parent (kept_under_slow_parent) the same differences and quotients in floats, without numpy's
    cost a call."""
    kept = kept_under_slow_parent(v, w, v_parent, points)
    if kept is not None:
        return tuple(np.array([(b - a) / cdt for a, b in zip(now, then)]) for now, then in zip((v, w), kept))
    v, w = np.asarray(v, float), np.asarray(w, float)
    v2, w2 = ghost_velocity(v, w, v_parent, points)
    return (v2 - v) / cdt, (w2 - w) / cdt


def viscous_impulse_force(mass: float, v_rel: np.ndarray, k: float, cdt: float) -> np.ndarray:
    """F = -K·v_rel held for a control step ``cdt`` as the exact exp(-K·t/m) decay of
    dv/dt = -K·v/m (the paper's needle friction in the hole ghosts), never overshooting."""
    return -mass * v_rel * (1.0 - math.exp(-k * cdt / mass)) / cdt
