"""AMBF's centre of mass for a mesh body without `inertial offset` (geometry/chai3d_com.py,
runner/ambf_bodies.py attach_com_estimates): the mean of
CHAI3D's first sub-mesh's welded vertices, once per sub-mesh, with the collision shape built in
that frame. Measured against AMBF (`adfkit parity`, 1.5 s, PyBullet / MuJoCo): a hull of two
boxes 31.4 / 35.0 -> 0.006 / 0.6 mm, a ball on a static slab mesh 10.95 / 12.44 -> 0.000 / 0.010
mm, a hull of two materials 60.0 / 64.8 -> 1.7 / 0.11 mm."""

from __future__ import annotations

import numpy as np
import pytest
from parity_scene import body, launch_with, parity

from adfkit.adf import load_scene
from adfkit.geometry.chai3d_com import body_com, mesh_com
from adfkit.parity import ambf
from adfkit.runner import Options, open_world

pytest.importorskip("pybullet")
BUILD, WHY = ambf.available()
needs_ambf = pytest.mark.skipif(BUILD is None, reason=WHY)


def _box(x0, x1, y0, y1, z0, z1) -> tuple[list, list]:
    v = [(x, y, z) for z in (z0, z1) for x, y in ((x0, y0), (x1, y0), (x1, y1), (x0, y1))]
    quads = [(1, 2, 3, 4), (5, 8, 7, 6), (1, 5, 6, 2), (4, 3, 7, 8), (1, 4, 8, 5), (2, 6, 7, 3)]
    return v, quads


def _obj(boxes, header: str = "", materials=None) -> str:
    """An OBJ of boxes, each an object (``materials``: each box's `usemtl`)."""
    lines = [header] if header else []
    base = 0
    for n, b in enumerate(boxes):
        v, quads = _box(*b)
        lines.append(f"o part{n}")
        if materials:
            lines.append(f"usemtl {materials[n]}")
        lines += [f"v {x!r} {y!r} {z!r}" for x, y, z in v]
        lines += ["f " + " ".join(str(base + i) for i in q) for q in quads]
        base += len(v)
    return "\n".join(lines) + "\n"


#: a bar along x and a post on its end: the corners they share are written apart by rounding
#: (0.04 and 0.03 + 0.01), which CHAI3D's single-precision reading makes one
L_BOXES = [(-0.04, 0.04, -0.01, 0.01, -0.01, 0.01), (0.03 - 0.01, 0.03 + 0.01, -0.01, 0.01, 0.03 - 0.02, 0.03 + 0.02)]


def com_estimate(m, b):
    """The estimate the runner attaches to body ``b`` of model ``m`` (None where AMBF takes the file's)."""
    return body_com(m, b)


def _model(tmp_path, text: str, extra: str = "") -> tuple:
    (tmp_path / "m.yaml").write_text(
        "bodies: [BODY b]\nBODY b:\n  name: b\n  mass: 0.2\n  mesh: parts.obj\n  collision mesh type: CONVEX_HULL\n"
        + extra
    )
    (tmp_path / "parts.obj").write_text(text)
    scene = load_scene(tmp_path / "m.yaml", None, [])
    m = scene.all_models()[0]
    return m, m.bodies[0]


def test_two_objects_without_materials_count_the_first_sub_mesh_twice(tmp_path):
    """No `mtllib`: every face goes to the first sub-mesh, and each object makes one: its 14
    welded vertices' mean (16 written, the two shared corners one each), twice."""
    m, b = _model(tmp_path, _obj(L_BOXES))
    mean = np.array([0.16 / 14, 0.0, 0.22 / 14])
    assert com_estimate(m, b) == pytest.approx(2 * mean, abs=1e-7)


def test_materials_make_the_sub_meshes(tmp_path):
    """Two materials: the first sub-mesh holds the faces of the library's first material (the
    post's, named second in the OBJ), counted for both sub-meshes; `scale` scales it."""
    (tmp_path / "two.mtl").write_text("newmtl post\nKd 1 0 0\nnewmtl bar\nKd 0 0 1\n")
    text = _obj(L_BOXES, "mtllib two.mtl", ["bar", "post"])
    m, b = _model(tmp_path, text)
    assert com_estimate(m, b) == pytest.approx([0.06, 0.0, 0.06], abs=1e-7)
    m, b = _model(tmp_path, text, "  scale: 2.0\n")
    assert com_estimate(m, b) == pytest.approx([0.12, 0.0, 0.12], abs=1e-7)


def test_the_files_offset_or_a_primitive_keeps_the_body_frame(tmp_path):
    m, b = _model(tmp_path, _obj(L_BOXES), "  inertial offset: {position: {x: 0.0, y: 0.0, z: 0.0}}\n")
    assert com_estimate(m, b) is None
    m, b = _model(tmp_path, _obj(L_BOXES), "  collision shape: Box\n  collision geometry: {x: 0.1, y: 0.1, z: 0.1}\n")
    assert com_estimate(m, b) is None


