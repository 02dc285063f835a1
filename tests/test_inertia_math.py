"""Principal moments as the converters write them: the same numbers on every machine."""

from __future__ import annotations

import numpy as np

from adfkit.converters.inertia import physical_problem, principal, without_noise

# pybullet_data's cube_no_rotation.urdf: a rod-like tensor whose smallest principal moment is 0
ROD = [[0.2125, -0.005, 0.0225], [-0.005, 0.205, 0.045], [0.0225, 0.045, 0.0125]]


def _holds(m) -> bool:
    """The triangle inequality exactly in floating point, as PyBullet's importer tests it."""
    a, b, c = m
    return a + b >= c and a + c >= b and b + c >= a and min(m) >= 0.0


def test_rounding_noise_is_taken_out():
    # the eigen-solver's output on one processor: one ulp on the wrong side of the inequality
    assert without_noise((5.551115123125559e-17, 0.21499999999999989, 0.215)) == (
        0.0,
        0.21499999999999989,
        0.21499999999999989,
    )
    assert without_noise((-3e-18, 0.215, 0.215)) == (0.0, 0.215, 0.215)


def test_real_violations_are_kept_for_the_caller():
    assert without_noise((0.1, 0.1, 0.3)) == (0.1, 0.1, 0.3)
    assert physical_problem(without_noise((0.1, 0.1, 0.3))) == "break the triangle inequality"
    assert without_noise((-0.01, 0.2, 0.2)) == (-0.01, 0.2, 0.2)


def test_principal_moments_of_a_rod_hold_exactly_under_any_rotation():
    rng = np.random.default_rng(3)
    for _ in range(200):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        moments, _ = principal(q @ np.asarray(ROD) @ q.T)
        assert _holds(moments), moments
        assert sorted(moments) == [0.0, *sorted(moments)[1:]]
        assert sorted(moments)[2] == np.float64(0.215) or abs(sorted(moments)[2] - 0.215) < 1e-12
