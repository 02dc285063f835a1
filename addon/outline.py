"""Wire outlines of collision primitives: a COLLISION_SHAPE object is a mesh shown as a wire
whose vertices are rebuilt from its ADF shape, size, radius, height and axis whenever one of
them changes (the properties' update callback), so what the user sees is what AMBF collides."""

from __future__ import annotations

import math

SEGMENTS = 24


def _ring(radius: float, z: float, n: int = SEGMENTS) -> list[tuple[float, float, float]]:
    return [(radius * math.cos(2 * math.pi * i / n), radius * math.sin(2 * math.pi * i / n), z) for i in range(n)]


def _tube(rings: list[list[tuple]], caps: bool = True) -> tuple[list, list]:
    """Vertices and faces of stacked rings joined by quads (with flat end caps)."""
    verts, faces = [], []
    for r in rings:
        verts.extend(r)
    n = len(rings[0])
    for k in range(len(rings) - 1):
        a, b = k * n, (k + 1) * n
        faces += [(a + i, a + (i + 1) % n, b + (i + 1) % n, b + i) for i in range(n)]
    if caps:
        faces.append(tuple(range(n - 1, -1, -1)))
        last = (len(rings) - 1) * n
        faces.append(tuple(range(last, last + n)))
    return verts, faces


def shape_geometry(shape: str, size, radius: float, height: float) -> tuple[list, list]:
    """(vertices, faces) of a primitive along +Z, centred at the origin (ADF conventions:
    box full edges, cylinder/cone/capsule total height, cone apex at +height/2)."""
    if shape == "BOX":
        x, y, z = (s / 2 for s in size)
        verts = [(sx * x, sy * y, sz * z) for sz in (-1, 1) for sy in (-1, 1) for sx in (-1, 1)]
        faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
        return verts, faces
    if shape == "CYLINDER":
        return _tube([_ring(radius, -height / 2), _ring(radius, height / 2)])
    if shape == "CONE":
        verts = _ring(radius, -height / 2) + [(0.0, 0.0, height / 2)]
        n = SEGMENTS
        faces = [tuple(range(n - 1, -1, -1))] + [(i, (i + 1) % n, n) for i in range(n)]
        return verts, faces
    # sphere and capsule: latitude rings (a capsule's two hemispheres apart by height - 2r)
    half = max(height / 2 - radius, 0.0) if shape == "CAPSULE" else 0.0
    rings = []
    lat = 8
    for k in range(1, lat):
        phi = math.pi * k / lat - math.pi / 2  # -90°..90° exclusive of the poles
        z = radius * math.sin(phi)
        z += half if phi > 0 else (-half if phi < 0 else 0.0)
        rings.append(_ring(radius * math.cos(phi), z))
    if shape == "CAPSULE" and half > 0:
        mid = lat // 2 - 1
        rings = rings[:mid] + [_ring(radius, -half), _ring(radius, half)] + rings[mid + 1 :]
    verts, faces = _tube(rings, caps=False)
    n = SEGMENTS
    bottom, top = len(verts), len(verts) + 1
    verts += [(0.0, 0.0, -radius - half), (0.0, 0.0, radius + half)]
    last = (len(rings) - 1) * n
    faces += [((i + 1) % n, i, bottom) for i in range(n)] + [(last + i, last + (i + 1) % n, top) for i in range(n)]
    return verts, faces


AXIS_SWAP = {"x": lambda v: (v[2], v[0], v[1]), "y": lambda v: (v[1], v[2], v[0]), "z": lambda v: v}


def outline_vertices(shape: str, size, radius: float, height: float, axis: str = "z") -> tuple[list, list]:
    verts, faces = shape_geometry(shape, size, radius, height)
    if shape != "BOX" and shape != "SPHERE":
        swap = AXIS_SWAP[(axis or "z").lower()]
        verts = [swap(v) for v in verts]
    return verts, faces


def update_outline(obj) -> None:
    """Rebuild a collision primitive object's wire mesh from its ADF shape settings."""
    if obj is None or obj.adf.kind != "COLLISION_SHAPE":
        return
    s = obj.adf.shape
    if obj.type != "MESH":  # an Empty from an older file: scale its display instead
        obj.empty_display_type = "SPHERE" if s.shape == "SPHERE" else "CUBE"
        obj.empty_display_size = max(max(s.size) / 2 if s.shape == "BOX" else max(s.radius, s.height / 2), 1e-4)
        return
    verts, faces = outline_vertices(s.shape, tuple(s.size), s.radius, s.height, s.axis)
    me = obj.data
    me.clear_geometry()
    me.from_pydata(verts, [], faces)
    me.update()
