"""`adfkit decompose MESH`: convex decomposition (CoACD) into a hull OBJ for ADF collision."""

from __future__ import annotations

import sys

from .. import jsonout

NAME = "decompose"
HELP = "convex decomposition of a mesh (CoACD) into one OBJ with a sub-mesh per hull"


def add_arguments(p) -> None:
    p.add_argument("mesh", help="mesh file (STL, OBJ, PLY, DAE)")
    p.add_argument("-o", "--output", help="output OBJ (default: MESH_hulls.obj beside the input)")
    p.add_argument("--max-hulls", type=int, default=16, help="upper bound on the hull count (default 16)")
    p.add_argument("--threshold", type=float, default=0.05, help="CoACD concavity threshold (default 0.05)")
    p.add_argument("--seed", type=int, default=0, help="random seed (same seed, same hulls)")
    p.add_argument("--resolution", type=int, default=30, help="pre-processing resolution (default 30)")
    p.add_argument("--scale", type=float, default=1.0, help="multiply the mesh by this (ADF 'scale')")
    p.add_argument("--separate", action="store_true", help="also write one OBJ per hull")
    p.add_argument("--no-cache", action="store_true", help="ignore and do not fill the cache")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")


def run(args) -> int:
    from pathlib import Path

    from ..diagnostics import AdfError, error
    from ..geometry.decompose import DecompositionParams, decompose, write_hull_files, write_hulls_obj
    from ..geometry.meshio import load_mesh
    from ..geometry.repair import manifold_volume, repair_mesh
    from ..report import Progress

    if args.max_hulls == 0 or args.max_hulls < -1 or args.threshold <= 0 or args.resolution <= 0:
        raise AdfError(
            error(
                "bad-argument",
                "--max-hulls must be >= 1 (or -1), --threshold and --resolution > 0",
                hint="e.g. --max-hulls 8 --threshold 0.05",
            )
        )
    src = Path(args.mesh)
    out = Path(args.output) if args.output else src.with_name(src.stem + "_hulls.obj")
    params = DecompositionParams(
        threshold=args.threshold, max_hulls=args.max_hulls, preprocess_resolution=args.resolution, seed=args.seed
    )
    with Progress(4, "decompose") as bar:
        mesh = load_mesh(src, scale=args.scale)
        bar.update(1, suffix="repairing")
        solid, report = repair_mesh(mesh)
        bar.update(1, suffix="running CoACD")
        result = decompose(solid, params, use_cache=not args.no_cache)
        bar.update(1, suffix="writing")
        write_hulls_obj(result.hulls, out)
        if args.separate:
            write_hull_files(result.hulls, out.parent, out.stem)
        union = manifold_volume(result.hulls)
        bar.update(1, suffix="done")
    summary = {
        "input": str(src),
        "output": str(out),
        "repair": report.summary(),
        "hulls": len(result.hulls),
        "hull_volumes": result.volumes,
        "input_volume": float(solid.volume),
        "union_volume": union,
        "union_over_input": union / float(solid.volume),
        "seconds": result.seconds,
        "cache_hit": result.cache_hit,
        "adf": {"collision mesh": out.name, "collision mesh type": "CONVEX_HULL"},
    }
    if args.json:
        jsonout.dump(summary, sys.stdout, indent=2)
        sys.stdout.write("\n")
        return 0
    print(f"{src.name}: {report.summary()}")
    print(
        f"{len(result.hulls)} convex hulls in {result.seconds:.2f} s"
        f"{' (cache hit)' if result.cache_hit else ''} -> {out}"
    )
    for i, v in enumerate(result.volumes):
        print(f"  hull_{i:03d}  volume {v:.6g} m³")
    print(
        f"input volume {solid.volume:.6g} m³, union of hulls {union:.6g} m³ ({100 * (union / solid.volume - 1):+.1f}%)"
    )
    print(f"ADF: collision mesh: {out.name}   collision mesh type: CONVEX_HULL")
    return 0
