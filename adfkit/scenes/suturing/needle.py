"""The curved suture needle: a procedural wire mesh (the challenge needle's radius and 3/8 arc,
a sharp tip, a blunt tail where the thread is fixed) and its compound convex collision.

The collision hulls come from CoACD (adfkit.geometry) once and are committed as
``data/NeedleCollision.OBJ``, so a build is quick and byte-identical; ``needle_hulls_text``
re-runs the decomposition (``refresh=True``) when the mesh or the parameters change.
"""

from __future__ import annotations

import math
from pathlib import Path

from ...model import RGBA, Body, Friction, Inertia, VelocityDamping
from . import layout as L
from .frames import pose, r, rot_z, translation
from .meshes import arc_wire, obj_text

DATA = Path(__file__).with_name("data")
HULLS_FILE = DATA / "NeedleCollision.OBJ"
TIP_LENGTH = 0.003  # m of arc over which the wire narrows to the point
MASS = 0.5  # kg, as the challenge's needle (its heavy mass keeps the thread taut)
STEEL = RGBA(r=0.8, g=0.8, b=0.82, a=1.0)
#: CoACD settings for the needle: tight hulls along a thin curved wire
HULL_THRESHOLD = 0.03
HULL_MAX = 16


def needle_mesh():
    """(vertices, faces) of the needle in its own frame: the arc in the xy plane around the
    origin, from the tail at NEEDLE_TAIL_ANGLE to the tip at NEEDLE_TIP_ANGLE."""
    return arc_wire(L.NEEDLE_RADIUS, L.NEEDLE_WIRE, L.NEEDLE_TAIL_ANGLE, L.NEEDLE_TIP_ANGLE, TIP_LENGTH)


def needle_obj_text() -> str:
    v, f = needle_mesh()
    return obj_text(
        v,
        f,
        mtllib="Needle.mtl",
        material="steel",
        comment="suture needle: 3/8 circle of radius 9.4 mm, wire 1 mm, written by adfkit",
    )


def needle_mtl_text() -> str:
    return "newmtl steel\nKa 0.2 0.2 0.2\nKd 0.800 0.800 0.820\nKs 0.9 0.9 0.9\nNs 200\nd 1\n"


def needle_hulls_text(refresh: bool = False) -> tuple[str, str]:
    """(OBJ, MTL) text of the committed hulls, or (``refresh``) of a fresh CoACD decomposition
    of needle_mesh(): one object and material per hull, the layout AMBF and the runner read as
    one convex shape each (adfkit.geometry.decompose)."""
    if not refresh and HULLS_FILE.is_file():
        return HULLS_FILE.read_text(), HULLS_FILE.with_suffix(".mtl").read_text()
    import trimesh

    from ...geometry.decompose import DecompositionParams, decompose, hulls_obj_text

    v, f = needle_mesh()
    d = decompose(
        trimesh.Trimesh(v, f, process=False),
        DecompositionParams(threshold=HULL_THRESHOLD, max_hulls=HULL_MAX, preprocess="off"),
    )
    obj, mtl = hulls_obj_text(d.hulls, "NeedleCollision.mtl")
    # vertices at fixed precision: small, and the same text on every machine
    lines = []
    for line in obj.splitlines():
        if line.startswith("v "):
            x, y, z = (float(t) for t in line.split()[1:4])
            line = f"v {x:.7f} {y:.7f} {z:.7f}"
        lines.append(line)
    return "\n".join(lines) + "\n", mtl + "\n"


def needle_body(world) -> Body:
    """The needle at pose ``world`` (4x4): mass and inertia of a thin ring arc about its COM."""
    rad, arc = L.NEEDLE_RADIUS, L.NEEDLE_ARC
    mid = (L.NEEDLE_TAIL_ANGLE + L.NEEDLE_TIP_ANGLE) / 2
    # centroid of a circular arc: at r·sin(a/2)/(a/2) from the centre along the bisector
    c = rad * math.sin(arc / 2) / (arc / 2)
    com = (c * math.cos(mid), c * math.sin(mid), 0.0)
    # ring arc about the centre: Iz = m r^2; about the bisector and its normal (half-angle h):
    h = arc / 2
    i_bis = MASS * rad * rad / 2 * (1 - math.sin(2 * h) / (2 * h))
    i_perp = MASS * rad * rad / 2 * (1 + math.sin(2 * h) / (2 * h))
    # shift to the COM (parallel axis), principal axes: along the bisector (x'), across it (y'), z
    i_x = i_bis
    i_y = i_perp - MASS * c * c
    i_z = MASS * rad * rad - MASS * c * c
    return Body(
        identifier="BODY Needle",
        name="Needle",
        mass=MASS,
        location=pose(world),
        inertia=Inertia(ix=r(i_x), iy=r(i_y), iz=r(i_z)),
        inertial_offset=pose(translation(*com) @ rot_z(mid)),
        mesh="Needle.OBJ",
        collision_mesh="NeedleCollision.OBJ",
        collision_mesh_type="CONVEX_HULL",
        collision_margin=0.0001,
        friction=Friction(static=0.5, rolling=0.0),
        restitution=0.0,
        damping=VelocityDamping(linear=0.9, angular=0.9),
        passive=False,
    )


__all__ = ["needle_mesh", "needle_obj_text", "needle_hulls_text", "needle_body", "HULLS_FILE"]
