"""A phantom authored in Blender (headless bpy, the add-on's hole helpers, as
docs/phantom_example.py does it) and checked by the suture: exported, put into the bundled scene by `adfkit suture --phantom`, its holes found,
the arms and the needle placed for them; the check of the needle's swept arc finds it clear
(fast), and the physics passes every pair (slow)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

bpy = pytest.importorskip("bpy")

from conftest import ROOT  # noqa: E402

from adfkit.diagnostics import Severity  # noqa: E402

sys.path.insert(0, str(ROOT / "docs"))
from phantom_example import author_phantom  # noqa: E402  - the steps docs/phantom.md documents


def test_the_add_on_authors_holes_the_suture_finds(addon, scene, tmp_path):
    """Exported: Entry k / Exit k bodies framed by four capsules (a 4.8 mm opening), tilted along
    the needle's arc, each with its ghost; in the bundled scene in place of its phantom, the
    pairs are found, the arms and the needle placed for them, and the needle's swept arc is clear."""
    import numpy as np

    from adfkit.adf import load_scene, read_file
    from adfkit.runner import Options, open_world
    from adfkit.scenes.suturing import layout as L
    from adfkit.scenes.suturing.own_phantom import TRAY_DEPTH, compose, phantom_holes
    from adfkit.tasks.holes import opening_half_extents
    from adfkit.tasks.needle import wire_radius
    from adfkit.tasks.suture import SutureTask
    from adfkit.tasks.sweep import check
    from adfkit.validator import validate_file

    path = author_phantom(addon, tmp_path / "export")
    assert [d for d in validate_file(path).diagnostics if d.severity >= Severity.ERROR] == []
    doc, _ = read_file(path, "model")
    for hole in (b for b in doc.bodies if b.name.startswith(("Entry", "Exit"))):  # the last one made too
        assert opening_half_extents(hole) == pytest.approx([0.0024, 0.0024], abs=1e-7) and hole.mass == 0.0
        assert {round(s.offset.position.x, 6) for s in hole.compound_collision_shape} == {-0.003, 0.0, 0.003}
    assert sorted(g.name for g in doc.ghost_objects) == sorted(
        f"ghost{k}{i}" for k in ("Entry", "Exit") for i in (1, 2, 3)
    )
    holes = phantom_holes(doc)
    assert holes.pairs() == [1, 2, 3]
    e, x = holes.frames[2]["entry"], holes.frames[2]["exit"]
    assert np.linalg.norm(x[:3, 3] - e[:3, 3]) == pytest.approx(0.014, abs=1e-6)
    # tilted as the bundled phantom's holes are: z along the needle's path out of the tissue
    assert e[:3, 2] == pytest.approx(L.hole_poses(1)[0][:3, 2], abs=1e-6)
    placed = compose(load_scene(Path(L.__file__).parents[3] / "sample_scenes" / "suturing" / "launch.yaml"), doc)
    assert placed.pairs == [1, 2, 3] and placed.lift_m == pytest.approx(TRAY_DEPTH, abs=1e-4)  # the slab under the slot
    world = open_world(placed.scene, Options(renderer="tiny", visuals=False))
    try:
        task = SutureTask(world, placed.pairs, seed=0)
        assert {sb.name for sb in task.roles.tissue} >= {"Phantom", "Entry1", "Exit3", "SutureTray"}
        assert check(task, wire_radius(task)) == {}
        # the arms stand to pair 2 (the middle one) as they stand to the bundled holes' centre
        rcm = task.psms["psm1"].base_in_world()[:3, 3]
        centre = (e[:3, 3] + x[:3, 3]) / 2
        assert rcm - centre == pytest.approx(np.array(L.RCM["psm1"]) - [0.0, 0.0, L.RIDGE_TOP], abs=1e-6)
    finally:
        world.close()


@pytest.mark.slow
def test_a_phantom_authored_in_blender_passes_the_suture(addon, scene, tmp_path, capsys):
    from adfkit.cli import main

    path = author_phantom(addon, tmp_path / "export")
    out = tmp_path / "out"
    rc = main(["suture", "--phantom", str(path), "--pairs", "all", "--out", str(out)])
    printed = capsys.readouterr().out
    assert rc == 0, printed
    assert printed.count("passed (entry") == 3
