"""ADF volumes in the PyBullet world: each volume's iso-surface (decided engine-neutrally in
adfkit.runner.volumes) as a static body, visual and concave collision, at the volume's
location, in its colour, in the camera images and the segmentation with a label of its own
(it joins ``world.bodies``)."""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ..rotations import matrix_to_pq
from ..volumes import volume_surfaces
from .bodies import make_sim_body


def build_volumes(world, models) -> None:
    """Add each model's volumes to ``world`` (a SimWorld) as static iso-surface bodies."""
    for vs in volume_surfaces(world, models):
        sb = make_sim_body(vs.key, vs.body, vs.model)
        pos, orn = matrix_to_pq(vs.pose)
        flat_v = np.asarray(vs.vertices, dtype=float).tolist()
        flat_f = np.asarray(vs.faces, dtype=int).reshape(-1).tolist()
        col = pb.createCollisionShape(
            pb.GEOM_MESH,
            vertices=flat_v,
            indices=flat_f,
            flags=pb.GEOM_FORCE_CONCAVE_TRIMESH,
            physicsClientId=world.cid,
        )
        vis = pb.createVisualShape(
            pb.GEOM_MESH, vertices=flat_v, indices=flat_f, rgbaColor=list(vs.rgba), physicsClientId=world.cid
        )
        sb.uid = pb.createMultiBody(0.0, col, vis, pos, orn, physicsClientId=world.cid)
        sb.cid, sb.link = world.cid, -1
        sb.ref_in_body = np.eye(4)
        sb.body_world_matrix = vs.pose
        sb._parts = None  # no ADF collision parts: the iso-surface mesh is its collision
        sb.surface = vs.surface  # what a viewer draws of it (its own frame)
        world.bodies.append(sb)
        world.volumes.append(vs.report)
