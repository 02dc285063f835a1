"""Low-resolution (collision) meshes made with modifiers, as AMBF's own add-on offered them: a
Decimate modifier per body mesh, shown or hidden in the viewport, removed in one click.

A modifier whose name starts with :data:`PREFIX` makes the low-res mesh only: export writes a
body's visual (high-res) mesh without it and, where the collision is that visual mesh, the
low-res copy with it, whether or not it is shown in the viewport. Other modifiers (a
Solidify, a Subdivision Surface) shape both. The geometry tools measure the high-res mesh.
"""

from __future__ import annotations

from contextlib import contextmanager

import bpy

PREFIX = "ADF low-res"


def modifiers(obj) -> list:
    return [m for m in getattr(obj, "modifiers", ()) if m.name.startswith(PREFIX)]


@contextmanager
def shown(objs, on: bool):
    """While inside, the low-res modifiers of ``objs`` are on (or off) in the viewport, which
    is what Blender's evaluated mesh applies; their settings are restored after."""
    mods = [m for o in objs for m in modifiers(o)]
    before = [m.show_viewport for m in mods]
    changed = any(b != on for b in before)
    try:
        for m in mods:
            m.show_viewport = on
        if changed:
            bpy.context.view_layer.update()
        yield
    finally:
        for m, b in zip(mods, before):
            m.show_viewport = b
        if changed:
            bpy.context.view_layer.update()


def bodies(scene) -> list:
    """The mesh objects whose meshes export writes: bodies, soft bodies and ghosts."""
    return [o for o in scene.objects if o.adf.kind in ("BODY", "SOFT_BODY", "GHOST") and o.type == "MESH"]


def add(scene, max_vertices: int = 150) -> list[str]:
    """A Decimate modifier (collapse) on every body mesh with more than ``max_vertices``
    vertices, its ratio bringing it to about that many; the ones made before are replaced.
    Returns the names of the objects given one."""
    remove(scene)
    done = []
    for o in sorted(bodies(scene), key=lambda o: o.name):
        n = len(o.data.vertices)
        if n <= max_vertices:
            continue
        mod = o.modifiers.new(PREFIX, "DECIMATE")
        mod.decimate_type = "COLLAPSE"
        mod.use_collapse_triangulate = True
        mod.ratio = max_vertices / n
        done.append(o.name)
    return done


def toggle(scene) -> int:
    """Show the low-res modifiers in the viewport if any is hidden, else hide them all;
    returns how many there are."""
    mods = [m for o in bodies(scene) for m in modifiers(o)]
    on = not all(m.show_viewport for m in mods)
    for m in mods:
        m.show_viewport = on
    return len(mods)


def remove(scene) -> int:
    """Remove the low-res modifiers (only those: a Solidify or a Subdivision Surface stays)."""
    n = 0
    for o in bodies(scene):
        for m in modifiers(o):
            o.modifiers.remove(m)
            n += 1
    return n
