"""Mass properties against closed forms (1e-6 relative for primitives) and tessellated meshes."""

from __future__ import annotations

import math

import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")

from adfkit.geometry.mass import (  # noqa: E402
    MassProperties,
    apply_to_body,
    mesh_mass_properties,
    primitive_mass_properties,
    shape_entries_mass_properties,
    to_adf,
)
from adfkit.model import Body, Geometry, ShapeEntry  # noqa: E402
from adfkit.model.pose import Pose, Quat, Vec3, rpy_to_quat  # noqa: E402

RHO = 1000.0


def rel(a, b):
    return np.max(np.abs(np.asarray(a) - np.asarray(b))) / np.max(np.abs(np.asarray(b)))


def test_box_closed_form_and_exact_mesh():
    g = Geometry(x=0.1, y=0.2, z=0.3)
    p = primitive_mass_properties("box", g, density=RHO)
    m = RHO * 0.006
    expected = np.diag([m * (0.04 + 0.09) / 12, m * (0.01 + 0.09) / 12, m * (0.01 + 0.04) / 12])
    assert p.mass == pytest.approx(6.0, rel=1e-12)
    assert rel(p.inertia, expected) < 1e-12
    # a box mesh is exact: the polyhedral integral equals the closed form
    mp = mesh_mass_properties(trimesh.creation.box([0.1, 0.2, 0.3]), density=RHO)
    assert rel(mp.inertia, expected) < 1e-9 and mp.mass == pytest.approx(6.0, rel=1e-12)


def test_sphere_cylinder_capsule_closed_forms():
    r, h = 0.05, 0.4
    s = primitive_mass_properties("sphere", Geometry(radius=r), mass=2.0)
    assert np.allclose(np.diag(s.inertia), 0.4 * 2.0 * r * r, rtol=1e-12)
    c = primitive_mass_properties("cylinder", Geometry(radius=r, height=h, axis="x"), mass=3.0)
    assert c.inertia[0, 0] == pytest.approx(0.5 * 3.0 * r * r, rel=1e-12)
    assert c.inertia[1, 1] == pytest.approx(3.0 * (3 * r * r + h * h) / 12, rel=1e-12)
    # capsule: height TOTAL incl. caps; build it from a cylinder and a sphere (two hemispheres)
    cap = primitive_mass_properties("capsule", Geometry(radius=r, height=h, axis="z"), density=RHO)
    cyl = primitive_mass_properties("cylinder", Geometry(radius=r, height=h - 2 * r), density=RHO)
    ball = primitive_mass_properties("sphere", Geometry(radius=r), density=RHO)
    assert cap.volume == pytest.approx(cyl.volume + ball.volume, rel=1e-12)
    half = (h - 2 * r) / 2
    # each hemisphere's COM sits 3r/8 from the cut; parallel axis from the hemisphere COM
    m_h = ball.mass / 2
    i_h_com = (0.4 - (3 / 8) ** 2) * m_h * r * r
    perp = cyl.inertia[0, 0] + 2 * (i_h_com + m_h * (half + 3 * r / 8) ** 2)
    assert cap.inertia[0, 0] == pytest.approx(perp, rel=1e-12)
    assert cap.inertia[2, 2] == pytest.approx(cyl.inertia[2, 2] + ball.inertia[2, 2], rel=1e-12)


def _capsule_mesh():
    # trimesh's capsule is not closed at the poles; manifold3d's hull of two spheres is.
    from adfkit.geometry.primitives import entry_manifold
    from adfkit.geometry.repair import from_manifold

    return from_manifold(
        entry_manifold(ShapeEntry(shape="capsule", geometry=Geometry(radius=0.05, height=0.3)), segments=256)
    )


