"""`adfkit parity` on a scene where neither side made a body the other made too (every body left
out, as AMBF leaves out a body whose visual mesh is not found): it says nothing was compared,
where it said every body agreed."""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pytest

from adfkit.cli import main
from adfkit.parity import ambf
from adfkit.parity.compare import Comparison, Gap
from adfkit.parity.session import NOTHING_COMPARED, Outcome, Request, print_text
from adfkit.parity.traces import Trace

BUILD, WHY = ambf.available()

MISSING_MESH = """\
bodies: [BODY lost, BODY found]
BODY lost:
  name: lost
  mesh: not-there.STL
  mass: 1.0
  location:
    position: {x: 0.0, y: 0.0, z: 0.5}
    orientation: {r: 0.0, p: 0.0, y: 0.0}
BODY found:
  name: found
  mass: 1.0
  collision shape: BOX
  collision geometry: {x: 0.1, y: 0.1, z: 0.1}
  location:
    position: {x: 0.0, y: 0.0, z: 0.5}
    orientation: {r: 0.0, p: 0.0, y: 0.0}
"""


def _comparison(n_bodies: int) -> Comparison:
    empty = Trace("ambf", {}, [], np.zeros(0), np.zeros((0, 0, 7)), [], np.zeros((0, 0)), 0.0)
    bodies = [Gap(f"b{i}", np.array([0.0, 1e-4]), np.array([0.0, 0.1])) for i in range(n_bodies)]
    return Comparison(empty, empty, np.array([0.0, 1.0]), bodies, [], [], [], 1e-3, 1.0)


def _text(c: Comparison) -> str:
    out = io.StringIO()
    print_text(Outcome([c], Request(Path("scene.yaml"), None, None)), stream=out)  # type: ignore[arg-type]
    return out.getvalue()


def test_no_body_compared_is_said_and_counted_not_called_agreement():
    none, one = _comparison(0), _comparison(1)
    assert none.as_json()["bodies_compared"] == 0 and one.as_json()["bodies_compared"] == 1
    assert f"nothing compared: {NOTHING_COMPARED}" in _text(none) and "agree:" not in _text(none)
    assert "agree: every body within 1 mm and 1°" in _text(one) and "nothing compared" not in _text(one)


@pytest.mark.skipif(BUILD is None, reason=WHY)
def test_a_scene_whose_bodies_both_sides_leave_out(tmp_path, capsys):
    scene = tmp_path / "lost.yaml"
    scene.write_text(MISSING_MESH.replace("BODY lost, BODY found", "BODY lost"), encoding="utf-8")
    assert main(["parity", str(scene), "--ambf", str(BUILD.root), "--seconds", "0.1", "--no-ground"]) == 0
    assert "nothing compared" in capsys.readouterr().out
    # with one body made on both sides it is compared as before
    scene.write_text(MISSING_MESH, encoding="utf-8")
    assert main(["parity", str(scene), "--ambf", str(BUILD.root), "--seconds", "0.1", "--no-ground", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    runs = doc if isinstance(doc, list) else doc.get("comparisons", [doc])
    assert runs[0]["bodies_compared"] == 1 and runs[0]["agree"]
