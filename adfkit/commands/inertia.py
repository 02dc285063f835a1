"""`adfkit inertia MESH --mass M | --density D`: volume, COM and principal inertia."""

from __future__ import annotations

import sys

from .. import jsonout

NAME = "inertia"
HELP = "mass properties of a mesh (volume, COM, principal moments and axes) for ADF"


def add_arguments(p) -> None:
    p.add_argument("mesh", help="mesh file (STL, OBJ, PLY, DAE)")
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--mass", type=float, help="total mass, kg")
    g.add_argument("--density", type=float, help="density, kg/m³")
    p.add_argument("--scale", type=float, default=1.0, help="multiply the mesh by this (ADF 'scale')")
    p.add_argument("--json", action="store_true", help="print JSON for machines")


def run(args) -> int:
    import math

    from ..diagnostics import AdfError, error
    from ..geometry.mass import mesh_mass_properties, to_adf
    from ..geometry.meshio import load_mesh
    from ..geometry.repair import repair_mesh

    value = args.mass if args.mass is not None else args.density
    if not math.isfinite(value) or value <= 0:
        raise AdfError(
            error(
                "bad-argument",
                f"--mass/--density must be positive, got {value}",
                hint="e.g. --mass 0.5 or --density 1000",
            )
        )
    solid, report = repair_mesh(load_mesh(args.mesh, scale=args.scale))
    props = mesh_mass_properties(solid, density=args.density, mass=args.mass)
    moments, axes = props.principal()
    inertia, offset = to_adf(props)
    rpy = offset.rpy()
    out = {
        "mesh": args.mesh,
        "repair": report.summary(),
        "mass": props.mass,
        "volume": props.volume,
        "density": props.density,
        "com": props.com.tolist(),
        "inertia_tensor": props.inertia.tolist(),
        "principal_moments": moments.tolist(),
        "principal_axes": axes.T.tolist(),
        "adf": {
            "mass": props.mass,
            "inertia": {"ix": inertia.ix, "iy": inertia.iy, "iz": inertia.iz},
            "inertial offset": {
                "position": dict(zip("xyz", offset.position)),
                "orientation": dict(zip(("r", "p", "y"), rpy)),
            },
        },
    }
    if args.json:
        jsonout.dump(out, sys.stdout, indent=2)
        sys.stdout.write("\n")
        return 0
    f = lambda v: " ".join(f"{x: .6g}" for x in v)  # noqa: E731
    print(f"{args.mesh}: {report.summary()}")
    print(f"mass      {props.mass:.6g} kg   volume {props.volume:.6g} m³   density {props.density:.6g} kg/m³")
    print(f"COM       {f(props.com)} m")
    print(f"moments   {f(moments)} kg·m²")
    for i, a in enumerate(axes.T):
        print(f"axis {i}    {f(a)}")
    print("ADF:")
    print(f"  mass: {props.mass:.9g}")
    print(f"  inertia: {{ix: {inertia.ix:.9g}, iy: {inertia.iy:.9g}, iz: {inertia.iz:.9g}}}")
    p = offset.position
    print(
        f"  inertial offset: {{position: {{x: {p[0]:.9g}, y: {p[1]:.9g}, z: {p[2]:.9g}}}, "
        f"orientation: {{r: {rpy[0]:.9g}, p: {rpy[1]:.9g}, y: {rpy[2]:.9g}}}}}"
    )
    return 0
