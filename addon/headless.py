"""Headless entry points used by `adfkit blend-import` / `blend-export` (bpy stays in addon/)."""

from __future__ import annotations

from pathlib import Path

import bpy

from . import register


def ensure_registered() -> None:
    if not hasattr(bpy.types.Object, "adf"):
        register()


def import_to_blend(model: Path, out_blend: Path):
    """Build a fresh scene from an ADF model and save it atomically; returns (objects, diagnostics)."""
    from . import build

    bpy.ops.wm.read_factory_settings(use_empty=True)
    ensure_registered()
    made, diags = build.import_model(Path(model))
    out = Path(out_blend).resolve()
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.tmp.blend")
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp), check_existing=False)
    tmp.replace(out)
    return made, diags


def export_blend(blend: Path, out_dir, name: str, mesh_format: str | None = None):
    """Open a .blend file and export its ADF objects (meshes in ``mesh_format``, default the
    file's export option); returns the export result."""
    from . import export

    bpy.ops.wm.open_mainfile(filepath=str(blend))
    ensure_registered()
    return export.export_scene(bpy.context.scene, out_dir, name, mesh_format=mesh_format)
