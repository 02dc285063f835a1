"""Procedural meshes of the suturing scene as OBJ text (fixed number formatting, so the files
are byte-identical build after build): boxes with texture coordinates and the needle's wire."""

from __future__ import annotations

import math

import numpy as np


def obj_text(
    vertices, faces, uvs=None, mtllib: str | None = None, material: str | None = None, comment: str = ""
) -> str:
    """OBJ text of one mesh; faces index vertices (and, when given, the same-index uvs) from 0,
    each with its normal (AMBF's OBJ reader needs full triplets: meshwrite.obj_faces)."""
    from ...geometry.meshwrite import obj_faces

    out = [f"# {comment}" if comment else "# written by adfkit"]
    if mtllib:
        out.append(f"mtllib {mtllib}")
    out += [f"v {x:.7f} {y:.7f} {z:.7f}" for x, y, z in np.asarray(vertices, float)]
    if uvs is not None:
        out += [f"vt {u:.5f} {w:.5f}" for u, w in np.asarray(uvs, float)]
    normals, face_lines = obj_faces(vertices, faces, uvs)
    out += normals
    if material:
        out.append(f"usemtl {material}")
    out += face_lines
    return "\n".join(out) + "\n"


def boxes_mesh(boxes, texture_scale: float):
    """One mesh of axis-aligned boxes ((min xyz), (max xyz)), each face with its own four
    vertices and planar texture coordinates (metres / texture_scale)."""
    verts, uvs, faces = [], [], []
    for lo, hi in boxes:
        lo, hi = np.asarray(lo, float), np.asarray(hi, float)
        for axis in range(3):
            for side in (0, 1):
                u_ax, v_ax = [a for a in range(3) if a != axis]
                corners = []
                for cu, cv in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    p = np.empty(3)
                    p[axis] = hi[axis] if side else lo[axis]
                    p[u_ax] = hi[u_ax] if cu else lo[u_ax]
                    p[v_ax] = hi[v_ax] if cv else lo[v_ax]
                    corners.append(p)
                # outward winding: counter-clockwise seen from outside
                normal = np.zeros(3)
                normal[axis] = 1.0 if side else -1.0
                if np.dot(np.cross(corners[1] - corners[0], corners[2] - corners[0]), normal) < 0:
                    corners = corners[::-1]
                base = len(verts)
                for p in corners:
                    verts.append(p)
                    uvs.append((p[u_ax] / texture_scale, p[v_ax] / texture_scale))
                faces += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
    return np.array(verts), np.array(uvs), faces


def arc_wire(
    radius: float, wire: float, start: float, end: float, tip_length: float, segments: int = 72, sides: int = 12
):
    """A closed tube of radius ``wire`` along the circle of ``radius`` (xy plane, centre at the
    origin) from angle ``start`` (blunt, capped) to ``end`` (sharp: the tube narrows to a point
    over the last ``tip_length`` of arc). Returns (vertices, faces)."""
    span = end - start
    arc_len = abs(span) * radius
    verts, faces = [], []
    rings = []
    for i in range(segments + 1):
        t = i / segments
        a = start + span * t
        to_end = (1.0 - t) * arc_len
        rw = wire * min(1.0, to_end / tip_length) if i < segments else 0.0
        centre = np.array([radius * math.cos(a), radius * math.sin(a), 0.0])
        radial = np.array([math.cos(a), math.sin(a), 0.0])
        normal = np.array([0.0, 0.0, 1.0])
        if i == segments:
            rings.append([len(verts)])
            verts.append(centre)
            break
        ring = []
        for j in range(sides):
            phi = 2 * math.pi * j / sides
            ring.append(len(verts))
            verts.append(centre + rw * (math.cos(phi) * radial + math.sin(phi) * normal))
        rings.append(ring)
    # side faces between consecutive rings; orientation fixed below
    for a_ring, b_ring in zip(rings[:-1], rings[1:]):
        for j in range(sides):
            a0, a1 = a_ring[j], a_ring[(j + 1) % sides]
            if len(b_ring) == 1:
                faces.append((a0, a1, b_ring[0]))
            else:
                b0, b1 = b_ring[j], b_ring[(j + 1) % sides]
                faces += [(a0, a1, b1), (a0, b1, b0)]
    cap = len(verts)
    verts.append(np.array([radius * math.cos(start), radius * math.sin(start), 0.0]))
    first = rings[0]
    for j in range(sides):
        faces.append((first[(j + 1) % sides], first[j], cap))
    v = np.array(verts)
    f = np.array(faces)
    # make the winding outward: the signed volume must be positive
    tri = v[f]
    vol = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0
    if vol < 0:
        f = f[:, ::-1]
    return v, [tuple(int(i) for i in row) for row in f]


def cylinder_mesh(radius: float, height: float, centre=(0.0, 0.0, 0.0), sides: int = 24):
    """A closed cylinder along z: (vertices, faces)."""
    cx, cy, cz = centre
    verts = []
    for z in (cz - height / 2, cz + height / 2):
        for j in range(sides):
            a = 2 * math.pi * j / sides
            verts.append((cx + radius * math.cos(a), cy + radius * math.sin(a), z))
    verts += [(cx, cy, cz - height / 2), (cx, cy, cz + height / 2)]
    bottom, top = 2 * sides, 2 * sides + 1
    faces = []
    for j in range(sides):
        k = (j + 1) % sides
        faces += [(j, k, sides + k), (j, sides + k, sides + j), (bottom, k, j), (top, sides + j, sides + k)]
    return np.array(verts), faces


def box_mesh(size, centre=(0.0, 0.0, 0.0)):
    """A closed box: (vertices, faces)."""
    lo = np.asarray(centre, float) - np.asarray(size, float) / 2
    hi = np.asarray(centre, float) + np.asarray(size, float) / 2
    v, _uv, f = boxes_mesh([(lo, hi)], 1.0)
    return v, f
