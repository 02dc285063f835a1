"""What collides with what, the same way in every engine: AMBF's collision groups as bit masks
(and the floors they let bodies through), the moving concave meshes played as convex parts
(``geometry.concave``), and the bodies whose concave mesh an engine takes the convex hull of
where that hull starts inside another body."""

from __future__ import annotations

from ..diagnostics import info, warning
from ..model.semantics import ShapeKind, collision_primitives, concave_mesh, effective_mass
from .plan import ALL_GROUPS, mesh_key

GROUP_BITS = 31


def collision_masks(world, bodies) -> dict[int, int]:
    """{id(ADF body): its collision bits} for ``bodies`` (ADF bodies), AMBF's collision groups
    (afFramework.cpp, buildCollisionGroups; checked in AMBF): two bodies that both have groups
    collide only when they share one; a body with none (`collision groups` absent or `[]`)
    collides with every body, so a floor written `collision groups: []` holds them all. A group
    is one bit of ``GROUP_BITS``, a body without groups has them all, and the engines collide a
    pair whose bits meet. Past ``GROUP_BITS`` groups two groups share a bit, so their bodies
    collide where AMBF's would not: a located ``runner-groups`` warning at the first such body."""
    bodies = list(bodies)
    groups = sorted({g for b in bodies for g in _groups(b)})
    bit = {g: 1 << (i % GROUP_BITS) for i, g in enumerate(groups)}
    out = {}
    for b in bodies:
        mask = 0
        for g in _groups(b):
            mask |= bit[g]
        out[id(b)] = mask or ALL_GROUPS
    _floors_passed(world, bodies, out)
    if len(groups) > GROUP_BITS:
        first = next(b for b in bodies if groups[GROUP_BITS] in _groups(b))
        world._warn(
            "runner-groups",
            f"{len(groups)} collision groups, more than the {GROUP_BITS} an engine's collision bits hold: "
            f"group {groups[GROUP_BITS]} shares a bit with group {groups[0]}, so their bodies collide where AMBF's "
            "do not",
            first,
            f"use at most {GROUP_BITS} distinct collision groups in one scene",
        )
    return out


def convex_stand_in(model, body, diagnostics: list):
    """The convex parts a moving body's concave collision mesh is played as in every engine
    (``geometry.concave.body_parts``), said as ``runner-convex-parts`` at the mesh; None where
    its hull per sub-mesh stands in (or the body is static, primitive, not concave)."""
    from ..geometry.concave import body_parts

    parts = body_parts(model, body)
    if parts is not None:
        convex_parts_note(diagnostics, body, parts.describe())
    return parts


def convex_parts_note(diagnostics: list, body, what: str) -> None:
    """The located ``runner-convex-parts`` note (``what``: ConvexParts.describe)."""
    diagnostics.append(
        info(
            "runner-convex-parts",
            f"{body.identifier}: its concave collision mesh {what}, standing in for the triangles AMBF collides",
            mesh_key(body),
            "to choose the parts, decompose the mesh yourself (adfkit decompose) and give `collision mesh type: "
            "CONVEX_HULL`",
        )
    )


def one_hull(sb) -> bool:
    """The engine body ``sb`` collides its concave mesh as the hull of each sub-mesh: not a
    moving mesh played as convex parts (``convex_stand_in``; its decision is remembered)."""
    from ..geometry.concave import body_parts

    return concave_mesh(sb.body) and body_parts(sb.model, sb.body) is None


#: deeper than this at the start, two bodies' shapes overlap (not a body resting on another)
HULL_OVERLAP = 0.002  # m


def hull_overlaps(world, pairs: dict, engine: str) -> None:
    """Each pair of bodies whose collision shapes overlap at the start by more than HULL_OVERLAP
    where one collides as the convex hull of a concave mesh (``pairs``: {(hull body, other body):
    depth, m}, engine bodies): the hollow it was made for is solid to the engine (puzzle1's torus
    starts 19 cm inside its peg's hull in MuJoCo and is flung off), said at the hull body's mesh and
    listed in ``not_played``."""
    for (hull, other), depth in sorted(pairs.items(), key=lambda kv: -kv[1]):
        b = hull.body
        why = (
            f"the {engine} engine collides its mesh as a convex hull, which starts {depth * 1e3:.0f} mm inside "
            f"{other.key}'s collision shape: what is hollow in it is solid here, and the two are pushed apart"
        )
        world.diagnostics.append(
            warning(
                "runner-hull-overlap",
                f"{b.identifier}: {why}",
                mesh_key(b),
                "decompose the mesh into convex parts (adfkit decompose, or the add-on's Generate convex collision)",
            )
        )
        world.not_played.append({"object": b.identifier, "what": "concave collision", "why": why})


def _floors_passed(world, bodies, masks) -> None:
    """A floor (a PLANE) with collision groups holds only the bodies that share one (or have
    none); each one whose dynamic bodies fall through it, as in AMBF, is named at its groups."""
    for floor in bodies:
        if not _groups(floor) or not any(p.kind is ShapeKind.PLANE for p in collision_primitives(floor) or []):
            continue
        passed = [
            b.identifier
            for b in bodies
            if b is not floor and effective_mass(b) > 0 and not masks[id(b)] & masks[id(floor)]
        ]
        if passed:
            world.diagnostics.append(
                warning(
                    "runner-floor-groups",
                    f"{floor.identifier}: its collision groups {_groups(floor)} share none with "
                    f"{', '.join(passed[:5])}{' ...' if len(passed) > 5 else ''}: they fall through it, as in AMBF",
                    floor.where("collision groups"),
                    "give the floor `collision groups: []` to hold every body, or add their group to it",
                )
            )


def _groups(body) -> list[int]:
    """The body's collision groups AMBF keeps (0-999; it warns about and drops the others)."""
    return [g for g in (body.collision_groups or []) if isinstance(g, int) and 0 <= g <= 999]
