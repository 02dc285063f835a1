"""adfkit blend-import MODEL.yaml OUT.blend: build a Blender scene from an ADF model, headless."""

from __future__ import annotations

NAME = "blend-import"
HELP = "import an ADF model into a new .blend file (needs the bpy module)"


def add_arguments(parser) -> None:
    parser.add_argument("model", help="ADF model file")
    parser.add_argument("out_blend", help=".blend file to write")


def load_addon():
    """The adfkit add-on package (addon/ beside this package), registered, and its bpy.

    bpy itself is imported only inside addon/ (addon/headless.py)."""
    import importlib
    import importlib.util
    import sys
    from pathlib import Path

    from ..diagnostics import AdfError, error

    name = "adfkit_blender_addon"
    if name not in sys.modules:
        root = Path(__file__).resolve().parents[2] / "addon"
        if not (root / "__init__.py").is_file():
            raise AdfError(
                error("no-addon", f"the Blender add-on is not at {root}", None, "run from a source checkout of adfkit")
            )
        spec = importlib.util.spec_from_file_location(
            name, root / "__init__.py", submodule_search_locations=[str(root)]
        )
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod
        spec.loader.exec_module(mod)
    mod = sys.modules[name]
    try:
        headless = importlib.import_module(f"{name}.headless")
    except ImportError as exc:
        if "bpy" not in str(exc):
            raise
        raise AdfError(
            error(
                "no-bpy",
                "the bpy module (Blender as a Python module) is not installed",
                None,
                "pip install bpy (Python 3.11), or run inside Blender",
            )
        ) from None
    headless.ensure_registered()
    for sub in ("export", "build", "gather", "render", "authoring"):
        importlib.import_module(f"{name}.{sub}")
    return headless.bpy, mod


def run(args) -> int:
    from pathlib import Path

    from ..report import print_diagnostics

    _, addon = load_addon()
    made, diags = addon.headless.import_to_blend(Path(args.model), Path(args.out_blend))
    if diags:
        print_diagnostics(diags)
    print(f"wrote {Path(args.out_blend).resolve()} ({len(made)} objects)")
    return 0
