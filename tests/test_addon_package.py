"""The extension package, checked with Blender's own extension tool (the `blender_ext.py`
that `blender --command extension ...` runs, shipped inside the bpy wheel)."""

from __future__ import annotations

import importlib.util
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
ADDON = ROOT / "addon"


def _blender_ext() -> Path:
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        pytest.skip("bpy (Blender as a Python module) is not installed")
    hits = list(Path(spec.submodule_search_locations[0]).glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
    if not hits:
        pytest.skip("this bpy build does not ship Blender's extension tool")
    return hits[0]


def _run(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(_blender_ext()), *args], capture_output=True, text=True, timeout=300)


def test_manifest_passes_blenders_validation():
    res = _run("validate", str(ADDON))
    assert res.returncode == 0, res.stdout + res.stderr
    assert "Success" in res.stdout


def test_manifest_wheel_list_is_rewritten_from_the_wheels_present(tmp_path):
    sys.path.insert(0, str(ADDON))
    try:
        from manifest_wheels import rewrite
    finally:
        sys.path.pop(0)
    shutil.copy(ADDON / "blender_manifest.toml", tmp_path)
    (tmp_path / "wheels").mkdir()
    for name in (
        "adfkit-0.1.0-py3-none-any.whl",
        "rpds_py-1-cp311-cp311-win_amd64.whl",
        "rpds_py-1-cp311-cp311-manylinux_2_17_x86_64.manylinux2014_x86_64.whl",
    ):
        (tmp_path / "wheels" / name).write_bytes(b"")
    text = rewrite(tmp_path)
    assert '"./wheels/rpds_py-1-cp311-cp311-win_amd64.whl",' in text
    assert 'platforms = ["linux-x64", "windows-x64"]' in text
    assert text.count("./wheels/") == 3


def test_extension_builds_with_blenders_tool_and_bundles_adfkit(tmp_path):
    """Offline build: the adfkit wheel only (build_wheels.sh adds the downloaded dependencies)."""
    src = tmp_path / "addon"
    shutil.copytree(ADDON, src, ignore=shutil.ignore_patterns("wheels", "__pycache__"))
    (src / "wheels").mkdir()
    pip = subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "--quiet",
            "--no-deps",
            "--no-build-isolation",
            "-w",
            str(src / "wheels"),
            str(ROOT),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    if pip.returncode != 0:
        pytest.skip(f"cannot build the adfkit wheel here: {pip.stderr[-300:]}")
    sys.path.insert(0, str(src))
    try:
        from manifest_wheels import rewrite
    finally:
        sys.path.pop(0)
    rewrite(src)
    out = tmp_path / "dist"
    out.mkdir()
    res = _run("build", "--source-dir", str(src), "--output-dir", str(out))
    assert res.returncode == 0, res.stdout + res.stderr
    (zip_path,) = out.glob("adfkit-*.zip")
    names = set(zipfile.ZipFile(zip_path).namelist())
    assert {"blender_manifest.toml", "__init__.py", "export.py", "operators.py"} <= names
    assert any(n.startswith("wheels/adfkit-") and n.endswith(".whl") for n in names)
    assert "build_wheels.sh" not in names and not any("__pycache__" in n for n in names)
    assert _run("validate", str(zip_path)).returncode == 0


def test_geometry_packages_are_bundled_at_the_tested_versions():
    """build_wheels.sh downloads the geometry wheels at the versions this suite runs with,
    and the manifest lists them for every platform (Generate convex collision in Blender)."""
    import importlib.metadata
    import re

    script = (ADDON / "build_wheels.sh").read_text()
    pins = dict(re.findall(r"([A-Za-z0-9_.-]+)==([0-9][^\s\"]*)", script.split("geometry_pins=", 1)[1].split("\n")[0]))
    assert set(pins) == {"trimesh", "manifold3d", "coacd", "scipy", "networkx"}
    for name, version in pins.items():
        try:
            assert importlib.metadata.version(name) == version, name
        except importlib.metadata.PackageNotFoundError:
            pytest.skip(f"{name} is not installed here")
    manifest = (ADDON / "blender_manifest.toml").read_text()
    for name in ("coacd", "manifold3d", "scipy"):  # binary: one wheel per platform
        listed = re.findall(rf'"\./wheels/({name}-[^"]+)"', manifest)
        assert len(listed) == 3 and any("win_amd64" in w for w in listed) and any("macosx" in w for w in listed)
