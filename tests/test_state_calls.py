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
    """The bundled suturing scene under adfkit run's options, the springs evaluated in numpy, 150
    control steps, once with the reads and pushes in C and once with the Python calls: every body's
    state the same to the bit after every 10."""
    _c_or_skip()
    a = open_world(load_scene(BUNDLED, None), Options(**AMBF))
    b = open_world(load_scene(BUNDLED, None), Options(**AMBF))
    try:
        a.step(1)
        b.step(1)
        assert a.springs._read_c is not None and b.springs._read_c is not None
        a.springs._c_springs = b.springs._c_springs = None  # numpy's evaluation on both
        b.springs._read_c = None  # and the Python calls on one
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
        assert w.springs._read_c is None and w.springs._c_springs is None and w.springs.pq
    finally:
        w.close()


def test_the_springs_in_c_give_numpy_s_torques_and_forces(tmp_path):
    """The parity scene's thread at the challenge's inertia (the published springs, which the
    bundled scene's thread leaves out) under adfkit run's options: the springs evaluated in C
    (spring_c.py) give every body numpy's torque and force to round-off, after 100 control steps
    (the thread falling from its held end, its joints bent) and with a thread element spun (its
    limits act). Control: with the C joints' rest angles moved they differ."""
    from adfkit.scenes.parity import SCENES, write_parity

    _c_or_skip()
    launch = write_parity(tmp_path)
    w = open_world(load_scene(launch, [SCENES.index("challenge_thread")]), Options(**AMBF))
    try:
        w.step(100)
        s = w.springs
        cs = s._c_springs
        assert cs is not None

        def both():
            state = pb.saveState(physicsClientId=w.cid)
            cs.apply(s._c_read(), w.dt, 0.2)
            in_c = cs.torque.copy(), cs.force.copy()
            pb.restoreState(state, physicsClientId=w.cid)
            got = {}
            s._c_springs, s._push = None, lambda t, f, p: got.update(t=t.copy(), f=f)
            try:
                s.apply(w.dt)
            finally:
                s._c_springs = cs
                del s._push
            pb.restoreState(state, physicsClientId=w.cid)
            force = got["f"] if got["f"] is not None else 0.0 * in_c[1]
            return in_c, (got["t"], force)

        def close(c, n):
            scale = max(abs(n[0]).max(), abs(n[1]).max())
            assert scale > 1e-6  # the springs act (N·m, N): a set of zeros would agree with anything
            return max(abs(c[0] - n[0]).max(), abs(c[1] - n[1]).max()) <= 1e-9 * scale

        assert close(*both())
        thread = next(sb for sb in s.bodies if sb.name.startswith("Thread") and not sb.static)
        pb.resetBaseVelocity(thread.uid, [0, 0, 0], [0.0, 40.0, 0.0], physicsClientId=w.cid)
        assert close(*both())
        moved = cs._keep["eq"] + 0.05  # the C's own rest angles (the set's stay)
        cs.struct.eq = moved.ctypes.data
        assert not close(*both())
    finally:
        w.close()
