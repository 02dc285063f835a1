"""An OBJ collision mesh of several objects (a convex decomposition) collides in MuJoCo as one
hull per object, as in PyBullet, not as the hull of them all (issue 23: the curved needle's
single hull filled its arc and could not pass a hole)."""

from __future__ import annotations

from pathlib import Path

from adfkit.converters.engine_fit import obj_objects, split_objects

ROOT = Path(__file__).resolve().parents[1]


def test_split_objects_writes_one_obj_per_object(tmp_path):
    src = tmp_path / "two.obj"
    src.write_text(
        "o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n"
        "o b\nv 5 0 0\nv 6 0 0\nv 5 1 0\nv 5 0 1\nv 9 9 9\nf 5/1 6/1 7/1\nf -5 -3 -2\n",
        encoding="utf-8",
    )
    parts = split_objects(src, tmp_path / "parts")
    assert [p.name for p in parts] == ["two_part000.obj", "two_part001.obj"]
    (va, fa), (vb, fb) = [obj_objects(p.read_text())[0] for p in parts]
    assert len(va) == 4 and fa == [[0, 1, 2], [0, 2, 3]]
    # the second object's own 4 vertices (the unused 9 9 9 is left out), negative indices resolved
    assert vb == [["5", "0", "0"], ["6", "0", "0"], ["5", "1", "0"], ["5", "0", "1"]] and fb == [[0, 1, 2], [0, 2, 3]]
    one = tmp_path / "one.obj"
    one.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", encoding="utf-8")
    assert split_objects(one, tmp_path / "parts") == [one]


def test_the_bundled_needle_collides_as_its_eight_hulls_in_mujoco():
    import mujoco

    from adfkit.adf import load_scene
    from adfkit.runner import Options
    from adfkit.runner.mujoco.world import MujocoWorld

    w = MujocoWorld(load_scene(ROOT / "sample_scenes" / "suturing" / "launch.yaml"), Options())
    try:
        m = w.model
        needle = w.body("Needle")
        colliding = [g for g in range(m.ngeom) if m.geom_bodyid[g] == needle.id and m.geom_contype[g]]
        assert len(colliding) == 8
        assert all(m.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH for g in colliding)
    finally:
        w.close()
