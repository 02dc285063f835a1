"""The contact points of a ghost's geom and a geom of its own body in MuJoCo (a PSM's finger
ghost hangs on the jaw it lies in): MuJoCo collides no body with itself, so such a pair never
gets the collider's points, where AMBF's ghost (a body of its own in Bullet) reads its manifold's.
Bullet makes a box-box pair's points at once (btBoxBoxDetector: a box in a box four; AMBF's
contact listing shows each of the challenge PSM's jaws in its finger ghost at four), its other
convex pairs one a collision pass (GJK: the suturing phantom's capsule rims in their hole ghosts
one each, measured, where MuJoCo's capsule-box collider makes two). So a box-box pair is
collided once (it is rigid), by MuJoCo's own collider in a model of the two geoms alone, each
on a body of its own where the scene holds them; any other pair keeps the distance query's one
point."""

from __future__ import annotations

import mujoco
import numpy as np

from ..ghost_rules import MANIFOLD_POINTS

_BOX = int(mujoco.mjtGeom.mjGEOM_BOX)


def rigid_points(m, d, pairs) -> dict[tuple[int, int], int]:
    """{(geom, geom) sorted: penetrating contact points, at most MANIFOLD_POINTS} of each pair
    (geom a, geom b) of two boxes, as MuJoCo's collider makes them with the two geoms where they
    stand now; other pairs are left out."""
    out: dict[tuple[int, int], int] = {}
    for a, b in pairs:
        if int(m.geom_type[a]) != _BOX or int(m.geom_type[b]) != _BOX:
            continue
        spec = mujoco.MjSpec()
        spec.option.gravity = [0.0, 0.0, 0.0]
        for g in (a, b):
            quat = np.zeros(4)
            mujoco.mju_mat2Quat(quat, d.geom_xmat[g])
            body = spec.worldbody.add_body(pos=d.geom_xpos[g].tolist(), quat=quat.tolist())
            body.add_freejoint()
            body.add_geom(
                type=mujoco.mjtGeom(int(m.geom_type[g])),
                size=m.geom_size[g].tolist(),
                contype=1,
                conaffinity=1,
                margin=0.0,
                mass=1.0,
            )
        try:
            model = spec.compile()
        except ValueError:  # MuJoCo refused the pair's model: the distance query's one point stands
            continue
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        n = int(np.count_nonzero(data.contact.dist[: data.ncon] < 0.0))
        if n:
            out[(min(a, b), max(a, b))] = min(n, MANIFOLD_POINTS)
    return out
