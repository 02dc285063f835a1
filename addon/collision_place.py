"""Where a collision mesh sits relative to its body, as AMBF's own add-on offered it: AMBF reads a
collision mesh file in the body's frame, so a collision mesh object whose origin is not the
body's either moves there (*Move to body origin*: the mesh goes where AMBF will put it) or keeps
where it is seen by baking its offset into its vertices (*Use current location*)."""

from __future__ import annotations

from adfkit.diagnostics import AdfError, SourceLocation, error


def _checked(obj):
    if obj.adf.kind != "COLLISION_MESH" or obj.type != "MESH":
        raise AdfError(
            error(
                "collision-placement",
                f"'{obj.name}' is not a collision mesh",
                SourceLocation(f"blender:{obj.name}"),
                "select a mesh marked Collision mesh (a child of its body)",
            )
        )
    body = obj.parent
    while body is not None and body.adf.kind not in ("BODY", "GHOST", "SOFT_BODY"):
        body = body.parent
    if body is None:
        raise AdfError(
            error(
                "collision-placement",
                f"collision mesh '{obj.name}' is not under a body",
                SourceLocation(f"blender:{obj.name}"),
                "parent it to the body it belongs to",
            )
        )
    return body


def move_to_body_origin(obj) -> None:
    """Put the collision mesh's origin and axes on its body's: its vertices, unchanged, are now
    read in the body's frame, where AMBF puts them."""
    body = _checked(obj)
    world = body.matrix_world.copy()
    obj.matrix_world = world


def use_current_location(obj) -> None:
    """Keep the collision mesh where it is seen, with its origin on its body's: its offset from
    the body is applied to its vertices (the mesh data), then its transform becomes the body's."""
    body = _checked(obj)
    offset = body.matrix_world.inverted() @ obj.matrix_world
    if obj.data.users > 1:
        obj.data = obj.data.copy()  # other objects share the mesh: they stay as they are
    obj.data.transform(offset)
    obj.data.update()
    obj.matrix_world = body.matrix_world.copy()