SLAB_AND_BALL = """bodies: [BODY slab, BODY ball]
BODY slab:
  name: slab
  mass: 0.0
  mesh: slab.obj
  collision mesh type: CONVEX_HULL
  location: {position: {x: 0.0, y: 0.0, z: 0.2}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY ball:
  name: ball
  mass: 0.1
  collision shape: Sphere
  collision geometry: {radius: 0.01}
  location: {position: {x: 0.18, y: 0.0, z: 0.3}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
"""
#: a slab 0.2 x 0.1 x 0.02 m written from its corner: its vertices' mean is (0.1, 0, -0.01)
SLAB = _obj([(0.0, 0.2, -0.05, 0.05, -0.02, 0.0)])


def _ball_rest(tmp_path, bodies: str) -> float:
    (tmp_path / "slab.obj").write_text(SLAB)
    (tmp_path / "s.yaml").write_text(SLAB_AND_BALL)
    world = open_world(load_scene(tmp_path / "s.yaml", None, []), Options(ground=True, visuals=False, bodies=bodies))
    try:
        world.run(0.6)
        return float(world.body("BODY ball").world_matrix()[2, 3])
    finally:
        world.close()


def test_a_static_slab_collides_where_ambf_moves_it(tmp_path):
    """Under AMBF's bodies the slab's collision mesh lies moved by its vertices' mean: its top at
    0.19 m, not 0.2 m, so the ball rests on it 10 mm lower (its 1 mm margin above)."""
    assert _ball_rest(tmp_path, "ambf") == pytest.approx(0.19 + 0.01 + 0.001, abs=3e-4)
    assert _ball_rest(tmp_path, "pybullet") == pytest.approx(0.2 + 0.01 + 0.001, abs=3e-4)


@needs_ambf
def test_parity_mesh_bodies_without_inertial_offset(tmp_path, capsys):
    """Against AMBF: the ball on the slab and a hull of two materials dropped on the floor."""
    (tmp_path / "slab.obj").write_text(SLAB)
    (tmp_path / "two.mtl").write_text("newmtl post\nKd 1 0 0\nnewmtl bar\nKd 0 0 1\n")
    (tmp_path / "parts.obj").write_text(_obj(L_BOXES, "mtllib two.mtl", ["bar", "post"]))
    tilted = """BODY two:
  name: two
  mass: 0.2
  mesh: parts.obj
  collision mesh type: CONVEX_HULL
  location: {position: {x: 0.5, y: 0.0, z: 0.1}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
"""
    text = (
        SLAB_AND_BALL.replace(
            "bodies: [BODY slab, BODY ball]", "bodies: [BODY slab, BODY ball, BODY two]\nnamespace: /ambf/env/"
        )
        + tilted
    )
    launch = launch_with(tmp_path, {"m.yaml": text})
    for doc in parity(capsys, launch, 1.5, "both"):  # with the mesh at the body frame: 10.95 / 12.44 mm, 60.0 / 64.8 mm
        assert body(doc, "ball")["max_position_gap_m"] < 1e-4, doc["engine"]  # 0.000 / 0.010 mm
        assert body(doc, "two")["max_position_gap_m"] < 2.5e-3, doc["engine"]  # 1.7 / 0.11 mm
        assert body(doc, "two")["final_position_gap_m"] < 1e-4, doc["engine"]  # 0.015 / 0.013 mm


def _stl_triangles(boxes) -> list:
    tris = []
    for b in boxes:
        v, quads = _box(*b)
        for q in quads:
            a, b2, c, d = (v[i - 1] for i in q)
            tris += [(a, b2, c), (a, c, d)]
    return tris


def test_an_stl_is_one_sub_mesh_binary_or_ascii(tmp_path):
    """An STL (binary or ASCII): its welded corners' mean, once: the slab's (0.1, 0, -0.01)."""
    import struct

    tris = _stl_triangles([(0.0, 0.2, -0.05, 0.05, -0.02, 0.0)])
    data = b"\0" * 80 + struct.pack("<I", len(tris))
    for t in tris:
        data += struct.pack("<12fH", 0, 0, 0, *[x for p in t for x in p], 0)
    (tmp_path / "b.stl").write_bytes(data)
    text = "solid s\n" + "".join(
        "facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {x} {y} {z}\n" for x, y, z in t) + "endloop\nendfacet\n"
        for t in tris
    )
    (tmp_path / "a.stl").write_text(text + "endsolid s\n")
    for name in ("b.stl", "a.stl"):
        assert mesh_com(tmp_path / name) == pytest.approx([0.1, 0.0, -0.01], abs=1e-7), name
    assert mesh_com(tmp_path / "b.stl", 3.0) == pytest.approx([0.3, 0.0, -0.03], abs=1e-6)
