"""The burr `adfkit drill` drills with, from a body of the scene: a body with a sphere shape
(its radius, at its origin), or a drill whose shape is a mesh, as the drilling projects ship
theirs (``1mm.OBJ`` ... ``6mm.OBJ``: a shaft ending in a round burr). For a mesh the burr is
a sphere fitted to its tip: the end of the mesh's long axis nearer the body's origin (AMBF's
drilling plugin holds the burr at the drill body's origin), the largest run of vertices from
that end that a sphere fits within 2 % of its radius. ``--burr-radius`` gives the radius
instead (the sphere then touches the tip's end), as a drill whose tip is not round needs.
What was used is said (``Burr.how``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...adf.paths import collision_mesh_path, uses_collision_mesh, visual_mesh_path
from ...diagnostics import AdfError, error

#: a fitted sphere is accepted when its vertices lie this close to it (a fraction of the radius)
FIT_TOLERANCE = 0.02


@dataclass
class Burr:
    body: object  # the ADF Body
    model: object  # its ModelFile
    radius: float  # m
    centre_in_body: np.ndarray  # (3,) m in the body's frame
    how: str  # what the sphere is: "its sphere shape", "a sphere fitted to the tip of 6mm.OBJ ..."


def _shape(body) -> str:
    return (body.collision_shape or body.shape or "").lower()


def _sphere_radius(body) -> float | None:
    geo = body.collision_geometry if body.collision_shape else body.geometry
    if _shape(body) == "sphere" and geo is not None and geo.radius:
        return float(geo.radius) * (body.scale if body.scale is not None else 1.0)
    return None


def mesh_path(model, body):
    """The mesh a drill body is drawn with (the finer one, where the burr's shape is), else the
    one it collides with."""
    import os

    if body.shape or body.compound_shape:
        return None
    visual = visual_mesh_path(model, body)
    if visual is not None and os.path.lexists(visual):
        return visual
    if uses_collision_mesh(body) and collision_mesh_path(model, body) is not None:
        return collision_mesh_path(model, body)
    return visual


def fit_sphere(points: np.ndarray) -> tuple[np.ndarray, float, float]:
    """(centre, radius, rms distance from the sphere) of the least-squares sphere through ``points``."""
    a = np.column_stack([2 * points, np.ones(len(points))])
    b = (points**2).sum(axis=1)
    sol, *_ = np.linalg.lstsq(a, b, rcond=None)
    centre = sol[:3]
    radius = float(np.sqrt(max(sol[3] + centre @ centre, 0.0)))
    rms = float(np.sqrt(np.mean((np.linalg.norm(points - centre, axis=1) - radius) ** 2)))
    return centre, radius, rms


def tip_sphere(verts: np.ndarray, radius: float | None = None) -> tuple[np.ndarray, float, str]:
    """(centre, radius, how) of the burr at the tip of a drill mesh (body frame, metres)."""
    c = verts.mean(axis=0)
    _, _, vt = np.linalg.svd(verts - c, full_matrices=False)
    axis = vt[0]
    proj = (verts - c) @ axis
    lo, hi = float(proj.min()), float(proj.max())
    origin = float(-c @ axis)  # the body's origin along the axis
    if abs(origin - lo) > abs(origin - hi):  # the tip is the end nearer the origin
        axis, proj, lo, hi = -axis, -proj, -hi, -lo
    from_end = proj - lo
    length = hi - lo
    if radius is not None:
        tip = c + lo * axis
        return tip + radius * axis, radius, f"a sphere of --burr-radius {radius:g} m touching the tip's end"
    best = None
    for reach in np.geomspace(max(length * 1e-3, 1e-9), length * 0.25, 48):
        sel = from_end <= reach
        if sel.sum() < 8:
            continue
        centre, r, rms = fit_sphere(verts[sel])
        good = r > 0 and rms <= FIT_TOLERANCE * r and reach >= 0.8 * r and (centre - c) @ axis - lo <= 1.5 * r
        if good:
            best = (centre, r, rms, int(sel.sum()))
        elif best is not None:
            break
    if best is None:
        raise ValueError("not round")
    centre, r, rms, n = best
    return centre, r, f"a sphere fitted to the tip of its mesh ({n} vertices within {rms * 1e6:.1f} µm rms)"


def _candidates(scene) -> list[tuple[object, object]]:
    return [(m, b) for m in scene.models for b in m.bodies if b.defined]


def _names(b) -> set:
    return {b.identifier, b.name, b.identifier.removeprefix("BODY ")}


def _from_body(model, body, radius: float | None) -> Burr:
    r = _sphere_radius(body)
    if r is not None:
        return Burr(body, model, r if radius is None else radius, np.zeros(3), "its sphere shape")
    path = mesh_path(model, body)
    who = body.identifier
    if path is None:
        kind = body.shape or body.collision_shape or (body.compound_shape and "compound") or None
        what = f"is a {kind}" if kind else "has no shape or mesh"
        raise AdfError(
            error(
                "drill-burr",
                f"the body {who!r} exists but {what}, not a sphere or a drill mesh with a tip",
                body.source,
                "drill with a body with a sphere shape, or one drawn with a drill mesh",
            )
        )
    from ...geometry.meshio import load_mesh

    scale = body.scale if body.scale is not None else 1.0
    mesh = load_mesh(path, scale, getattr(model, "tree", None), body.where("mesh") or body.source)
    try:
        centre, r, how = tip_sphere(np.asarray(mesh.vertices, dtype=float), radius)
    except ValueError:
        raise AdfError(
            error(
                "drill-burr",
                f"the body {who!r} is a mesh ({path.name}) whose tip no sphere fits within "
                f"{FIT_TOLERANCE:.0%} of its radius",
                body.source,
                "give --burr-radius R to drill with a sphere of radius R at its tip",
            )
        ) from None
    return Burr(body, model, r, centre, how.replace("its mesh", path.name))


def find_burr(scene, name: str | None, radius: float | None = None) -> Burr:
    """The burr: the body ``name`` names (a sphere shape, or a drill mesh); without a name, the
    sphere body whose name holds 'burr', else the only sphere body, else the only body whose
    name holds 'drill' or 'burr', else the only body drawn with a mesh."""
    bodies = _candidates(scene)
    if name:
        hit = [(m, b) for m, b in bodies if name in _names(b)]
        if len(hit) != 1:
            listed = ", ".join(sorted(b.identifier for _, b in bodies)) or "none"
            raise AdfError(
                error(
                    "drill-burr",
                    f"{len(hit)} bodies are named {name!r} (the scene's bodies: {listed})",
                    None,
                    "name the burr's body with --burr NAME",
                )
            )
        return _from_body(*hit[0], radius)
    spheres = [(m, b) for m, b in bodies if _sphere_radius(b) is not None]
    pick = [s for s in spheres if "burr" in (s[1].name or s[1].identifier).lower()] or spheres
    if not pick:
        pick = [(m, b) for m, b in bodies if any(w in (b.name or b.identifier).lower() for w in ("drill", "burr"))]
    if not pick:
        pick = [(m, b) for m, b in bodies if mesh_path(m, b) is not None]
    if len(pick) != 1:
        listed = ", ".join(b.identifier for _, b in pick or bodies) or "none"
        raise AdfError(
            error(
                "drill-burr",
                f"no single burr: {len(pick)} candidate bodies ({listed})",
                None,
                "name the burr's body with --burr NAME (a sphere, or a drill mesh whose tip is the burr)",
            )
        )
    return _from_body(*pick[0], radius)


__all__ = ["Burr", "find_burr", "fit_sphere", "tip_sphere"]
