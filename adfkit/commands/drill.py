"""`adfkit drill [SCENE] [--path FILE] [--out DIR]`: drill a scene's voxel volume with the
scene's spherical burr along a straight scripted path (towards the volume's centre, --depth
into the bone) or the waypoints of a tool path file; write the drilled slices, volume.yaml,
surface.stl, metrics.json and drilling.gif into DIR (docs/volumes.md).

Exit status: 0 drilled, 1 drilled but a protected tissue was touched (each one reported as a
warning), 2 bad input."""

from __future__ import annotations

import sys
from pathlib import Path

NAME = "drill"
HELP = "drill a scene's voxel volume along a tool path; write the drilled slices, metrics and a GIF"

ROOT = Path(__file__).resolve().parents[2]
BUNDLED = ROOT / "sample_scenes" / "drilling" / "launch.yaml"


def add_arguments(p) -> None:
    p.add_argument("scene", nargs="?", help="launch file or folder (default: the bundled sample_scenes/drilling)")
    p.add_argument("-l", "--indices", help="launch file: multibody configs to load, as AMBF's -l (e.g. 0,1 or 0-2)")
    p.add_argument("--path", help="tool path file: one waypoint `x y z` (metres, world frame) per line")
    p.add_argument("--out", default="drill-output", help="output folder (default drill-output)")
    p.add_argument(
        "--volume",
        help="which volume: its index (0: the first loaded), its model file (FILE or FILE:NAME) or its name "
        "(default: the scene's only one)",
    )
    p.add_argument(
        "--burr",
        help="the burr's body: a sphere, or a drill mesh whose tip is the burr (default: the body named *burr*)",
    )
    p.add_argument(
        "--burr-radius", type=float, help="m: drill with a sphere of this radius (at a mesh drill's tip: its end)"
    )
    p.add_argument(
        "--protect", action="append", default=[], metavar="TISSUE", help="a tissue the burr must not touch (repeat)"
    )
    p.add_argument("--speed", type=float, default=0.01, help="tool speed along the path, m/s (default 0.01)")
    p.add_argument(
        "--removal-rate",
        type=float,
        default=25.0,
        help="1/s: a voxel inside the burr is removed after 1/rate seconds; 0 removes nothing (default 25)",
    )
    p.add_argument("--depth", type=float, default=0.006, help="scripted path: metres past the surface (0.006)")
    p.add_argument("--frames", type=int, default=40, help="frames of the GIF (default 40)")


def _bad(message: str, hint: str):
    from ..diagnostics import AdfError, error

    return AdfError(error("bad-option", message, None, hint))


def _check_options(args) -> None:
    import math

    for name, v, lo in (("--speed", args.speed, 0.0), ("--depth", args.depth, None)):
        if not math.isfinite(v) or (lo is not None and v <= lo) or abs(v) > 10:
            raise _bad(f"{name} {v} is out of range", f"{name} is in metres (per second), e.g. 0.01")
    if not math.isfinite(args.removal_rate) or not 0 <= args.removal_rate <= 1e4:
        raise _bad(f"--removal-rate {args.removal_rate} is out of range", "0 (no removal) to 10000 per second")
    if not 1 <= args.frames <= 500:
        raise _bad(f"--frames {args.frames} is out of range", "1 to 500")
    r = args.burr_radius
    if r is not None and (not math.isfinite(r) or not 1e-5 <= r <= 0.1):
        raise _bad(f"--burr-radius {r} is out of range", "a radius in metres, 0.00001 to 0.1 (e.g. 0.003 for 6 mm)")


def _scene(args):
    from .. import inputs
    from ..diagnostics import AdfError, error

    if args.scene:
        launch = inputs.scene_file(args.scene)
        inputs.check_file(launch, what="scene file")
        return launch
    if BUNDLED.is_file():
        return BUNDLED
    raise AdfError(
        error("no-scene", "no scene given and no bundled sample", None, "run `adfkit build-scene drilling DIR`")
    )


def _check_out(out: Path, inputs_files) -> None:
    from ..diagnostics import AdfError, error

    if out.exists() and not out.is_dir():
        raise AdfError(error("drill-out", f"--out {out} is a file, not a folder", None, "name a folder to write into"))
    slices = (out / "slices").resolve()
    mine = {Path(f).resolve() for f in inputs_files}
    if any(f.parent == slices for f in mine) or (out / "volume.yaml").resolve() in mine:
        raise AdfError(
            error(
                "drill-out",
                f"--out {out} would write over the volume's own slices",
                None,
                "give another output folder; adfkit never overwrites its input",
            )
        )


