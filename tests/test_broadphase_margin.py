"""The broadphase's margin (runner/pybullet/broadphase_margin.py): one per process, which each
PyBullet world puts in force before it steps; under AMBF's bodies a creeping body keeps its box
in Bullet's tree, and the poses stay what PyBullet's own margin gives."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

pb = pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402
from adfkit.runner.pybullet import broadphase_margin  # noqa: E402
from adfkit.runner.pybullet import world as pb_world  # noqa: E402

BUNDLED = Path(__file__).resolve().parent.parent / "sample_scenes" / "suturing" / "launch.yaml"
#: the options adfkit run and adfkit parity play a scene with (AMBF's ghosts, springs and bodies)
AMBF = dict(visuals=False, ghosts="ambf", springs="ambf", bodies="ambf", control_substeps=4, ground=True)

needs_margin = pytest.mark.skipif(
    broadphase_margin.margin_now() is None, reason="PyBullet's module has no gDbvtMargin symbol to find"
)


@needs_margin
def test_each_world_puts_its_margin_in_force_and_a_new_world_does_not_take_it_away():
    """A world under AMBF's bodies steps with BODIES_AMBF in force, even after its ghosts' own
    world was made mid-step (PyBullet puts 0 back at every world it makes); a world under
    Options() puts PyBullet's 0 back before it steps, and the first world its own again."""
    scene = load_scene(BUNDLED, None)
    ambf = open_world(scene, Options(**AMBF))
    plain = open_world(scene, Options(visuals=False))
    try:
        ambf.step(3)  # its ghosts' pass world is made in the first control step
        assert ambf._ghost_pass.cid is not None
        assert broadphase_margin.margin_now() == broadphase_margin.BODIES_AMBF > 0
        plain.step(1)
        assert broadphase_margin.margin_now() == broadphase_margin.PYBULLET == 0.0
        ambf.step(1)
        assert broadphase_margin.margin_now() == broadphase_margin.BODIES_AMBF
    finally:
        ambf.close()
        plain.close()


def _digest(monkeypatch, margin: float, nudge: float = 0.0) -> str:
    monkeypatch.setattr(pb_world, "BODIES_AMBF", margin)
    w = open_world(load_scene(BUNDLED, None), Options(**AMBF))
    try:
        if nudge:
            needle = w.body("Needle")
            p, q = pb.getBasePositionAndOrientation(needle.uid, physicsClientId=w.cid)
            pb.resetBasePositionAndOrientation(needle.uid, (p[0] + nudge, p[1], p[2]), q, physicsClientId=w.cid)
        w.step(150)
        return hashlib.sha256(repr([sb.state() for sb in w.bodies]).encode()).hexdigest()
    finally:
        w.close()


@needs_margin
def test_the_margin_leaves_the_bundled_scene_where_pybullets_own_leaves_it(monkeypatch):
    """The bundled suturing scene under adfkit run's options, 0.6 s (the thread settling on the
    phantom, the PSMs holding): every body's state the same to the bit with BODIES_AMBF as with
    PyBullet's 0 (the margin only keeps boxes in the tree; a pair made earlier within it has no
    points until its bodies come within the contact threshold). Control: the needle put 1 nm
    aside at the start ends elsewhere (the digest sees a nanometre)."""
    ours = _digest(monkeypatch, broadphase_margin.BODIES_AMBF)
    assert ours == _digest(monkeypatch, 0.0)
    assert _digest(monkeypatch, 0.0, nudge=1e-9) != ours
