"""ADF volumes in the PyBullet world: each volume's iso-surface (decided engine-neutrally in
adfkit.runner.volumes) as a static body, visual and concave collision, at the volume's
location, in its colour, in the camera images and the segmentation with a label of its own
(it joins ``world.bodies``).

PyBullet refuses a mesh of more than 131,072 vertices or 524,288 indices, and a real skull's
surface has several times that: the surface is cut into pieces within both limits
(geometry.surface_parts.split_surface), the first the body's base and the others fixed links of
the same multibody (``SimBody.piece_links``), each colliding as a concave triangle mesh, so
the contact is on the surface itself wherever it is touched; the body meets every collision
group, as a floor does."""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ...geometry.surface_parts import PYBULLET_MAX_FACES, PYBULLET_MAX_VERTICES, split_surface
from ..plan import ALL_GROUPS
from ..rotations import matrix_to_pq
from ..volumes import volume_surfaces
from .bodies import make_sim_body


def _shapes(world, verts: np.ndarray, faces: np.ndarray, rgba) -> tuple[int, int]:
    flat_v = np.asarray(verts, dtype=float).tolist()
    flat_f = np.asarray(faces, dtype=int).reshape(-1).tolist()
    col = pb.createCollisionShape(
        pb.GEOM_MESH, vertices=flat_v, indices=flat_f, flags=pb.GEOM_FORCE_CONCAVE_TRIMESH, physicsClientId=world.cid
    )
    vis = pb.createVisualShape(
        pb.GEOM_MESH, vertices=flat_v, indices=flat_f, rgbaColor=list(rgba), physicsClientId=world.cid
    )
    return col, vis


def build_volumes(world, models) -> None:
    """Add each model's volumes to ``world`` (a SimWorld) as static iso-surface bodies."""
    from .bodies import SimBody

    for vs in volume_surfaces(world, models, SimBody):
        sb = make_sim_body(vs.key, vs.body, vs.model)
        pose = vs.location if vs.parent is None else vs.parent.world_matrix() @ vs.location
        if vs.parent is not None and not vs.parent.static:
            world._warn(
                "runner-volume",
                f"{vs.volume.identifier}: placed where its parent {vs.parent.name!r} starts; PyBullet collides "
                "with a triangle mesh only on a static body, so it does not follow the parent when it moves",
                vs.volume,
                "give the parent no mass, or play the scene with --engine mujoco",
            )
            world.not_played.append(
                {"object": vs.volume.identifier, "what": "moving parent", "why": "PyBullet: a static triangle mesh"}
            )
        pos, orn = matrix_to_pq(pose)
        pieces = split_surface(vs.vertices, vs.faces, PYBULLET_MAX_VERTICES, PYBULLET_MAX_FACES)
        shapes = [_shapes(world, v, f, vs.rgba) for v, f in pieces]
        k = len(shapes) - 1
        sb.uid = pb.createMultiBody(
            0.0,
            shapes[0][0],
            shapes[0][1],
            pos,
            orn,
            linkMasses=[0.0] * k,
            linkCollisionShapeIndices=[c for c, _ in shapes[1:]],
            linkVisualShapeIndices=[v for _, v in shapes[1:]],
            linkPositions=[[0.0, 0.0, 0.0]] * k,
            linkOrientations=[[0.0, 0.0, 0.0, 1.0]] * k,
            linkInertialFramePositions=[[0.0, 0.0, 0.0]] * k,
            linkInertialFrameOrientations=[[0.0, 0.0, 0.0, 1.0]] * k,
            linkParentIndices=[0] * k,
            linkJointTypes=[pb.JOINT_FIXED] * k,
            linkJointAxis=[[0.0, 0.0, 1.0]] * k,
            physicsClientId=world.cid,
        )
        sb.cid, sb.link = world.cid, -1
        sb.piece_links = tuple(range(k))
        for link in (-1, *sb.piece_links):
            pb.setCollisionFilterGroupMask(sb.uid, link, ALL_GROUPS, ALL_GROUPS, physicsClientId=world.cid)
        sb.ref_in_body = np.eye(4)
        sb.body_world_matrix = pose
        sb._parts = None  # no ADF collision parts: the iso-surface mesh is its collision
        vs.solid = None  # (what MuJoCo makes its convex parts of)
        sb.surface = vs.surface  # what a viewer draws of it (its own frame)
        sb.key = world.registry.add(vs.key, sb)  # world.body("VOLUME ...") finds it, as in MuJoCo
        world.bodies.append(sb)
        vs.report["pieces"] = len(pieces)
        world.volumes.append(vs.report)
