"""Primitive fits on the meshes a modeller really has: an empty one, a single face, a flat grid,
an open box, two boxes sharing an edge. Each fit encloses every vertex, or says why it cannot."""

from __future__ import annotations

import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh", reason="trimesh (geometry extra) is not installed")

from adfkit.diagnostics import AdfError  # noqa: E402
from adfkit.geometry.primitives import FITTERS, fit_error  # noqa: E402
from adfkit.model.pose import Quat  # noqa: E402


def _grid(n: int = 5) -> trimesh.Trimesh:
    xs = np.linspace(0.0, 0.1, n)
    v = np.array([[x, y, 0.0] for y in xs for x in xs])
    f = [[j * n + i, j * n + i + 1, (j + 1) * n + i + 1] for j in range(n - 1) for i in range(n - 1)]
    f += [[j * n + i, (j + 1) * n + i + 1, (j + 1) * n + i] for j in range(n - 1) for i in range(n - 1)]
    return trimesh.Trimesh(v, f, process=False)


def _meshes() -> dict[str, trimesh.Trimesh]:
    box = trimesh.creation.box([0.01, 0.02, 0.03])
    other = trimesh.creation.box([0.01, 0.02, 0.03]).apply_translation([0.01, 0.02, 0.0])
    return {
        "empty": trimesh.Trimesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=int)),
        "single face": trimesh.Trimesh([[0, 0, 0], [0.01, 0, 0], [0, 0.01, 0]], [[0, 1, 2]], process=False),
        "flat grid": _grid(),
        "open box": trimesh.Trimesh(box.vertices, box.faces[:-2], process=False),
        "non-manifold": trimesh.util.concatenate([box, other]),
    }


# what each fit gives on each mesh: a refusal with its rule, or "fits"
EXPECTED = {
    "empty": dict.fromkeys(FITTERS, "mesh-empty"),
    "single face": {"box": "mesh-flat", "sphere": "fits", "cylinder": "fits", "capsule": "fits"},
    "flat grid": {"box": "mesh-flat", "sphere": "fits", "cylinder": "fits", "capsule": "fits"},
    "open box": dict.fromkeys(FITTERS, "fits"),
    "non-manifold": dict.fromkeys(FITTERS, "fits"),
}


def _inside(entry, pts: np.ndarray, tol: float = 1e-9) -> bool:
    """Every point inside the primitive (in its offset frame)."""
    pose = entry.offset
    rot = np.array(Quat(*pose.orientation).matrix())
    local = (pts - np.array(tuple(pose.position))) @ rot
    g, kind = entry.geometry, entry.shape.lower()
    if kind == "box":
        return bool(np.all(np.abs(local) <= np.array([g.x, g.y, g.z]) / 2 + tol))
    if kind == "sphere":
        return bool(np.all(np.linalg.norm(local, axis=1) <= g.radius + tol))
    a = "xyz".index((g.axis or "z").lower())
    t = local[:, a]
    radial = np.linalg.norm(np.delete(local, a, axis=1), axis=1)
    if kind == "cylinder":
        return bool(np.all(np.abs(t) <= g.height / 2 + tol) and np.all(radial <= g.radius + tol))
    half = g.height / 2 - g.radius  # capsule: distance to the core segment
    d = np.hypot(np.maximum(np.abs(t) - half, 0.0), radial)
    return bool(np.all(d <= g.radius + tol))


@pytest.mark.parametrize("mesh_name", list(EXPECTED))
@pytest.mark.parametrize("kind", list(FITTERS))
def test_every_fit_on_every_degenerate_mesh_encloses_or_says_why(mesh_name, kind):
    mesh = _meshes()[mesh_name]
    want = EXPECTED[mesh_name][kind]
    if want != "fits":
        with pytest.raises(AdfError) as info:
            FITTERS[kind](mesh)
        d = info.value.diagnostics[0]
        assert d.rule == want and d.message and d.hint
        return
    entry = FITTERS[kind](mesh)
    g = entry.geometry
    assert all(v is None or v > 0 for v in (g.x, g.y, g.z, g.radius, g.height))
    assert _inside(entry, np.asarray(mesh.vertices))
    err, volume = fit_error(mesh, entry)
    assert 0.0 <= err <= 1.0 and volume > 0
    if mesh_name in ("single face", "flat grid"):
        assert err == 1.0  # nothing has volume to overlap


def test_an_open_box_fits_its_own_box_exactly():
    entry = FITTERS["box"](_meshes()["open box"])
    assert sorted((entry.geometry.x, entry.geometry.y, entry.geometry.z)) == pytest.approx([0.01, 0.02, 0.03])
    assert fit_error(_meshes()["open box"], entry)[0] == pytest.approx(0.0, abs=1e-9)


def _capsule_volume(r: float, height: float) -> float:
    return np.pi * r * r * (height - 2 * r) + 4.0 / 3.0 * np.pi * r**3


def test_a_capsule_around_a_square_pad_is_the_one_of_least_volume():
    """A 0.2 × 0.2 × 0.004 pad: the thinnest enclosing capsule (radius 0.1) is 0.4 long, since
    its caps must reach the corners; the fit is the capsule of least volume over every radius
    (0.105, 0.346 long), and it encloses the pad."""
    from adfkit.geometry.primitives import capsule_around

    pad = trimesh.creation.box([0.2, 0.2, 0.004])
    entry = FITTERS["capsule"](pad)
    g = entry.geometry
    assert _inside(entry, np.asarray(pad.vertices))
    v = np.asarray(pad.vertices)
    r_thin, h_thin, _ = capsule_around(v, np.zeros(3), np.array([1.0, 0.0, 0.0]))
    assert (r_thin, h_thin) == pytest.approx((np.hypot(0.1, 0.002), 0.4), abs=1e-3)
    assert g.height == pytest.approx(0.346, abs=0.002) and g.radius == pytest.approx(0.105, abs=0.001)
    # no radius on a side's axis (or the diagonal's) encloses the pad in less
    best = np.inf
    for axis in (np.array([1.0, 0.0, 0.0]), np.array([1.0, 1.0, 0.0]) / np.sqrt(2)):
        t, radial = v @ axis, np.linalg.norm(v - np.outer(v @ axis, axis), axis=1)
        for r in np.linspace(radial.max(), 0.2, 4001):
            reach = np.sqrt(np.maximum(r * r - radial**2, 0.0))
            core = max(float((t - reach).max() - (t + reach).min()), 0.0)
            best = min(best, np.pi * r * r * core + 4.0 / 3.0 * np.pi * r**3)
    assert _capsule_volume(g.radius, g.height) <= best * (1 + 1e-4)
    assert _capsule_volume(g.radius, g.height) < 0.95 * _capsule_volume(r_thin, h_thin)
