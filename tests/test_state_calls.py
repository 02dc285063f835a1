"""The springs' reads and pushes through PyBullet's own C API in one call each (state_calls.py): the
same numbers as PyBullet's Python calls, so the same trajectory to the bit; without a compiler (or
with ADFKIT_NO_C) the Python calls."""

from __future__ import annotations

from pathlib import Path

import pytest

pb = pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402
from adfkit.runner.pybullet import state_calls  # noqa: E402

BUNDLED = Path(__file__).resolve().parent.parent / "sample_scenes" / "suturing" / "launch.yaml"
#: the options adfkit run and adfkit parity play a scene with (AMBF's ghosts, springs and bodies)
AMBF = dict(visuals=False, ghosts="ambf", springs="ambf", bodies="ambf", control_substeps=4, ground=True)


def _c_or_skip():
    if state_calls._load() is None:
        pytest.skip("state_calls.c could not be built or loaded here (no C compiler?): the Python calls play")


def test_the_c_reads_are_pybullet_s_reads():
    """Every free spring body of the bundled suturing scene, read in one C call, is what
    getBasePositionAndOrientation and getBaseVelocity give, to the bit; after a physics step the
    earlier read is not (the read is of the moment, not a copy kept)."""
    _c_or_skip()
    w = open_world(load_scene(BUNDLED, None), Options(**AMBF))
    try:
        w.step(30)
        s = w.springs
        assert s._read_c is not None
        uids = s._bases
        read = s._read_c()
        for row, uid in zip(read.tolist(), uids):
            p, q = pb.getBasePositionAndOrientation(uid, physicsClientId=w.cid)
            v, om = pb.getBaseVelocity(uid, physicsClientId=w.cid)
            assert tuple(row) == p + q + v + om
        pb.stepSimulation(physicsClientId=w.cid)
        assert (s._read_c() != read).any()
    finally:
        w.close()


def test_the_c_calls_play_the_python_calls_trajectory():
    """The bundled suturing scene under adfkit run's options, 150 control steps, once with the C calls
    and once with the Python calls: every body's state the same to the bit after every 10."""
    _c_or_skip()
    a = open_world(load_scene(BUNDLED, None), Options(**AMBF))
    b = open_world(load_scene(BUNDLED, None), Options(**AMBF))
    try:
        a.step(1)
        b.step(1)
        assert a.springs._read_c is not None and b.springs._read_c is not None
        b.springs._read_c = None  # the Python calls from here on
        for _ in range(15):
            a.step(10)
            b.step(10)
            assert [sb.state() for sb in a.bodies] == [sb.state() for sb in b.bodies]
    finally:
        a.close()
        b.close()


def test_without_the_library_the_python_calls_play(monkeypatch):
    """ADFKIT_NO_C: no library, for_client answers None, and the springs read with the Python calls."""
    monkeypatch.setattr(state_calls, "_tried", False)
    monkeypatch.setattr(state_calls, "_lib", None)
    monkeypatch.setenv("ADFKIT_NO_C", "1")
    w = open_world(load_scene(BUNDLED, None), Options(**AMBF))
    try:
        assert state_calls.for_client(w.cid) is None
        w.step(2)
        assert w.springs._read_c is None and w.springs.pq
    finally:
        w.close()
