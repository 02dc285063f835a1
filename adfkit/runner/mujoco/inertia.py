"""Bodies' inertia in the MuJoCo world as AMBF's btRigidBodies have it, where AMBF's bodies are
asked for (``Options.bodies`` "ambf": ``adfkit run``, ``adfkit parity``)."""

from __future__ import annotations

import numpy as np

from ...converters.mjcf_write import MIN_INERTIA
from ...model.semantics import inertial_offset
from ..ambf_bodies import estimated_inertia, frozen_inertia
from ..rotations import pose_to_matrix


def ambf_inertia(opt, spec, bodies) -> None:
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
        if frozen is not None:
            spec.body(bp.mjname).inertia = frozen
            continue
        est = estimated_inertia(bp.model, bp.body, pose_to_matrix(inertial_offset(bp.body)))
        if est is not None:
            spec.body(bp.mjname).inertia = np.maximum(est, MIN_INERTIA)
