"""`obj-empty-submesh`: AMBF 2.0 crashes (a segfault, exit -11) building the concave collision
shape of an OBJ one of whose CHAI3D sub-meshes has no face: a material of its library no face
uses, or more objects than materials (geometry/chai3d_com.py empty_submeshes). Measured with
`adfkit parity` on a body of each: the two with an empty sub-mesh stop AMBF, static or moving;
the same meshes as hulls load."""

from __future__ import annotations

import pytest
from test_ambf_com import L_BOXES, _obj

from adfkit.cli import main
from adfkit.parity import ambf
from adfkit.validator import validate_file

BUILD, WHY = ambf.available()
MTL = {
    "two.mtl": "newmtl post\nKd 1 0 0\nnewmtl bar\nKd 0 0 1\n",
    "three.mtl": "newmtl post\nnewmtl bar\nnewmtl unused\n",
}
MESHES = {  # name: (text, the error expected)
    "objects.obj": (_obj(L_BOXES), True),  # two objects, no materials: every face in the first
    "both.obj": (_obj(L_BOXES, "mtllib two.mtl", ["bar", "post"]), False),
    "unused.obj": (_obj(L_BOXES, "mtllib three.mtl", ["bar", "post"]), True),
    "one.obj": (_obj(L_BOXES[:1]), False),
}


def _model(tmp_path, mesh: str, mass: float = 0.2, kind: str = "") -> object:
    for name, text in MTL.items():
        (tmp_path / name).write_text(text)
    (tmp_path / mesh).write_text(MESHES[mesh][0])
    path = tmp_path / "m.yaml"
    path.write_text(
        "bodies: [BODY x]\nnamespace: /ambf/env/\nBODY x:\n  name: x\n"
        f"  mass: {mass}\n  inertial offset: {{position: {{x: 0.0, y: 0.0, z: 0.0}}}}\n  mesh: {mesh}\n{kind}"
        "  location: {position: {x: 0.0, y: 0.0, z: 0.2}, orientation: {r: 0.0, p: 0.0, y: 0.0}}\n"
    )
    return path


@pytest.mark.parametrize("mesh", sorted(MESHES))
def test_a_concave_mesh_with_an_empty_sub_mesh_is_an_error(tmp_path, mesh):
    rules = [(str(d.severity), d.rule, d.location.line) for d in validate_file(_model(tmp_path, mesh)).diagnostics]
    assert (("error", "obj-empty-submesh", 7) in rules) is MESHES[mesh][1]


def test_a_hull_of_it_is_fine(tmp_path):
    path = _model(tmp_path, "unused.obj", kind="  collision mesh type: CONVEX_HULL\n")
    assert not [d for d in validate_file(path).diagnostics if d.rule == "obj-empty-submesh"]


@pytest.mark.skipif(BUILD is None, reason=WHY)
@pytest.mark.parametrize("mesh", ["unused.obj", "both.obj"])
def test_ambf_crashes_where_the_rule_says(tmp_path, capsys, mesh):
    from parity_scene import launch_with

    model = _model(tmp_path, mesh, mass=0.0)
    launch = launch_with(tmp_path, {"m.yaml": model.read_text()})
    capsys.readouterr()
    code = main(["parity", str(launch), "--seconds", "0.1", "--engine", "pybullet", "--json"])
    said = capsys.readouterr()
    assert ("ambf-failed" in said.out + said.err) is MESHES[mesh][1]
    assert code == (2 if MESHES[mesh][1] else 0)
