"""`adfkit drill` on scenes in the shape the drilling projects ship: a launch file loading two
volume files that name the same volume (chosen by index, file or name; -l as AMBF's), a drill
whose shape is a mesh (the burr a sphere fitted to its tip, said so), a body that exists but is
no burr, and RGBA slices drilled and written back with their colours."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("skimage", reason="scikit-image (geometry extra) is not installed")
trimesh = pytest.importorskip("trimesh")

from volume_shapes import BONE, project, write_launch  # noqa: E402

from adfkit.cli import main  # noqa: E402

TIP = 0.0015  # m: the mesh drill's round tip


def _drill_mesh(path, tip: float | None = TIP):
    """A drill along +x from its origin: a shaft, and at the origin a ball of radius ``tip``
    (None: the shaft's flat end is the tip)."""
    shaft = trimesh.creation.cylinder(radius=0.0006, height=0.05)
    shaft.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    shaft.apply_translation([0.025, 0, 0])
    parts = [shaft] + ([trimesh.creation.icosphere(subdivisions=3, radius=tip)] if tip else [])
    trimesh.util.concatenate(parts).export(path)


DRILLS = """\
bodies: [BODY mastoidectomy_drill, BODY 4mm, BODY handle]
joints: []
high resolution path: meshes/high_res/
namespace: /ambf/env/
BODY mastoidectomy_drill:
  name: mastoidectomy_drill
  mesh: ''
  mass: 0.0
  location: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0, p: 0, y: 0}}
BODY 4mm:
  name: 4mm
  mesh: 4mm.OBJ
  collision mesh type: CONCAVE_MESH
  mass: 0.0
  scale: 1.0
  location: {position: {x: -0.27, y: 0.0, z: 0.0}, orientation: {r: 0, p: 0, y: 0}}
BODY handle:
  name: handle
  mass: 0.0
  shape: Box
  geometry: {x: 0.01, y: 0.01, z: 0.01}
  location: {position: {x: 0.0, y: 0.0, z: 0.1}, orientation: {r: 0, p: 0, y: 0}}
"""


@pytest.fixture()
def drilling_project(tmp_path):
    adf = project(tmp_path, slices=24, side=24, files=("volume_a.yaml", "volume_b.yaml"))
    (adf / "meshes" / "high_res").mkdir(parents=True)
    _drill_mesh(adf / "meshes" / "high_res" / "4mm.OBJ")
    (adf / "drills.yaml").write_text(DRILLS)
    (adf / "world.yaml").write_text("enclosure size: {length: 10.0, width: 10.0, height: 3.0}\nnamespace: /ambf/env/\n")
    write_launch(tmp_path, "ADF", "world.yaml", ["drills.yaml", "volume_a.yaml", "volume_b.yaml"])
    return tmp_path


def _run(root, *args):
    return main(["drill", str(root / "launch.yaml"), "--out", str(root / "out"), "--frames", "2", *args])


def test_two_files_naming_one_volume_are_told_apart_by_index_file_or_indices(drilling_project, capsys):
    root = drilling_project
    assert _run(root, "--burr", "4mm") == 2  # which one?
    err = capsys.readouterr().err
    assert "error[drill-volume]: the scene has 2 volumes: 0: mastoidectomy_volume (" in err
    assert "volume_a.yaml); 1: mastoidectomy_volume (" in err and "--volume INDEX" in err
    assert _run(root, "--burr", "4mm", "--volume", "mastoidectomy_volume") == 2
    assert "matches 2 volumes" in capsys.readouterr().err
    for choice in (["--volume", "1"], ["--volume", str(root / "ADF" / "volume_b.yaml")], ["-l", "0,2"]):
        assert _run(root, "--burr", "4mm", *choice) == 0, choice
        m = json.loads((root / "out" / "metrics.json").read_text())
        assert m["volume"] == "VOLUME mastoidectomy_volume" and m["voxels_removed_total"] > 0, choice
    assert _run(root, "--burr", "4mm", "--volume", "7") == 2
    assert "'7' matches none of 0: mastoidectomy_volume" in capsys.readouterr().err


def test_a_mesh_drill_drills_with_a_sphere_fitted_to_its_tip_and_says_so(drilling_project, capsys):
    root = drilling_project
    assert _run(root, "--burr", "4mm", "--volume", "0") == 0
    out = capsys.readouterr().out
    assert "burr: BODY 4mm, a sphere fitted to the tip of 4mm.OBJ (" in out and "radius 1.5 mm" in out
    m = json.loads((root / "out" / "metrics.json").read_text())
    assert m["burr"]["radius_m"] == pytest.approx(TIP, rel=0.01)
    assert np.allclose(m["burr"]["start_m"], [-0.27, 0, 0], atol=1e-5)  # the tip is at the body's origin
    # --burr-radius: a sphere of that radius touching the tip's end
    assert _run(root, "--burr", "4mm", "--volume", "0", "--burr-radius", "0.003") == 0
    m = json.loads((root / "out" / "metrics.json").read_text())
    assert m["burr"]["radius_m"] == 0.003 and "--burr-radius" in m["burr"]["sphere"]
    assert np.allclose(m["burr"]["start_m"], [-0.27 + (0.003 - TIP), 0, 0], atol=1e-4)  # back along the shaft


def test_a_mesh_without_a_round_tip_needs_a_radius(drilling_project, capsys):
    root = drilling_project
    _drill_mesh(root / "ADF" / "meshes" / "high_res" / "4mm.OBJ", tip=None)
    assert _run(root, "--burr", "4mm", "--volume", "0") == 2
    err = capsys.readouterr().err
    assert "drills.yaml:" in err and "error[drill-burr]: the body 'BODY 4mm' is a mesh (4mm.OBJ) whose tip" in err
    assert "--burr-radius" in err
    assert _run(root, "--burr", "4mm", "--volume", "0", "--burr-radius", "0.001") == 0


@pytest.mark.parametrize(
    "burr, says",
    [
        ("handle", "the body 'BODY handle' exists but is a Box, not a sphere or a drill mesh"),
        ("mastoidectomy_drill", "the body 'BODY mastoidectomy_drill' exists but has no shape or mesh"),
        ("burr9", "0 bodies are named 'burr9' (the scene's bodies: BODY 4mm, BODY handle, BODY mastoidectomy_drill)"),
    ],
)
def test_a_body_that_is_no_burr_is_named_for_what_it_is(drilling_project, capsys, burr, says):
    assert _run(drilling_project, "--burr", burr, "--volume", "0") == 2
    assert says in capsys.readouterr().err


def test_rgba_slices_are_drilled_and_keep_their_colours(drilling_project):
    from PIL import Image

    root = drilling_project
    assert _run(root, "--burr", "4mm", "--volume", "0") == 0
    src = root / "resources" / "volumes" / "skull"
    removed = kept = 0
    for i in range(24):
        before = np.asarray(Image.open(src / f"plane00{i}.png"))
        after = np.asarray(Image.open(root / "out" / "slices" / f"plane00{i}.png"))
        assert after.shape == before.shape == (24, 24, 4)
        gone = (before[..., 3] > 0) & (after[..., 3] == 0)
        assert (after[gone] == 0).all()  # emptied in every channel, as AMBF's drilling does
        assert np.array_equal(after[~gone], before[~gone])
        removed += int(gone.sum())
        kept += int(((after[..., 3] > 0) & np.all(after[..., :3] == BONE, axis=-1)).sum())
    m = json.loads((root / "out" / "metrics.json").read_text())
    assert removed == m["voxels_removed_total"] > 0 and kept > 1000
    assert main(["validate", str(root / "out" / "volume.yaml")]) == 0


def test_the_skull_scene_is_laid_out_as_the_projects_and_drills(tmp_path, capsys):
    from adfkit.scenes.skull import SkullParams, write_skull
    from adfkit.validator.engine import validate_paths

    launch = write_skull(tmp_path, SkullParams(voxels=32))
    results, problems = validate_paths([launch])
    found = [(str(d.severity), d.rule) for r in results for d in r.diagnostics] + [(p.rule,) for p in problems]
    assert found == [("info", "volume-slice-count")]  # 30 slices under count 512; cameras under main_camera
    assert main(["drill", str(launch), "--out", str(tmp_path / "out"), "--frames", "2"]) == 0
    assert "burr: BODY 2mm, a sphere fitted to the tip of 2mm.OBJ" in capsys.readouterr().out
    m = json.loads((tmp_path / "out" / "metrics.json").read_text())
    assert m["burr"]["radius_m"] == pytest.approx(0.001, rel=0.01) and m["voxels_removed_total"] > 0


def test_tissues_by_colour_and_a_protected_nerve(tmp_path, capsys):
    """The skull scene's labels.yaml names its colours' tissues, as the projects' segmented
    volumes are coloured: a path down through the facial nerve is reported; one that stops
    above it is not."""
    from adfkit.scenes.skull import SkullParams, write_skull

    launch = write_skull(tmp_path, SkullParams(voxels=64))
    for depth, rc in ((-0.004, 1), (0.006, 0)):
        (tmp_path / "p.txt").write_text(f"-0.005 0.0018 0.03\n-0.005 0.0018 {depth}\n")
        out = tmp_path / f"out{rc}"
        args = ["drill", str(launch), "--path", str(tmp_path / "p.txt"), "--removal-rate", "1000", "--out", str(out)]
        assert main([*args, "--frames", "2"]) == rc
        m = json.loads((out / "metrics.json").read_text())
        assert m["labels"] == {"bone": "#fff9db", "sigmoid sinus": "#6eb8d1", "facial nerve": "#f4d631"}
        assert m["voxels_removed"]["bone"] > 0 and m["protected"] == ["facial nerve", "sigmoid sinus"]
        err = capsys.readouterr().err
        assert ("warning[drill-protected]: the burr touched protected tissue 'facial nerve'" in err) == (rc == 1)
        assert (m["voxels_removed"]["facial nerve"] > 0) == (rc == 1)


def test_tissues_by_colour_need_colour_slices(tmp_path, capsys):
    from adfkit.scenes.drilling import write_drilling

    launch = write_drilling(tmp_path)
    (tmp_path / "slices" / "labels.yaml").write_text('bone: "#fff9db"\n')
    assert main(["drill", str(launch), "--out", str(tmp_path / "out")]) == 2
    assert "names tissues by colour, and the volume's slices are grey" in capsys.readouterr().err
    (tmp_path / "slices" / "labels.yaml").write_text('bone: "#fff9dx"\n')  # not a colour
    assert main(["validate", str(tmp_path / "slices" / "labels.yaml")]) == 1
    assert 'or a colour "#rrggbb"' in capsys.readouterr().out
