"""AMBF's contact solver settings (runner/pybullet/solver_info.py): where AMBF's bodies are asked
for, PyBullet's world takes btContactSolverInfo's values as AMBF's Bullet keeps them; under
Options() it keeps PyBullet's own."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pybullet")
import pybullet as pb  # noqa: E402

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402

DEPTH = 0.005  # how far the box starts inside the slab (m)

SCENE = f"""\
bodies: [BODY slab, BODY box]
joints: []
namespace: /ambf/env/
gravity: {{x: 0.0, y: 0.0, z: 0.0}}
BODY slab:
  name: slab
  mass: 0.0
  collision shape: BOX
  collision geometry: {{x: 1.0, y: 1.0, z: 0.1}}
  location: {{position: {{x: 0.0, y: 0.0, z: 0.0}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
BODY box:
  name: box
  mass: 1.0
  collision shape: BOX
  collision geometry: {{x: 0.1, y: 0.1, z: 0.1}}
  location: {{position: {{x: 0.0, y: 0.0, z: {0.1 - DEPTH}}}, orientation: {{r: 0.0, p: 0.0, y: 0.0}}}}
"""


def _push_out(tmp_path: Path, bodies: str) -> float:
    """The share of the box's depth in the slab that one physics step's contact pushes it out
    by: the contact's error reduction (Bullet's m_erp2) when nothing else moves it."""
    path = tmp_path / "sunk.yaml"
    path.write_text(SCENE)
    w = open_world(load_scene(path), Options(visuals=False, ground=False, control_substeps=1, bodies=bodies))
    try:
        sb = next(sb for sb in w.bodies if sb.body.name == "box")
        w.step(1)
        vz = pb.getBaseVelocity(sb.uid, physicsClientId=w.cid)[0][2]
        return vz * w.dt / DEPTH
    finally:
        w.close()


def test_a_sunk_box_is_pushed_out_at_ambfs_contact_erp_only_where_ambfs_bodies_are_asked(tmp_path):
    # AMBF's Bullet 2.88 keeps btContactSolverInfo's m_erp2 0.2; PyBullet's server sets 0.08
    assert _push_out(tmp_path, "ambf") == pytest.approx(0.2, rel=0.05)
    assert _push_out(tmp_path, "pybullet") == pytest.approx(0.08, rel=0.05)  # control: Options() keeps PyBullet's
