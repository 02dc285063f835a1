"""Play a built SimWorld for a while with a progress bar and write what `adfkit run` and
`adfkit demo` leave behind: report.json and each camera's frames."""

from __future__ import annotations

from pathlib import Path

from .. import jsonout


def play(world, seconds: float, out: Path | None = None, frames: bool = True, scene_label: str = "") -> dict:
    """Run ``seconds`` of simulated time; returns the report (also written to out/report.json,
    with the camera frames beside it, when ``out`` is given)."""
    from ..adf import atomic_write_text
    from ..report import Progress
    from .cameras import save_frames

    steps = int(round(seconds / (world.dt * world.opt.control_substeps)))
    with Progress(steps, "simulating") as bar:
        world.run(seconds, bar)
    report = world.report()
    report.setdefault("engine", getattr(world, "engine", "pybullet"))
    report["scene"] = scene_label
    report["diagnostics"] = [f"{d.rule}: {d.message}" for d in world.diagnostics]
    if out is not None:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        if frames:
            try:
                report["frames"] = save_frames(world, out)
            except RuntimeError as e:  # the MuJoCo engine without a headless OpenGL (CameraUnavailable)
                if type(e).__name__ != "CameraUnavailable":
                    raise
                report["frames"] = []
                report["camera_problem"] = str(e)
        atomic_write_text(out / "report.json", jsonout.dumps(report, indent=2))
    return report


def unstable(report: dict) -> list[str]:
    """Bodies that became NaN, exploded (> 10 m/s) or fell through the floor at the end, and
    every instability the engine met on the way (runner/stability.py: a state reset, a singular
    inertia, NaN, a flung body), with its time."""
    events = [
        f"{e['body'] or 'the scene'}: {e['kind']} at t = {e['time_s']:.3f} s" for e in report.get("instabilities", [])
    ]
    return report["nan"] + report["exploded"] + report["fell_through_floor"] + events


def summary(report: dict) -> str:
    return (
        f"played {report['simulated_time_s']:.2f} s in {report['wall_time_s']:.2f} s "
        f"({report['real_time_factor']:.2f}x real time): {report['bodies']} bodies, {report['joints']} joints, "
        f"{report['steps']} steps, max constraint error {report['max_constraint_error_m'] * 1000:.3f} mm"
    )