@pytest.mark.parametrize(
    "kind,geometry,mesh,tol",
    [
        # Bound: an inscribed tessellation loses volume O((2π/n)²); relative error below tol.
        ("sphere", Geometry(radius=0.05), lambda: trimesh.creation.icosphere(6, 0.05), 2e-4),
        (
            "cylinder",
            Geometry(radius=0.05, height=0.3),
            lambda: trimesh.creation.cylinder(0.05, 0.3, sections=512),
            1e-4,
        ),
        ("capsule", Geometry(radius=0.05, height=0.3), _capsule_mesh, 1e-3),
    ],
)
def test_tessellated_meshes_agree_within_bound(kind, geometry, mesh, tol):
    exact = primitive_mass_properties(kind, geometry, density=RHO)
    approx = mesh_mass_properties(mesh(), density=RHO)
    assert approx.volume == pytest.approx(exact.volume, rel=tol)
    assert rel(approx.inertia, exact.inertia) < 2 * tol
    assert np.linalg.norm(approx.com) < 1e-9


def test_offset_rotated_pose_parallel_axis():
    g = Geometry(x=0.1, y=0.2, z=0.3)
    pose = Pose(Vec3(0.5, -0.2, 1.0), rpy_to_quat(0.3, -0.7, 1.1))
    moved = primitive_mass_properties("box", g, pose, density=RHO)
    box = trimesh.creation.box([0.1, 0.2, 0.3])
    t = np.eye(4)
    t[:3, :3] = np.array(Quat(*pose.orientation).matrix())
    t[:3, 3] = pose.position
    box.apply_transform(t)
    mp = mesh_mass_properties(box, density=RHO)
    assert np.allclose(mp.com, [0.5, -0.2, 1.0], atol=1e-12)
    assert rel(moved.inertia, mp.inertia) < 1e-9
    # ADF form: principal moments are the box's, the offset's rotation brings them back
    inertia, offset = to_adf(moved)
    m = 6.0
    assert sorted([inertia.ix, inertia.iy, inertia.iz]) == pytest.approx(
        sorted([m * 0.13 / 12, m * 0.10 / 12, m * 0.05 / 12]), rel=1e-9
    )
    r = np.array(Quat(*offset.orientation).matrix())
    assert np.allclose(r @ np.diag([inertia.ix, inertia.iy, inertia.iz]) @ r.T, moved.inertia, atol=1e-12)
    # parallel axis: about the world origin
    d = np.array([0.5, -0.2, 1.0])
    assert np.allclose(moved.about([0, 0, 0]), moved.inertia + m * (d @ d * np.eye(3) - np.outer(d, d)))


def test_compound_of_two_boxes_equals_one_box():
    halves = [
        ShapeEntry(shape="box", geometry=Geometry(x=0.1, y=0.2, z=0.15), offset=Pose(Vec3(0, 0, z)))
        for z in (-0.075, 0.075)
    ]
    total = shape_entries_mass_properties(halves, mass=6.0)
    whole = primitive_mass_properties("box", Geometry(x=0.1, y=0.2, z=0.3), mass=6.0)
    assert rel(total.inertia, whole.inertia) < 1e-12 and np.allclose(total.com, 0)
    body = apply_to_body(Body(identifier="BODY b"), total)
    assert body.mass == pytest.approx(6.0)
    assert sorted([body.inertia.ix, body.inertia.iy, body.inertia.iz]) == pytest.approx(
        sorted(np.diag(whole.inertia)), rel=1e-12
    )


def test_open_mesh_is_a_diagnostic():
    from adfkit.diagnostics import AdfError

    m = trimesh.creation.box([1, 1, 1])
    m.update_faces(np.arange(len(m.faces) - 1))
    with pytest.raises(AdfError) as exc:
        mesh_mass_properties(m, density=1.0)
    assert exc.value.diagnostics[0].rule == "mesh-not-closed"
    assert isinstance(MassProperties(1, 1, np.zeros(3), np.eye(3)).density, float)
    assert math.isfinite(MassProperties(1, 1, np.zeros(3), np.eye(3)).density)
