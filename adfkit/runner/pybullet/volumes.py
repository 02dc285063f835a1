"""ADF volumes in the PyBullet world: each volume's iso-surface (adfkit.geometry.volume) as a
static body, visual and concave collision, at the volume's location, in its colour, in the
camera images and the segmentation with a label of its own (it joins ``world.bodies``).

What of a volume is not played is listed, never dropped: its ``shaders`` (the runner draws
the iso-surface, not AMBF's ray-marched volume), a ``parent`` (the volume stays where its
location puts it), a volume whose slices cannot be read (the reason, located)."""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ...diagnostics import AdfError
from ...model import Body
from ...model.semantics import pose_or_identity
from ..names import merge_namespace
from ..plan import rgba
from ..rotations import matrix_to_pq, pose_to_matrix
from .bodies import make_sim_body

BONE = [0.93, 0.89, 0.78, 1.0]


def not_played_parts(vol) -> list[dict]:
    out = []
    if vol.shaders is not None:
        out.append(
            {
                "object": vol.identifier,
                "what": "shaders",
                "why": "the runner draws the iso-surface as a mesh, not AMBF's ray-marched volume",
            }
        )
    if vol.parent:
        out.append(
            {
                "object": vol.identifier,
                "what": "parent",
                "why": f"not followed: the volume stays where its location puts it (parent {vol.parent!r})",
            }
        )
    return out


def build_volumes(world, models) -> None:
    """Add each model's volumes to ``world`` (a SimWorld) as static iso-surface bodies."""
    from ...geometry.volume import iso_surface, load_volume

    for m in models:
        ns = m.namespace or ""
        for vol in m.volumes:
            if not vol.defined:
                continue
            try:
                data = load_volume(m, vol)
                verts, faces = iso_surface(data, vol.iso_surface_value)
            except AdfError as exc:
                for d in exc.diagnostics:
                    world._warn(
                        "runner-volume", f"{d.message}; the volume is not played", vol, d.hint or "fix the slices"
                    )
                world.not_played.append({"object": vol.identifier, "what": "volume", "why": exc.diagnostics[0].message})
                continue
            world.not_played.extend(not_played_parts(vol))
            if len(faces) == 0:
                world._warn(
                    "runner-volume",
                    f"{vol.identifier}: no voxel reaches the iso-surface value "
                    f"{vol.iso_surface_value if vol.iso_surface_value is not None else 0.5}; nothing to draw",
                    vol,
                    "lower `iso-surface value` (a fraction of full scale)",
                )
                world.not_played.append({"object": vol.identifier, "what": "volume", "why": "empty iso-surface"})
                continue
            body = Body(
                identifier=vol.identifier,
                name=vol.name or vol.identifier.removeprefix("VOLUME "),
                mass=0.0,
                location=pose_or_identity(vol.location),
                source=vol.source,
            )
            sb = make_sim_body(merge_namespace(ns, vol.namespace) + vol.identifier, body, m)
            pose = pose_to_matrix(pose_or_identity(vol.location))
            pos, orn = matrix_to_pq(pose)
            flat_v = np.asarray(verts, dtype=float).tolist()
            flat_f = np.asarray(faces, dtype=int).reshape(-1).tolist()
            col = pb.createCollisionShape(
                pb.GEOM_MESH,
                vertices=flat_v,
                indices=flat_f,
                flags=pb.GEOM_FORCE_CONCAVE_TRIMESH,
                physicsClientId=world.cid,
            )
            vis = pb.createVisualShape(
                pb.GEOM_MESH, vertices=flat_v, indices=flat_f, rgbaColor=rgba(vol) or BONE, physicsClientId=world.cid
            )
            sb.uid = pb.createMultiBody(0.0, col, vis, pos, orn, physicsClientId=world.cid)
            sb.cid, sb.link = world.cid, -1
            sb.ref_in_body = np.eye(4)
            sb.body_world_matrix = pose
            sb._parts = None  # no ADF collision parts: the iso-surface mesh is its collision
            sb.surface = (
                np.asarray(verts, dtype=np.float32),
                np.asarray(faces, dtype=np.uint32),
                tuple(rgba(vol) or BONE),
            )  # what a viewer draws of it (its own frame)
            world.bodies.append(sb)
            world.volumes.append(
                {
                    "object": vol.identifier,
                    "key": sb.key,
                    "voxels": list(data.voxels.shape[::-1]),
                    "dimensions_m": data.dimensions.tolist(),
                    "triangles": int(len(faces)),
                    "iso_surface_value": vol.iso_surface_value if vol.iso_surface_value is not None else 0.5,
                }
            )
