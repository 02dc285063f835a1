"""A static tissue body's concave collision mesh read as its triangles (adfkit/tasks/mesh_distance.py),
as AMBF and PyBullet collide it, in the planner's clearance and the check before the run: the
same distances as the collision primitives it was made from, on both sides of the surface; its
convex hull (as MuJoCo collides it) fills the channels."""

from __future__ import annotations

import math

import numpy as np
import pytest
from suture_phantoms import phantom_file

from adfkit.adf import read_file
from adfkit.scenes.suturing.own_phantom import _Placed
from adfkit.tasks.clearance import Tissue
from adfkit.tasks.mesh_distance import TriangleMeshes


def _points(n=6000, seed=0):
    """Points over the generated phantom, from under its slab to above its ridge."""
    rng = np.random.default_rng(seed)
    lo, hi = np.array([-0.03, -0.04, -0.005]), np.array([0.03, 0.04, 0.03])
    return lo + rng.random((n, 3)) * (hi - lo)


def _phantoms(tmp_path):
    """The tissue of a generated phantom by its box primitives, and the same body with its
    primitives taken away: it collides as its mesh (the boxes' OBJ), read as triangles and as hulls."""
    path = phantom_file(tmp_path, pairs=2, spacing=0.012)
    doc, _ = read_file(path, "model")
    body = next(b for b in doc.bodies if b.name == "Phantom")
    boxes = Tissue([_Placed(body, doc)])
    body.compound_collision_shape = None
    return boxes, Tissue([_Placed(body, doc)]), Tissue([_Placed(body, doc)], triangles=False)


def test_a_mesh_of_boxes_reads_as_the_boxes_it_was_made_of(tmp_path):
    """The phantom's OBJ (a slab and ridge blocks, each a closed box standing on the slab) gives
    the boxes' signed distance everywhere, inside them too; its hull does not (6 mm off in the
    channels, which it fills)."""
    boxes, tris, hulls = _phantoms(tmp_path)
    assert not tris.hulls and len(tris.meshes) == 1 and tris.meshes[0].closed
    pts = _points()
    want = boxes.exact(pts, pts.mean(axis=0), 0.2)
    got = tris.exact(pts, pts.mean(axis=0), 0.2)
    assert (want < 0).sum() > 500 and (want > 0).sum() > 500  # both sides are asked
    assert np.abs(got - want).max() < 1e-12
    assert np.abs(hulls.exact(pts, pts.mean(axis=0), 0.2) - want).max() > 0.005


def _one_surface():
    """The phantom's slab and ridge as ONE closed surface (their union), with concave edges
    where the ridge meets the slab and the channels open, and the boxes' primitives."""
    m3 = pytest.importorskip("manifold3d")
    u = None
    for lo, hi in [
        ((-0.03, -0.03, 0.0), (0.03, 0.03, 0.01)),
        ((-0.01, -0.03, 0.01), (0.01, -0.003, 0.02)),
        ((-0.01, 0.003, 0.01), (0.01, 0.03, 0.02)),
    ]:
        b = m3.Manifold.cube([h - l for l, h in zip(lo, hi)]).translate(list(lo))
        u = b if u is None else u + b
    mesh = u.to_mesh()
    return np.asarray(mesh.vert_properties)[:, :3].astype(float), np.asarray(mesh.tri_verts).astype(np.int64)


def test_one_closed_surface_is_signed_by_its_nearest_feature_whichever_way_it_is_wound():
    """A point's sign from the pseudo-normal of its nearest face, edge or vertex: inside the
    ridge, beside the concave edge where it stands on the slab, in the channel: the same signs
    as a point-in-box test, for the surface wound outward or inward."""
    v, f = _one_surface()
    pts = _points(seed=1)
    x, y, z = pts.T
    inside = ((np.abs(x) < 0.03) & (np.abs(y) < 0.03) & (z > 0) & (z < 0.01)) | (
        (np.abs(x) < 0.01) & (np.abs(y) > 0.003) & (np.abs(y) < 0.03) & (z >= 0.01) & (z < 0.02)
    )
    for faces in (f, f[:, ::-1]):
        mesh = TriangleMeshes(v, faces)
        assert len(mesh.parts) == 1 and mesh.closed
        d = mesh.exact(pts, pts.mean(axis=0), 0.2)
        sure = np.abs(d) > 1e-7  # float32 vertices: points on the surface are either
        assert ((d < 0) == inside)[sure].all()
        assert inside.sum() > 300 and (~inside).sum() > 300


def test_an_open_sheet_has_no_inside():
    """The surface with its top faces taken away (a sheet, as Bullet's triangle mesh has no
    inside either): the distance is the unsigned distance to the triangles."""
    v, f = _one_surface()
    mesh = TriangleMeshes(v, f[:-2])
    assert not mesh.closed
    pts = _points(seed=2)
    d = mesh.exact(pts, pts.mean(axis=0), 0.2)
    closed = TriangleMeshes(v, f).exact(pts, pts.mean(axis=0), 0.2)
    assert (d >= 0).all() and (closed < 0).any()
    # two faces fewer: no point nearer, most as near as to the closed surface
    assert (d >= np.abs(closed) - 1e-12).all() and (np.abs(d - np.abs(closed)) < 1e-12).mean() > 0.5


def test_a_cylinder_of_tissue_is_read_as_a_cylinder_not_its_capsule():
    """A cylinder primitive (12 mm radius, 20 mm long along y): the signed distance is the
    cylinder's, 12 mm past its ends too, where the capsule of its radius it was read as reached."""
    from types import SimpleNamespace

    from adfkit.model import Body, Geometry, Pose, Vec3

    body = Body(
        identifier="BODY Ridge",
        name="Ridge",
        mass=0.0,
        location=Pose(Vec3(0.01, 0.02, 0.0)),
        collision_shape="Cylinder",
        collision_geometry=Geometry(radius=0.012, height=0.02, axis="y"),
    )
    sb = SimpleNamespace(body=body, model=None, name="Ridge", static=True, world_matrix=lambda: np.eye(4))
    sb.world_matrix = lambda: np.array([[1, 0, 0, 0.01], [0, 1, 0, 0.02], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    t = Tissue([sb])
    local = np.array(
        [
            [0.0, 0.0, 0.0],  # the centre: 10 mm inside (the ends are nearer than the side)
            [0.0, 0.0, 0.015],  # 3 mm off the side
            [0.0, 0.013, 0.0],  # 3 mm past an end, on the axis (the capsule: 9 mm inside)
            [0.0, 0.013, 0.015],  # 3 mm past the end and 3 mm off the side: the rim 4.24 mm away
            [0.005, -0.004, 0.0],  # 7 mm in from the side, 6 mm in from the end
        ]
    )
    got = t.exact(local + [0.01, 0.02, 0.0], np.array([0.01, 0.02, 0.0]), 0.1)
    assert got == pytest.approx([-0.010, 0.003, 0.003, math.hypot(0.003, 0.003), -0.006], abs=1e-12)
