"""Bodies' inertia in the MuJoCo world as AMBF's btRigidBodies have it, where AMBF's bodies are
asked for (``Options.bodies`` "ambf": ``adfkit run``, ``adfkit parity``)."""

from __future__ import annotations

import numpy as np

from ...converters.mjcf_write import MIN_INERTIA
from ...model.semantics import inertial_offset
from ..ambf_bodies import estimated_inertia, frozen_inertia
from ..rotations import pose_to_matrix


def ambf_inertia(opt, spec, bodies, warn=None) -> None:
    """Where ``opt`` asks for AMBF's bodies, a moving body of ``bodies`` (build.BodyPlan) whose file
    gives a mass and no `inertia` gets
    the inertia AMBF estimates (ambf_bodies.estimated_inertia: the box of its collision shape's
    bounds grown by its collision margin) in place of the MJCF writer's (the bounds alone), as the
    PyBullet runner's bodies do: the corpus springy KUKA's link7 6.509e-4 kg·m² about x (AMBF's
    6.512e-4), 6.13e-4 with the writer's."""
    if opt.bodies != "ambf":
        return
    for bp in bodies:
        if bp.mjname == "world":
            continue
        frozen = frozen_inertia(bp.body)  # a moment of 0: AMBF's body never turns about that axis
        if frozen is not None and _holds(frozen):
            spec.body(bp.mjname).inertia = frozen
            continue
        if frozen is not None:
            # one moment 0, the others not: no rigid body's inertia MuJoCo accepts (A + B >= C), so
            # it refused the whole scene; the file's moments (MuJoCo's floor for the 0) are played
            # (AMBF's body, tilted onto the floor, turns NaN from its first contacts)
            if warn is not None:
                warn(
                    "runner-inertia",
                    f"{bp.body.identifier}: a moment of inertia of 0 beside two that are not: the MuJoCo engine "
                    "cannot hold the body from turning about that axis, and lets it turn",
                    bp.body,
                )
            given = bp.body.inertia
            spec.body(bp.mjname).inertia = np.maximum([given.ix, given.iy, given.iz], MIN_INERTIA)
            continue
        est = estimated_inertia(bp.model, bp.body, pose_to_matrix(inertial_offset(bp.body)))
        if est is not None:
            spec.body(bp.mjname).inertia = np.maximum(est, MIN_INERTIA)


def _holds(moments) -> bool:
    """Whether MuJoCo takes these principal moments (each at most the sum of the other two)."""
    a, b, c = (float(v) for v in moments)
    return a + b >= c and b + c >= a and c + a >= b
