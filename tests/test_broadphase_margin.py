"""The broadphase's margin (runner/pybullet/broadphase_margin.py): one per process, which each
PyBullet world puts in force before it steps (PyBullet puts its own 0 back at every world it
makes); a creeping body keeps its box in Bullet's tree, and the poses stay what PyBullet's own
margin gives."""

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
def test_each_world_steps_with_the_margin_though_a_world_made_since_put_pybullets_back():
    """A world under adfkit run's options steps with MARGIN in force, even after its ghosts' own
    world was made mid-step; a world made since by anyone (PyBullet puts 0 back) leaves 0 in
    force until a world of adfkit's steps, under Options() as under run's options."""
    scene = load_scene(BUNDLED, None)
    ambf = open_world(scene, Options(**AMBF))
    plain = open_world(scene, Options(visuals=False))
    other = None
    try:
        ambf.step(3)  # its ghosts' pass world is made in the first control step
        assert ambf._ghost_pass.cid is not None
        assert broadphase_margin.margin_now() == broadphase_margin.MARGIN > 0
        other = pb.connect(pb.DIRECT)
        assert broadphase_margin.margin_now() == broadphase_margin.PYBULLET == 0.0
        plain.step(1)
        assert broadphase_margin.margin_now() == broadphase_margin.MARGIN
        pb.resetSimulation(physicsClientId=other)  # makes its world again: 0
        assert broadphase_margin.margin_now() == 0.0
        ambf.step(1)
        assert broadphase_margin.margin_now() == broadphase_margin.MARGIN
    finally:
        ambf.close()
        plain.close()
        if other is not None:
            pb.disconnect(other)


def _digest(monkeypatch, opt: dict, margin: float, nudge: float = 0.0) -> str:
    monkeypatch.setattr(pb_world, "BROADPHASE_MARGIN", margin)
    w = open_world(load_scene(BUNDLED, None), Options(**opt))
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
@pytest.mark.parametrize("opt", [AMBF, dict(visuals=False)], ids=["run", "Options"])
def test_the_margin_leaves_the_bundled_scene_where_pybullets_own_leaves_it(monkeypatch, opt):
    """The bundled suturing scene, 150 control steps (the thread settling on the phantom, the PSMs
    holding), under adfkit run's options and under Options(): every body's state the same to the
    bit with MARGIN as with PyBullet's 0 (the margin keeps boxes in the tree; a pair it makes
    earlier has no points until its bodies come within the contact breaking threshold). Control:
    the needle put 1 nm aside at the start ends elsewhere (the digest sees a nanometre)."""
    ours = _digest(monkeypatch, opt, broadphase_margin.MARGIN)
    assert ours == _digest(monkeypatch, opt, 0.0)
    assert _digest(monkeypatch, opt, 0.0, nudge=1e-9) != ours
