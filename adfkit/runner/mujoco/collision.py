"""What the MuJoCo engine collides, from the MJCF writer's model: ADF collision groups as
contype/conaffinity bits (collisions.collision_masks: AMBF's rule), excluded pairs for joints and
models that ignore inter-collision, each body's friction, and a located warning for every
collision shape the writer could not give MuJoCo."""

from __future__ import annotations

import mujoco

from ...converters.urdf import _material
from ...diagnostics import warning
from ...model.semantics import ShapeKind
from ..ambf_bodies import AMBF_MARGIN
from ..collisions import collision_masks, convex_parts_note
from .contacts import ambf_surface

GHOST_GROUP = 4  # a ghost's geoms: never drawn, seen by no ray
#: a ghost's contype under AMBF's rule: bit 31, which no collision group uses (plan.ALL_GROUPS), so it
#: meets no geom, yet MuJoCo puts the geom in its body's collision tree, where the ghosts' collision
#: pass (ghosts._collider_points) finds it once its conaffinity is opened (a geom compiled without
#: bits is left out of that tree and never collides, whatever its bits later)
GHOST_CONTYPE = -(1 << 31)

EXCLUDE_SPARE = 512  # run-time excluded pairs (MujocoWorld.set_collision); the suture turns off ~300
_SHAPE_FEATURES = {f"collision {k.value}" for k in ShapeKind}


def warn_losses(world, m, losses) -> None:
    """The MJCF writer's losses of model ``m`` that change what the engine plays, as located
    warnings (the rest are the converter's business)."""
    for loss in losses:  # the MJCF writer already made a flat collision mesh a thin box (engine_fit)
        if loss.feature == "collision mesh" and "flat" in loss.reason:
            world._warn("runner-flat-mesh", f"{loss.element}: {loss.reason}", m.body(loss.element))
        elif loss.feature == "mesh" and "is not read by" in loss.reason:  # PLY, 3DS: converted or left out
            world._warn("runner-mesh-format", f"{loss.element}: {loss.reason}", m.body(loss.element))
        elif loss.feature == "concave collision mesh":  # the same parts as the PyBullet runner's, said alike
            convex_parts_note(world.diagnostics, m.body(loss.element), loss.reason.split(" (AMBF")[0])
        elif loss.feature in _SHAPE_FEATURES:
            _shape_left_out(world, m, loss)
        elif loss.feature == "collision shape" and "no usable collision primitive" in loss.reason:
            world._warn("runner-no-collision", f"{loss.element}: no usable collision primitive", m.body(loss.element))
        elif loss.feature == "mass" and "PLANE" in loss.reason:  # as the PyBullet runner's runner-plane
            world._warn(
                "runner-plane",
                f"{loss.element}: a PLANE shape on a dynamic body; made static",
                m.body(loss.element),
            )


def _shape_left_out(world, m, loss) -> None:
    """A collision shape the MJCF writer could not write (a plane on a moving body, an unknown
    primitive): the body collides without it, said where the shape is written and in
    ``not_played``."""
    body = m.body(loss.element)
    key = "collision shape" if body is not None and body.collision_shape else "compound collision shape"
    world.diagnostics.append(
        warning(
            "runner-shape-left-out",
            f"{loss.element}: {loss.feature}: {loss.reason}; the MuJoCo engine's body does not collide with it",
            body.where(key) if body is not None else None,
            "give the body a shape MuJoCo collides (a box, sphere, cylinder, capsule or mesh)",
        )
    )
    world.not_played.append({"object": loss.element, "what": loss.feature, "why": loss.reason})


def hull_margin(body) -> float:
    """A mesh geom's contact margin under AMBF's bodies: the body's `collision margin` (AMBF's
    1 mm without it). Bullet collides a hull (and AMBF's other mesh shapes) grown by its margin;
    MuJoCo's contacts come to rest at the pair's margin, so the geom keeps the same distance. A
    box's, cylinder's and capsule's margins lie inside them in Bullet and a sphere's is its radius:
    MuJoCo's primitives keep none. Between two meshes MuJoCo takes the larger margin, where Bullet
    adds the two."""
    m = body.collision_margin
    return float(m) if m is not None and m >= 0 else AMBF_MARGIN


def collision_filters(world, spec, bodies, joints, plans_by_model) -> None:
    """ADF collision groups as contype/conaffinity bits (bodies collide when they share a
    group, as in the PyBullet runner); joints (the tree's and those closing loops) and models
    that ignore inter-collision as excluded body pairs."""
    masks = collision_masks(world, [bp.body for bp in bodies])
    for bp in bodies:
        mask = masks[id(bp.body)]
        fr = bp.body.friction
        geoms = bp.geoms(spec)
        drawn = any(g.group == 1 for g in geoms)
        rgba = _material(bp.body)
        for g in geoms:
            if not drawn and g.group == 3:
                g.group = 0  # no visual shape written: the camera sees the collision shape
                if rgba is not None:
                    g.rgba = rgba

            if (g.contype == 0 and g.conaffinity == 0) or g.group == GHOST_GROUP:
                continue
            g.contype = g.conaffinity = mask
            if world.opt.bodies == "ambf":  # AMBF's surfaces (contacts.ambf_surface)
                ambf_surface(g, fr)
                if g.type == mujoco.mjtGeom.mjGEOM_MESH:
                    g.margin = hull_margin(bp.body)
            elif fr is not None and fr.static is not None:
                g.friction = [fr.static, g.friction[1], fr.rolling if fr.rolling is not None else g.friction[2]]
    pairs = set()
    for j, _kind, parent, child, *_ in joints:
        if j.ignore_inter_collision is not False:
            pairs.add((parent.mjname, child.mjname))
    for m, mine, _tree in plans_by_model:
        if m.ignore_inter_collision:
            bs = list(mine.values())
            for i, a in enumerate(bs):
                for b in bs[i + 1 :]:
                    pairs.add((a.mjname, b.mjname))
    for a, b in sorted(pairs):
        if a != b and "world" not in (a, b):
            spec.add_exclude(bodyname1=a, bodyname2=b)
    # spare slots for MjWorld.set_collision: MuJoCo's excluded pairs are compiled in, so a task
    # that turns a pair off at run time fills a world-world placeholder (a pair that never collides)
    for _ in range(EXCLUDE_SPARE):
        spec.add_exclude(bodyname1="world", bodyname2="world")