def run(args) -> int:
    import time

    import numpy as np

    from ..adf import load_scene, parse_indices
    from ..diagnostics import Severity, warning
    from ..geometry.voxels_edit import BlockSurface
    from ..report import Progress, print_diagnostics
    from ..tasks.drilling import output as outp
    from ..tasks.drilling.inputs import label_colour, read_path_file
    from ..tasks.drilling.prepare import default_path, editable, prepare
    from ..tasks.drilling.task import DrillParams, DrillTask

    _check_options(args)
    launch = _scene(args)
    waypoints = read_path_file(args.path) if args.path else None
    diags: list = []
    scene = load_scene(launch, parse_indices(args.indices), diags)
    if any(d.severity >= Severity.ERROR for d in diags):
        print_diagnostics(diags, sys.stderr)
        return 2
    ds = prepare(scene, args.volume, args.burr, args.protect, args.burr_radius)
    out = Path(args.out)
    _check_out(out, ds.data.files)
    vol = editable(ds)
    if waypoints is None:
        waypoints = default_path(ds, vol, args.depth)
    surface = BlockSurface(vol.values, vol.dimensions, vol.iso)
    params = DrillParams(speed=args.speed, removal_rate=args.removal_rate)
    task = DrillTask(vol, ds.pose, ds.burr_radius, ds.burr_start, waypoints, params, ds.protected, surface)
    every = max(1, task.total_steps // args.frames)
    frames, remesh_s, step_s = [], 0.0, 0.0
    prot_ids = task.protected_ids
    tissue_colours = [None, *(label_colour(r) for r in ds.label_ranges)]
    with Progress(task.total_steps, "drill") as bar:
        for i in range(task.total_steps):
            t0 = time.perf_counter()
            task.step()
            step_s += time.perf_counter() - t0
            if (i + 1) % every == 0 or i + 1 == task.total_steps:
                t0 = time.perf_counter()
                surface.update()
                remesh_s += time.perf_counter() - t0
                local = task.rot.T @ (task.burr - task.origin)
                frames.append(outp.render_frame(vol, local, ds.burr_radius, prot_ids, colours=tissue_colours))
            bar.update(1)
    st = task.state
    names = vol.label_names
    removed = {names[i]: int(st.removed[i]) for i in range(1, len(names))}
    trace = np.array(st.trace) if st.trace else np.zeros((0, 9))
    fmag = np.linalg.norm(trace[:, 4:7], axis=1) if len(trace) else np.zeros(0)
    keep = np.unique(np.linspace(0, len(trace) - 1, min(len(trace), 500)).astype(int)) if len(trace) else []
    protected_hits = {}
    for lid, (t_first, where) in sorted(st.first_touch.items()):
        n = int(np.count_nonzero(vol.protected_hit & (vol.labels == lid)))
        protected_hits[names[lid]] = {"voxels_touched": n, "first_time_s": round(t_first, 6), "first_burr_m": where}
    metrics = {
        "scene": str(launch),
        "volume": ds.volume.identifier,
        "burr": {
            "body": ds.burr_name,
            "sphere": ds.burr_how,
            "radius_m": ds.burr_radius,
            "start_m": ds.burr_start.tolist(),
        },
        "path_m": task.points.tolist(),
        "labels": {  # 0..1 of full scale, or a colour
            n: label_colour(r) or [r[0] / ds.data.unit, r[1] / ds.data.unit if np.isfinite(r[1]) else None]
            for n, r in zip(names[1:], ds.label_ranges)
        },
        "labels_file": ds.labels_file,
        "protected": sorted(ds.protected),
        "voxel_size_m": vol.step.tolist(),
        "voxels_removed": removed,
        "voxels_removed_total": int(sum(removed.values())),
        "volume_removed_m3": float(sum(removed.values()) * vol.voxel_volume),
        "protected_touched": protected_hits,
        "simulated_time_s": round(st.t, 6),
        "steps": st.steps,
        "step_s": params.dt,
        "final_burr_m": task.burr.tolist(),
        "force": {
            "max_n": float(fmag.max()) if len(fmag) else 0.0,
            "mean_in_contact_n": float(fmag[fmag > 0].mean()) if np.any(fmag > 0) else 0.0,
            "pull_max_n": float(trace[:, 8].max()) if len(trace) else 0.0,
            "steps_above_pull_cap": int((fmag > params.max_force).sum()),
            "profile": {
                "t_s": [round(float(trace[k, 0]), 6) for k in keep],
                "force_n": [round(float(fmag[k]), 6) for k in keep],
                "depth_m": [round(float(trace[k, 7]), 9) for k in keep],
                "burr_m": [[round(float(x), 7) for x in trace[k, 1:4]] for k in keep],
            },
        },
        "params": {k: getattr(params, k) for k in params.__dataclass_fields__},
        "surface": {"triangles": surface.triangles, "blocks_remeshed": surface.remeshed},
        "wall_s": {"drilling_per_step": step_s / max(1, st.steps), "remesh_total": remesh_s},
    }
    prefix = ds.volume.images.prefix
    try:
        outp.write_slices(ds.data.files, vol.removed_mask, out / "slices", prefix)
        outp.write_volume_model(ds.volume, ds.model, vol.values.shape[0], prefix, out / "volume.yaml")
        surface.write_stl(out / "surface.stl")
        outp.write_metrics(metrics, out / "metrics.json")
        outp.write_gif(frames, out / "drilling.gif")
    except OSError as exc:
        from ..diagnostics import AdfError, error

        raise AdfError(
            error(
                "drill-out",
                f"cannot write into {out}: {exc.strerror or type(exc).__name__}",
                None,
                "check the folder's permissions and free space",
            )
        ) from None
    where = ds.volume.where("images") or ds.volume.source
    warns = [
        warning(
            "drill-protected",
            f"the burr touched protected tissue '{name}': {h['voxels_touched']} voxels, first at "
            f"t = {h['first_time_s']:.3f} s with the burr at ({', '.join(f'{x:.4f}' for x in h['first_burr_m'])}) m",
            where,
            "keep the tool path away from it" + ("" if args.path else ", or lower --depth"),
        )
        for name, h in protected_hits.items()
    ]
    print_diagnostics(warns, sys.stderr)
    counts = ", ".join(f"{n} {c}" for n, c in removed.items())
    print(
        f"burr: {ds.burr_name}, {ds.burr_how}, radius {ds.burr_radius * 1000:.3g} mm\n"
        f"drilled {ds.volume.identifier} for {st.t:.2f} s: {metrics['voxels_removed_total']} voxels removed "
        f"({counts}); peak force {metrics['force']['max_n']:.2f} N; wrote {out}/"
    )
    return 1 if protected_hits else 0
