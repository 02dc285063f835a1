"""adfkit blend-export FILE.blend OUT_DIR: export a .blend scene as an ADF model, headless."""

from __future__ import annotations

NAME = "blend-export"
HELP = "export the ADF objects of a .blend file as an ADF model (needs the bpy module)"


def add_arguments(parser) -> None:
    parser.add_argument("blend", help=".blend file authored with the adfkit add-on")
    parser.add_argument("out_dir", help="folder for MODEL.yaml and its meshes")
    parser.add_argument("--name", default=None, help="model file name without .yaml (default: the .blend name)")
    parser.add_argument(
        "--mesh-format",
        type=str.upper,
        choices=("OBJ", "STL", "PLY", "3DS"),
        default=None,
        help="format of the meshes written (default: the .blend's export option, OBJ unless changed); "
        "AMBF loads OBJ, STL and 3DS, PyBullet and MuJoCo OBJ and STL",
    )


def run(args) -> int:
    from pathlib import Path

    from ..diagnostics import AdfError, SourceLocation, error
    from ..report import print_diagnostics
    from .blend_import import load_addon

    blend = Path(args.blend)
    if not blend.is_file():
        raise AdfError(
            error(
                "missing-file", f"{blend} does not exist", SourceLocation(str(blend)), "give the path of a .blend file"
            )
        )
    _, addon = load_addon()
    res = addon.headless.export_blend(blend, args.out_dir, args.name or blend.stem, mesh_format=args.mesh_format)
    if res.diagnostics:
        print_diagnostics(res.diagnostics)
    if not res.ok:
        print("export failed: nothing was written")
        return 1
    print(f"wrote {res.path} ({len(res.written)} files written, {len(res.skipped)} unchanged meshes kept)")
    return 0
