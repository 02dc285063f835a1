"""AMBF's ghost rule on a multibody link in C (state_calls.c adfkit_ghost_link, used by
ghost_steps.ambf_ghost through link_push) against numpy's path (ADFKIT_NO_C): the same force and
torque (numpy's rounding where the machine's BLAS rounds as the C file's fused multiply-adds do,
else within a few units in the last place), and the same trajectory."""

from __future__ import annotations

import math
import random
from pathlib import Path

import numpy as np
import pytest

pb = pytest.importorskip("pybullet")

from adfkit.adf import load_scene  # noqa: E402
from adfkit.runner import Options, open_world  # noqa: E402
from adfkit.runner.ghost_rules import ALONG_FROM  # noqa: E402
from adfkit.runner.pybullet import ghost_steps, state_calls  # noqa: E402

BUNDLED = Path(__file__).resolve().parent.parent / "sample_scenes" / "suturing" / "launch.yaml"
AMBF = dict(visuals=False, ghosts="ambf", springs="ambf", bodies="ambf", control_substeps=4, ground=True)


def _c_or_skip():
    if state_calls._load() is None:
        pytest.skip("state_calls.c could not be built or loaded here (no C compiler?): numpy's rule plays")
    c = ghost_steps.link_rule_in_c()
    assert c
    return c


def _close(a, b) -> bool:
    return all(math.isclose(x, y, rel_tol=1e-13, abs_tol=1e-300) or abs(x - y) < 1e-18 for x, y in zip(a, b))


def test_the_c_rule_on_a_link_is_numpy_s():
    """5000 random links under parents moving fast, slowly, near ALONG_FROM and not at all: C's force
    and torque are numpy's, within a few units in the last place (to the bit on the project's box, whose
    OpenBLAS rounds its 3-vector dot and 3x3 products as the C file's fused multiply-adds: 5000 of 5000)."""
    c = _c_or_skip()
    rng = random.Random(7)
    for i in range(5000):

        def vec(scale):
            return tuple(rng.uniform(-1, 1) * scale for _ in range(3))

        v, w = vec(10 ** rng.randint(-6, 0)), vec(10 ** rng.randint(-6, 1))
        vp = (0.0, 0.0, 0.0) if i % 4 == 0 else vec([1.0, 1e-4, ALONG_FROM / 1.7321, 1e-7][i % 4])
        q = np.array(vec(1.0) + (rng.uniform(-1, 1),))
        rot = pb.getMatrixFromQuaternion((q / np.linalg.norm(q)).tolist())
        mass, inertia, points = rng.uniform(0.01, 2), vec(1e-3), rng.randint(1, 16)
        fc, tc = ghost_steps.link_push(v, w, vp, points, 0.004, mass, inertia, rot, c)
        fn, tn = ghost_steps.link_push(v, w, vp, points, 0.004, mass, inertia, rot, False)
        assert _close(fc, fn) and _close(tc, tn), (v, w, vp, fc, fn, tc, tn)


def test_the_c_rule_plays_numpy_s_trajectory():
    """The bundled suturing scene under adfkit run's options, 150 control steps, once with the
    rule on links in C and once in numpy: every body's state within 1 nm and 1e-9 of each other
    after every 10 (the same to the bit where this machine's BLAS rounds as the C file does)."""
    c = _c_or_skip()
    a = open_world(load_scene(BUNDLED, None), Options(**AMBF))
    b = open_world(load_scene(BUNDLED, None), Options(**AMBF))
    pushed = []
    real = ghost_steps.link_push

    def numpy_push(*args, c=None):
        pushed.append(args)
        return real(*args, c=False)

    try:
        for _ in range(15):
            a.step(10)
            ghost_steps.link_push = numpy_push
            try:
                b.step(10)
            finally:
                ghost_steps.link_push = real
            for sa, sb in zip((s.state() for s in a.bodies), (s.state() for s in b.bodies)):
                assert np.allclose(np.concatenate(sa), np.concatenate(sb), rtol=0, atol=1e-9)
        assert pushed  # the rule acted on links (the PSMs' fingers in their ghosts)
        assert c
    finally:
        a.close()
        b.close()
