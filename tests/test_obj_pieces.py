"""An OBJ collision mesh is hulled per sub-mesh as AMBF builds it: each object's faces of each
material. The corpus suturing set's needle and phantom collision meshes are one object each
with nine and eleven materials; as one hull each, the needle was a filled half-disc and the
phantom's hull covered its holes and lay over the thread (1.8 mm into it at the start, which
spun the thread up and turned the needle over)."""

from __future__ import annotations

import numpy as np
import pytest

from adfkit.geometry.objpieces import obj_pieces, pieces_obj_text

TWO_BLOCKS = """mtllib two.mtl
o Blocks
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
v 3 0 0
v 4 0 0
v 4 1 0
v 3 1 0
v 3 0 1
v 4 0 1
v 4 1 1
v 3 1 1
usemtl left
f 1 2 3 4
f 5 6 7 8
f 1 2 6 5
f 4 3 7 8
usemtl right
f 9 10 11 12
f -4 -3 -2 -1
f 9 10 14 13
f 12 11 15 16
"""


def test_one_object_of_two_materials_is_two_pieces():
    (va, fa), (vb, fb) = obj_pieces(TWO_BLOCKS)
    assert len(va) == len(vb) == 8 and fa[0] == [0, 1, 2, 3]
    assert {x[0] for x in va} == {"0", "1"} and {x[0] for x in vb} == {"3", "4"}  # negative indices resolved
    again = obj_pieces(pieces_obj_text([(va, fa), (vb, fb)]))
    assert again == [(va, fa), (vb, fb)]


def test_one_material_per_object_keeps_the_objects():
    text = "o a\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no b\nusemtl m\nv 5 0 0\nv 6 0 0\nv 5 1 0\nf 4 5 6\n"
    assert [len(v) for v, _ in obj_pieces(text)] == [3, 3]
    assert len(obj_pieces("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")) == 1


def test_pybullet_hulls_each_material_of_an_object(tmp_path):
    """A static body whose collision mesh is two 1 m blocks 2 m apart in one object, one material
    each (CONVEX_HULL): a ball dropped between them falls through the gap, as in AMBF; the hull
    of both would catch it."""
    pytest.importorskip("pybullet")
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    (tmp_path / "blocks.obj").write_text(TWO_BLOCKS)
    (tmp_path / "two.mtl").write_text("newmtl left\nKd 1 0 0\nnewmtl right\nKd 0 0 1\n")
    (tmp_path / "model.yaml").write_text(
        """bodies: [BODY blocks, BODY ball]
BODY blocks:
  name: blocks
  mass: 0.0
  mesh: blocks.obj
  collision mesh type: CONVEX_HULL
  location: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
BODY ball:
  name: ball
  mass: 0.1
  collision shape: SPHERE
  collision geometry: {radius: 0.2}
  location: {position: {x: 2.0, y: 0.5, z: 2.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
"""
    )
    world = open_world(load_scene(tmp_path / "model.yaml", None, []), Options(ground=False, visuals=False))
    try:
        world.run(1.0)
        assert world.body("BODY ball").com_position()[2] < 0.0  # through the gap, not resting on a hull at z = 1
        assert np.isfinite(world.body("BODY ball").com_position()).all()
    finally:
        world.close()
