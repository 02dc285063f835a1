"""A moving concave mesh (AMBF's default `collision mesh type`, a triangle mesh it collides as
it is) played as convex parts where one hull would fill its hollow (adfkit/geometry/concave.py):
the same decision in both engines and in the MJCF and URDF writers. A ring dropped around a peg
slides down it; as the hull of the ring (`CONVEX_HULL`, the negative control) it is thrown up the peg."""

from __future__ import annotations

import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")

from adfkit.geometry import concave  # noqa: E402
from adfkit.geometry import decompose as dec  # noqa: E402

#: a ring (major radius 50 mm, tube 12 mm: a 38 mm hole) and a peg of 20 mm radius, 0.2 m tall
MAJOR, MINOR, PEG_R, PEG_H = 0.05, 0.012, 0.02, 0.2


@pytest.fixture(autouse=True)
def _fresh(tmp_path, monkeypatch):
    """A cold CoACD cache of this test's own, and no decision remembered from another test."""
    monkeypatch.setenv("ADFKIT_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(concave, "_DONE", {})


def _ring(path):
    trimesh.creation.torus(major_radius=MAJOR, minor_radius=MINOR, major_sections=32, minor_sections=12).export(path)
    return path


def _inside_any(hulls, point) -> bool:
    """The point is inside one of the convex hulls: behind every face of it."""
    p = np.asarray(point, dtype=float)
    return any(bool(np.all(np.einsum("ij,ij->i", h.face_normals, p - h.triangles[:, 0]) <= 0)) for h in hulls)


def test_a_ring_is_parts_that_leave_its_hole_open(tmp_path):
    parts = concave.convex_parts(_ring(tmp_path / "ring.stl"))
    assert parts is not None and parts.decomposed == 1
    assert 0.3 < parts.fill < concave.HULL_FILL  # a ring fills about half its hull
    assert 4 <= len(parts.hulls) <= concave.STAND_IN["max_hulls"]
    assert all(h.is_convex for h in parts.hulls)
    hole = [0.0, 0.0, 0.0]
    assert not _inside_any(parts.hulls, hole)  # the peg's room is open...
    assert _inside_any([trimesh.load(tmp_path / "ring.stl").convex_hull], hole)  # ...and solid in one hull
    assert _inside_any(parts.hulls, [MAJOR, 0.0, 0.0])  # the tube itself is solid


def test_a_convex_mesh_keeps_its_hull_and_costs_no_decomposition(tmp_path):
    trimesh.creation.box((0.1, 0.2, 0.05)).export(tmp_path / "box.stl")
    trimesh.creation.icosphere(radius=0.05).export(tmp_path / "ball.obj")
    calls = dec.COACD_CALLS
    assert concave.convex_parts(tmp_path / "box.stl") is None
    assert concave.convex_parts(tmp_path / "ball.obj") is None
    assert dec.COACD_CALLS == calls


def test_separate_pieces_are_hulled_one_by_one_without_coacd(tmp_path):
    """A slab and a peg in one mesh (puzzle1's PegBase): each piece is convex, the hull of both a
    wedge that fills the room around the peg."""
    slab = trimesh.creation.box((0.4, 0.4, 0.02))
    peg = trimesh.creation.cylinder(radius=PEG_R, height=PEG_H)
    peg.apply_translation([0, 0, PEG_H / 2 + 0.02])
    trimesh.util.concatenate([slab, peg]).export(tmp_path / "pegbase.stl")
    calls = dec.COACD_CALLS
    parts = concave.convex_parts(tmp_path / "pegbase.stl")
    assert parts is not None and parts.fill < 0.3
    assert len(parts.hulls) == 2 and parts.decomposed == 0 and dec.COACD_CALLS == calls
    beside_peg = [0.1, 0.0, 0.1]
    assert not _inside_any(parts.hulls, beside_peg)
    assert _inside_any([trimesh.load(tmp_path / "pegbase.stl").convex_hull], beside_peg)


def test_a_decomposition_is_made_once_and_read_from_the_cache(tmp_path):
    ring = _ring(tmp_path / "ring.stl")
    calls = dec.COACD_CALLS
    first = concave.convex_parts(ring)
    assert dec.COACD_CALLS == calls + 1 and first.coacd_s > 0
    concave._DONE.clear()  # a later run: the disk cache answers
    again = concave.convex_parts(ring)
    assert dec.COACD_CALLS == calls + 1 and again.coacd_s == 0.0
    assert [h.volume for h in again.hulls] == pytest.approx([h.volume for h in first.hulls])


def _ring_on_peg(tmp_path, mesh_type: str = "", peg: bool = True) -> object:
    """The ring 0.15 m up around the peg (its mesh on line 11), or the ring alone."""
    from adfkit.adf import load_scene

    _ring(tmp_path / "ring.stl")
    bodies = "[BODY peg, BODY ring]" if peg else "[BODY ring]"
    (tmp_path / "model.yaml").write_text(
        f"""bodies: {bodies}
BODY peg:
  name: peg
  mass: 0.0
  collision shape: CYLINDER
  collision geometry: {{radius: {PEG_R}, height: {PEG_H}, axis: z}}
  location: {{position: {{x: 0.0, y: 0.0, z: {PEG_H / 2}}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
BODY ring:
  name: ring
  mass: 0.1
  mesh: ring.stl
{mesh_type}
  location: {{position: {{x: 0.0, y: 0.0, z: 0.15}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
"""
    )
    return load_scene(tmp_path / "model.yaml", None, [])


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_a_ring_dropped_around_a_peg_slides_down_it(tmp_path, engine):
    pytest.importorskip(engine)
    from adfkit.runner import Options, open_world

    rests = {}
    for label, mesh_type in (("concave", ""), ("hull", "  collision mesh type: CONVEX_HULL")):
        world = open_world(_ring_on_peg(tmp_path, mesh_type), Options(visuals=False), engine=engine)
        try:
            notes = [d for d in world.diagnostics if d.rule == "runner-convex-parts"]
            overlaps = [d for d in world.diagnostics if d.rule == "runner-hull-overlap"]
            world.run(0.6)
            rests[label] = world.body("BODY ring").world_matrix()[:3, 3]
        finally:
            world.close()
        if label == "concave":
            assert len(notes) == 1 and "BODY ring" in notes[0].message and notes[0].location.line == 11
            assert overlaps == []
        else:
            assert notes == [] and overlaps == []  # the file asks for the hull: no surprise to say
    ground = -0.001  # the runner's floor, 1 mm under the lowest body (the peg's foot)
    assert rests["concave"][2] < ground + MINOR + 0.005  # down the peg to the floor
    assert np.hypot(*rests["concave"][:2]) < MAJOR - MINOR - PEG_R + 0.002  # still around it
    # the control: its hull starts in the peg and is thrown up along it (0.26 m high at 0.6 s in
    # PyBullet, 7.9 m in MuJoCo), nowhere near the floor
    assert rests["hull"][2] > PEG_H / 2


def test_both_engines_and_both_writers_make_the_same_parts(tmp_path):
    pytest.importorskip("mujoco")
    pytest.importorskip("pybullet")
    import mujoco
    import pybullet as pb

    from adfkit.converters import write
    from adfkit.runner import Options, open_world

    scene = _ring_on_peg(tmp_path)
    said = []
    for engine in ("pybullet", "mujoco"):
        world = open_world(scene, Options(visuals=False), engine=engine)
        try:
            said += [d.message for d in world.diagnostics if d.rule == "runner-convex-parts"]
        finally:
            world.close()
    assert len(said) == 2 and said[0] == said[1]
    n = len(concave.convex_parts(tmp_path / "ring.stl").hulls)
    for suffix in (".xml", ".urdf"):
        out = tmp_path / "out" / f"ring{suffix}"
        out.parent.mkdir(exist_ok=True)
        # URDF holds one tree: the ring alone, its root link
        losses = write(scene.models[0] if suffix == ".xml" else _ring_on_peg(tmp_path, peg=False).models[0], out)
        assert [x.feature for x in losses if x.element == "BODY ring"].count("concave collision mesh") == 1
        parts = sorted((out.parent / "ring_meshes").glob("ring_convex_*.obj"))
        assert len(parts) == n
        if suffix == ".xml":
            m = mujoco.MjModel.from_xml_path(str(out))
            ring = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "ring")
            assert int(np.sum((m.geom_bodyid == ring) & (m.geom_contype > 0))) == n
        else:
            cid = pb.connect(pb.DIRECT)
            try:
                uid = pb.loadURDF(str(out), physicsClientId=cid)
                assert len(pb.getCollisionShapeData(uid, -1, physicsClientId=cid)) == n
            finally:
                pb.disconnect(cid)


def test_parts_files_are_their_own_when_an_id_comes_back(monkeypatch):
    """The OBJ of a body's convex parts is remembered by the parts' id: an id Python hands out
    again to new parts once the old ones are gone (the tests that swap _DONE out free theirs)
    gives the new parts a file of their own, not the old parts' (which a PyBullet world took as the
    body's collision shape). Stood in by an entry under the new parts' id."""
    box = trimesh.creation.box((0.01, 0.01, 0.01))
    ball = trimesh.creation.icosphere(radius=0.02)
    old = concave.ConvexParts([box], 1.0, 0, 0.0)
    new = concave.ConvexParts([ball], 1.0, 0, 0.0)
    monkeypatch.setattr(concave, "_FILES", {id(new): (old, concave.parts_obj(old))})
    mine = trimesh.load(concave.parts_obj(new), force="mesh")
    assert mine.extents == pytest.approx([0.04, 0.04, 0.04], rel=0.05)  # the ball's, not the box's 0.01
