"""Rewrite the `wheels` and `platforms` lists of blender_manifest.toml from addon/wheels/.

Blender needs every bundled wheel listed by exact file name; run by build_wheels.sh after it
downloads them, so the manifest never names a wheel that is not there."""

from __future__ import annotations

import re
import sys
from pathlib import Path

PLATFORM_TAGS = {"manylinux": "linux-x64", "macosx": "macos-arm64", "win_amd64": "windows-x64"}


def platforms_of(name: str) -> set[str]:
    return {p for tag, p in PLATFORM_TAGS.items() if tag in name}


def rewrite(addon_dir: Path) -> str:
    wheels = sorted(p.name for p in (addon_dir / "wheels").glob("*.whl"))
    if not wheels:
        raise SystemExit(f"no wheels in {addon_dir / 'wheels'}")
    platforms = sorted(set().union(*(platforms_of(w) for w in wheels))) or ["linux-x64", "macos-arm64", "windows-x64"]
    manifest = addon_dir / "blender_manifest.toml"
    text = manifest.read_text(encoding="utf-8")
    block = "wheels = [\n" + "".join(f'  "./wheels/{w}",\n' for w in wheels) + "]"
    text = re.sub(r"(?ms)^wheels = \[.*?^\]", lambda _m: block, text)
    text = re.sub(
        r"(?m)^platforms = \[.*\]$", lambda _m: "platforms = [" + ", ".join(f'"{p}"' for p in platforms) + "]", text
    )
    manifest.write_text(text, encoding="utf-8")
    return text


if __name__ == "__main__":
    rewrite(Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parent))
