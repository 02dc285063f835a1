"""Each collision hull gets its file's `collision margin`, as AMBF sets it on every hull it makes.
PyBullet gives every shape 1 mm, and a hull collides grown by its margin; its changeDynamics
reaches the hulls of a body of several only on a multibody's base (adfkit/runner/pybullet/
margins.py). The corpus suturing set's needle, nine hulls under 1 mm thick, collided as if
2.8-3 mm thick and was forced through its phantom's channel with up to 130 N."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")


def _boxes_obj(boxes) -> str:
    """One OBJ object with a material per box ((x0, x1), (y0, y1), (z0, z1)): a hull each."""
    lines = ["o Boxes"]
    quads = [(1, 2, 3, 4), (5, 8, 7, 6), (1, 5, 6, 2), (4, 3, 7, 8), (1, 4, 8, 5), (2, 6, 7, 3)]
    for n, ((x0, x1), (y0, y1), (z0, z1)) in enumerate(boxes):
        lines += [f"v {x} {y} {z}" for z in (z0, z1) for x, y in ((x0, y0), (x1, y0), (x1, y1), (x0, y1))]
        lines.append(f"usemtl m{n}")
        lines += ["f " + " ".join(str(8 * n + i) for i in q) for q in quads]
    return "\n".join(lines) + "\n"


#: two plates 0.8 mm thick, 2 mm apart, in one object with a material each: two hulls
PLATES = _boxes_obj(
    [((-0.02, -0.001), (-0.01, 0.01), (-0.0004, 0.0004)), ((0.001, 0.02), (-0.01, 0.01), (-0.0004, 0.0004))]
)


def _rest_gap(tmp_path, plates_margin: str, floor: str, engine: str = "pybullet") -> float:
    """How far, m, the plates' underside comes to rest above the floor's top (z = 0); MuJoCo
    with AMBF's bodies (`adfkit run`'s), the only ones it gives a hull's margin."""
    from adfkit.adf import load_scene
    from adfkit.runner import Options, open_world

    (tmp_path / "plates.obj").write_text(PLATES)
    (tmp_path / "model.yaml").write_text(
        f"""bodies: [BODY floor, BODY plates]
BODY floor:
  name: floor
  mass: 0.0
{floor}
  location: {{position: {{x: 0.0, y: 0.0, z: 0.0}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
BODY plates:
  name: plates
  mass: 0.01
  inertia: {{ix: 1.0e-6, iy: 1.0e-6, iz: 2.0e-6}}
  mesh: plates.obj
  collision mesh type: CONVEX_HULL
{plates_margin}
  location: {{position: {{x: 0.0, y: 0.0, z: 0.003}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
"""
    )
    opt = Options(ground=False, visuals=False, bodies="ambf" if engine == "mujoco" else "pybullet")
    world = open_world(load_scene(tmp_path / "model.yaml", None, []), opt, engine=engine)
    try:
        world.run(0.5)
        return world.body("BODY plates").world_matrix()[2, 3] - 0.0004
    finally:
        world.close()


BOX_FLOOR = """  collision shape: BOX
  collision geometry: {x: 0.2, y: 0.2, z: 0.02}
  collision offset: {position: {x: 0.0, y: 0.0, z: -0.01}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
  collision margin: 0.0001"""


def test_hulls_of_a_body_take_the_files_margin(tmp_path):
    """Two hulls 0.8 mm thick with `collision margin: 0.0001` rest 0.1 mm above a box (its margin
    is inside it); without the key they keep AMBF's and PyBullet's default, 1 mm."""
    assert _rest_gap(tmp_path, "  collision margin: 0.0001", BOX_FLOOR) == pytest.approx(1e-4, abs=5e-5)
    assert _rest_gap(tmp_path, "", BOX_FLOOR) == pytest.approx(1e-3, abs=1e-4)


def test_static_hulls_take_the_files_margin(tmp_path):
    """A static floor of two hulls (the corpus phantom's slab and ridge blocks are hulls) with
    `collision margin: 0.0001` holds the plates 0.2 mm up (both margins), not 1.1 mm."""
    (tmp_path / "slabs.obj").write_text(
        _boxes_obj([((-0.05, -0.001), (-0.05, 0.05), (-0.01, 0.0)), ((0.001, 0.05), (-0.05, 0.05), (-0.01, 0.0))])
    )
    hull_floor = "  collision mesh: slabs.obj\n  collision mesh type: CONVEX_HULL\n  collision margin: 0.0001"
    assert _rest_gap(tmp_path, "  collision margin: 0.0001", hull_floor) == pytest.approx(2e-4, abs=5e-5)
    hull_floor_default = "  collision mesh: slabs.obj\n  collision mesh type: CONVEX_HULL"
    assert _rest_gap(tmp_path, "  collision margin: 0.0001", hull_floor_default) == pytest.approx(1.1e-3, abs=1e-4)


def test_mujoco_hulls_take_the_files_margin(tmp_path):
    """MuJoCo's geoms have no margin of their own; under AMBF's bodies a mesh geom gets the
    body's `collision margin` (AMBF's 1 mm without the key) as its contact margin, where MuJoCo's
    contacts come to rest, so a hull rests as far from a box as in Bullet: 0.1 mm, 1 mm, 10 mm
    (`adfkit parity` on a 3 cm icosphere of margin 0.01 dropped on the floor: 11.1 mm from AMBF
    before, 0.004 mm at the end)."""
    pytest.importorskip("mujoco")
    assert _rest_gap(tmp_path, "  collision margin: 0.0001", BOX_FLOOR, "mujoco") == pytest.approx(1e-4, abs=5e-5)
    assert _rest_gap(tmp_path, "", BOX_FLOOR, "mujoco") == pytest.approx(1e-3, abs=1e-4)
    assert _rest_gap(tmp_path, "  collision margin: 0.01", BOX_FLOOR, "mujoco") == pytest.approx(1e-2, abs=2e-4)
