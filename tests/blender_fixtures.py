"""What the add-on tests build their scenes from (the ``addon`` and ``scene`` fixtures are in
conftest.py): a named cube."""

from __future__ import annotations

import bpy


def cube(name, size=0.05, location=(0, 0, 0)):
    """A cube object of edge ``size`` m at ``location``, its object and its mesh called ``name``."""
    bpy.ops.mesh.primitive_cube_add(size=size, location=location)
    o = bpy.context.active_object
    o.name = o.data.name = name
    return o
