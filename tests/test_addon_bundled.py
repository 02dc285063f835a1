"""The built extension in a fresh bpy process that sees none of the venv's packages: the zip
(adfkit's wheel and the dependency wheels at build_wheels.sh's pins, Linux x64) is installed
by Blender's own installer, and the geometry operators run on what it bundles.

The wheels come from PyPI (pip's cache after the first run; 48 MB, scipy alone 35 MB); the
tests skip, saying why, when PyPI cannot be reached. About 8 s with the wheels cached. A second
build without the geometry wheels checks that the operators then say which package is missing."""

from __future__ import annotations

import json
import os
import platform
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("bpy")

ROOT = Path(__file__).resolve().parent.parent
ADDON = ROOT / "addon"
GEOMETRY = ("trimesh", "manifold3d", "coacd", "scipy", "networkx")
LINUX = ("--platform", "manylinux2014_x86_64", "--platform", "manylinux_2_28_x86_64")

pytestmark = pytest.mark.skipif(
    sys.platform != "linux" or platform.machine() != "x86_64", reason="builds the Linux x64 extension"
)


def _pins(with_geometry: bool) -> list[str]:
    script = (ADDON / "build_wheels.sh").read_text()
    text = re.search(r'\npins="([^"]*)"', script).group(1)
    if with_geometry:
        text += " " + re.search(r'\ngeometry_pins="([^"]*)"', script).group(1)
    return text.split()


def _blender_ext() -> Path:
    import importlib.util

    spec = importlib.util.find_spec("bpy")
    hits = list(Path(spec.submodule_search_locations[0]).glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
    if not hits:
        pytest.skip("this bpy build does not ship Blender's extension tool")
    return hits[0]


def build_extension(tmp: Path, with_geometry: bool) -> Path:
    """The extension zip as build_wheels.sh makes it, for Linux x64 only."""
    src = tmp / "addon"
    shutil.copytree(ADDON, src, ignore=shutil.ignore_patterns("wheels", "__pycache__"))
    wheels = src / "wheels"
    wheels.mkdir()
    py = [sys.executable, "-m", "pip"]
    quiet = ["--quiet", "--disable-pip-version-check"]
    res = subprocess.run(
        [*py, "wheel", *quiet, "--no-deps", "--no-build-isolation", "-w", str(wheels), str(ROOT)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    if res.returncode != 0:
        pytest.skip(f"cannot build the adfkit wheel here: {res.stderr[-300:]}")
    res = subprocess.run(
        [*py, "download", *quiet, "--only-binary=:all:", "--python-version", "3.11", *LINUX, "--no-deps"]
        + ["-d", str(wheels), *_pins(with_geometry)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    if res.returncode != 0:
        pytest.skip(f"cannot download the dependency wheels (PyPI unreachable?): {res.stderr[-300:]}")
    sys.path.insert(0, str(src))
    try:
        from manifest_wheels import rewrite
    finally:
        sys.path.pop(0)
        sys.modules.pop("manifest_wheels", None)
    rewrite(src)
    out = tmp / "dist"
    out.mkdir()
    res = subprocess.run(
        [sys.executable, str(_blender_ext()), "build", "--source-dir", str(src), "--output-dir", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert res.returncode == 0, res.stdout + res.stderr
    (zip_path,) = out.glob("adfkit-*.zip")
    return zip_path


def run_fresh(zip_path: Path, tmp: Path) -> dict:
    """tests/bundled_child.py in a Python that sees the standard library, bpy and Blender's numpy
    only (-I -S: no site-packages), with Blender's user folder in ``tmp``."""
    import importlib.util

    site = tmp / "site"
    site.mkdir()
    for name in ("bpy", "numpy"):  # the installed packages (a loaded bpy names Blender's own module)
        pkg = Path(importlib.util.find_spec(name).submodule_search_locations[0])
        (site / pkg.name).symlink_to(pkg)
        if (pkg.parent / f"{pkg.name}.libs").is_dir():
            (site / f"{pkg.name}.libs").symlink_to(pkg.parent / f"{pkg.name}.libs")
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "BLENDER_"))}
    env["BLENDER_USER_RESOURCES"] = str(tmp / "blender-user")
    res = subprocess.run(
        [sys.executable, "-I", "-S", str(Path(__file__).parent / "bundled_child.py"), str(zip_path), str(site)],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp,
        env=env,
    )
    line = next((ln for ln in res.stdout.splitlines() if ln.startswith("RESULT ")), None)
    assert res.returncode == 0 and line, res.stdout[-2000:] + res.stderr[-2000:]
    return json.loads(line[len("RESULT ") :])


def _bundled(found: dict, tmp: Path) -> None:
    """Nothing importable before the install; adfkit from the extension's own site-packages after."""
    assert set(found["before"].values()) == {None}
    assert found["install"] == ["FINISHED"]
    local = str(tmp / "blender-user" / "extensions" / ".local")
    assert found["from"]["adfkit"].startswith(local)


def test_without_its_geometry_wheels_the_operators_say_which_package_is_missing(tmp_path):
    found = run_fresh(build_extension(tmp_path, with_geometry=False), tmp_path)
    _bundled(found, tmp_path)
    ops = found["ops"]
    assert ops["mark_cube"] == ["FINISHED"] and ops["cube"][0] == 1.0  # density x volume needs no trimesh
    for op in ("estimate_inertia", "fit_cylinder", "convex_hull", "decomposition"):
        text = ops[op]
        assert text.startswith("Error: this needs the geometry package '"), (op, text)
        assert "install the adfkit extension built with its geometry wheels" in text and "Traceback" not in text
    assert ops["hull_parts"] == ops["decomposition_parts"] == 0 and ops["cylinder"] == []


def test_geometry_operators_run_on_the_bundled_wheels(tmp_path):
    found = run_fresh(build_extension(tmp_path, with_geometry=True), tmp_path)
    _bundled(found, tmp_path)
    local = str(tmp_path / "blender-user" / "extensions" / ".local")
    assert all(found["from"][m].startswith(local) for m in ("trimesh", "coacd", "scipy", "manifold3d"))
    ops = found["ops"]
    # estimate inertia: a 10 cm cube of 1000 kg/m³ is 1 kg, I = m·(a² + a²)/12
    assert ops["estimate_inertia"] == ["FINISHED"]
    mass, inertia = ops["cube"]
    assert mass == pytest.approx(1.0, rel=1e-6) and inertia == pytest.approx([1.0 * 0.02 / 12] * 3, rel=1e-5)
    # fit primitive: the cylinder found on a 64-sided cylinder mesh of r = 2 cm, l = 10 cm
    assert ops["fit_cylinder"] == ["FINISHED"]
    ((shape, radius, height),) = ops["cylinder"]
    assert shape == "CYLINDER" and radius == pytest.approx(0.02, rel=0.02) and height == pytest.approx(0.1, rel=0.02)
    # convex hull (CoACD, one hull) and decomposition (up to 8) of a ring: R 5 cm, r 1.5 cm at x = 0.6
    assert ops["convex_hull"] == ["FINISHED"] and ops["hull_parts"] == 1
    assert ops["decomposition"] == ["FINISHED"] and 2 <= ops["decomposition_parts"] <= 8
    lo, hi = ops["decomposition_bounds"]
    assert lo == pytest.approx([0.535, -0.065, -0.015], abs=2e-3) and hi == pytest.approx(
        [0.665, 0.065, 0.015], abs=2e-3
    )
