"""One suture episode: build the world, drive the SutureTask step by step, observe it, and
write metrics.json, trajectory.png, cameraL.gif and (with ``record``) the dataset.

``run_episode`` is what `adfkit suture` runs and what a Ray fan-out or a Gymnasium wrapper calls.
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from ..scratch import temp_beside
from .metrics import SutureObserver, finite
from .suture import SutureError, SutureTask

GIF_EVERY_S = 1.0  # simulated seconds between GIF frames
GIF_WIDTH = 320  # pixels: the GIF is a preview; cameraL.mp4 has the camera's own resolution
VIDEO_EVERY_S = 0.2  # simulated seconds between video frames (played at 5 fps: real time)
#: Bullet solver iterations for the suture: at AMBF's 10 the needle-thread joint stretches up to
#: 9 mm while the needle is carried and the thread can miss the hole the needle went through
#: (2 of 10 seeds of pair 1); at 50 the thread follows (docs/suture.md has the figures)
SOLVER_ITERATIONS = 50


def _left_camera(world):
    cams = world.cameras
    for c in cams:
        n = c.name.lower()
        if n.endswith("l") or n.endswith("_left") or "left" in n:
            return c
    return cams[0] if cams else None


def _poses(task) -> dict:
    out = {}
    for name, psm in task.psms.items():
        out[name] = {
            "T_world_ee": (psm.base_in_world() @ psm.measured_cp()).tolist(),
            "T_world_base": psm.base_in_world().tolist(),
            "jp": [float(v) for v in psm.measured_jp()],
            "jaw": psm.measured_jaw(),
        }
    return {"needle": task.needle_pose(), "psms": out}


class _Bar:
    """rich progress on a terminal, nothing when piped."""

    def __init__(self, enabled: bool) -> None:
        self.bar = None
        if enabled and sys.stderr.isatty():
            from rich.console import Console
            from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

            self.bar = Progress(
                SpinnerColumn(),
                TextColumn("{task.description}"),
                TimeElapsedColumn(),
                console=Console(file=sys.stderr),
                transient=True,
            )
            self.bar.start()
            self.id = self.bar.add_task("suture")

    def update(self, text: str) -> None:
        if self.bar is not None:
            self.bar.update(self.id, description=text)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()


def play_task(
    world,
    task,
    out: Path | None = None,
    record: bool | str = False,
    every: int = 10,
    gif: bool = True,
    progress: bool = True,
    render_process: bool = True,
) -> tuple[dict, SutureObserver, list]:
    """Drive ``task`` on ``world`` to its end (or failure); returns (metrics, observer, GIF frames).
    ``record``: True or "dataset" for the dataset folder, "rosbag" for a ROS 1 bag.
    ``render_process``: camera L's frames drawn in a process of their own where the world
    allows it (runner.engines.camera_recording), else between the steps."""
    obs = SutureObserver(task)
    writer = None
    if record == "rosbag" and out is not None:
        from ..dataset.rosbag import RosbagWriter

        writer = RosbagWriter(world, Path(out) / "episode.bag")
    elif record and out is not None:
        from ..dataset.writer import DatasetWriter

        writer = DatasetWriter(world, Path(out) / "dataset")
    cam = _left_camera(world) if gif else None
    cdt = world.dt * world.opt.control_substeps
    gif_every = max(1, int(round(GIF_EVERY_S / cdt)))
    video_every = max(1, int(round(VIDEO_EVERY_S / cdt)))
    clock = time.perf_counter
    spent = {"observe_s": 0.0, "render_s": 0.0}
    t0 = clock()
    rec = None
    if cam is not None:
        from ..runner.engines import camera_recording

        a = clock()
        video_path = Path(out) / "cameraL.mp4" if out is not None else None
        rec = camera_recording(world, cam, video_path, 1.0 / (video_every * cdt), GIF_WIDTH, process=render_process)
        spent["render_s"] += clock() - a
    bar = _Bar(progress)
    failure = None
    n = 0
    said = 0  # the plan's warnings printed so far (said as the plan is made, before the arms move)
    try:
        for phase in task.steps():
            if progress and len(getattr(task, "plan_warnings", ())) > said:
                bar.close()
                for w in task.plan_warnings[said:]:
                    print(w, file=sys.stderr)
                said = len(task.plan_warnings)
                bar = _Bar(progress)
            world.step(1)
            a = clock()
            obs.observe()
            b = clock()
            spent["observe_s"] += b - a
            n += 1
            if writer is not None and n % every == 0:
                writer.write(n, _poses(task), phase)
            if rec is not None:
                to_video, to_gif = rec.video_path is not None and n % video_every == 0, n % gif_every == 0
                if to_video or to_gif:
                    rec.frame(to_video, to_gif)
            spent["render_s"] += clock() - b
            if n % 25 == 0:
                rtf = world.sim_time / (time.perf_counter() - t0)
                bar.update(f"{phase}  t={world.sim_time:5.2f} s  {rtf:.2f}x real time")
    except (SutureError, ValueError, KeyError) as exc:
        failure = f"{task.phase}: {exc}"
    finally:
        bar.close()
        if writer is not None:
            writer.close()
        if rec is not None:
            a = clock()
            rec.close()  # the frames still being drawn elsewhere are waited for: they are the episode's time too
            spent["render_s"] += clock() - a
    metrics = obs.metrics(time.perf_counter() - t0, failure)
    spent["physics_s"] = world.wall_time
    spent["planning_and_servo_s"] = metrics["episode_wall_time_s"] - sum(spent.values())
    metrics["where_the_time_goes"] = spent
    if rec is not None and rec.video_path is not None and rec.video_frames:
        metrics["video"] = {
            "file": rec.video_path.name,
            "frames": rec.video_frames,
            "fps": round(rec.fps, 3),
            "width": cam.width,
            "height": cam.height,
            "camera": cam.name,
            "drawn_in": rec.drawn_in,
        }
    if rec is not None and rec.note:
        metrics["pictures_note"] = rec.note
    if writer is not None and record == "rosbag":
        metrics["rosbag"] = {"file": "episode.bag", "frames": writer.frames, "every_control_steps": every}
    elif writer is not None:
        metrics["dataset"] = {"dir": "dataset", "frames": writer.frames, "every_control_steps": every}
    return metrics, obs, (rec.gif if rec is not None else [])


def tissue_outline(task):
    """The tissue bodies' mesh vertices in the world (for the plot), or None (the plot's view,
    around the holes, leaves out a floor's far corners)."""
    from ..adf.paths import collision_mesh_path
    from .needle import obj_vertices

    out = []
    for sb in task.tissue():
        path = collision_mesh_path(sb.model, sb.body)
        if path is not None and path.is_file() and path.suffix.lower() == ".obj":
            v = obj_vertices(path) * (sb.body.scale or 1.0)
            t = sb.world_matrix()
            out.append(v @ t[:3, :3].T + t[:3, 3])
    return np.concatenate(out) if out else None


def plot_trajectory(obs: SutureObserver, task, path: Path, verdicts: list | None = None) -> None:
    """Tip trajectory over the phantom with the holes, top (x-y) and side (x-z) views; with
    ``verdicts`` (metrics' pairs) each pair is marked passed or failed with its rule."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    tip = np.array(obs.tip_path) if obs.tip_path else np.zeros((0, 4))
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), dpi=90)
    tissue = tissue_outline(task)
    holes = [(p.index, task.world.ghost_pose(p.entry)[:3, 3], task.world.ghost_pose(p.exit)[:3, 3]) for p in task.pairs]
    for ax, (i, j), title in ((axes[0], (0, 1), "top view"), (axes[1], (0, 2), "side view")):
        if tissue is not None:
            ax.scatter(tissue[:, i], tissue[:, j], s=1, c="#e8b4a8", label="phantom")
        if len(tip):
            sc = ax.scatter(tip[:, 1 + i], tip[:, 1 + j], s=2, c=tip[:, 0], cmap="viridis", label="needle tip")
        for k, e, x in holes:
            ax.plot(e[i], e[j], "o", mfc="none", mec="tab:blue", ms=9)
            ax.plot(x[i], x[j], "s", mfc="none", mec="tab:red", ms=9)
            ax.annotate(str(k), (e[i], e[j]), textcoords="offset points", xytext=(-12, 4), fontsize=8)
            v = next((p for p in verdicts or [] if p.get("pair") == k), None)
            if v is not None and i == 0 and j == 1:
                ok = v.get("passed")
                ax.annotate(
                    "\u2713 passed" if ok else f"\u2717 {v.get('rule') or 'failed'}",
                    (x[i], x[j]),
                    textcoords="offset points",
                    xytext=(10, -3),
                    fontsize=8,
                    color="tab:green" if ok else "tab:red",
                    weight="bold",
                )
        if holes:
            pts = np.array([h[1] for h in holes] + [h[2] for h in holes])
            lo, hi = pts.min(axis=0) - 0.03, pts.max(axis=0) + 0.03
            if len(tip):
                lo = np.minimum(lo, tip[:, 1:].min(axis=0) - 0.005)
                hi = np.maximum(hi, tip[:, 1:].max(axis=0) + 0.005)
            ax.set_xlim(lo[i], hi[i])
            ax.set_ylim(lo[j], hi[j])
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)" if j == 1 else "z (m)")
        ax.set_title(title + "  (o entry, \u25a1 exit)")
    if len(tip):
        fig.colorbar(sc, ax=axes, label="time (s)", shrink=0.8)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)


def write_outputs(out: Path, metrics: dict, obs, task, frames) -> list[str]:
    from ..adf import atomic_write_text

    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / "metrics.json", json.dumps(finite(metrics), indent=2, allow_nan=False))
    written = ["metrics.json"]
    plot_trajectory(obs, task, out / "trajectory.png", metrics.get("pairs"))
    written.append("trajectory.png")
    if frames:
        import imageio.v2 as imageio

        fd, tmp = temp_beside(out / "cameraL.gif", ".gif")
        os.close(fd)
        imageio.mimsave(tmp, frames, duration=GIF_EVERY_S, loop=0)
        Path(tmp).replace(out / "cameraL.gif")
        written.append("cameraL.gif")
    if metrics.get("video"):
        written.append(metrics["video"]["file"])
    return written


def _order_in(order: list[int]):
    """Sort key: a pair's place in ``order`` (pairs not in it last, by number)."""
    return lambda k: (order.index(k), k) if k in order else (len(order), k)


def run_episode(
    launch,
    indices=None,
    pairs=(1,),
    seed: int = 0,
    out=None,
    record: bool = False,
    gui: bool = False,
    progress: bool = True,
    every: int = 10,
    gif: bool = True,
    options=None,
    engine: str = "pybullet",
    render_process: bool = True,
    phantom=None,
    not_tissue=(),
) -> dict:
    """Play one scripted suture of hole ``pairs`` (None: every whole pair of the scene) on the
    scene; returns the metrics (also written with the pictures to ``out`` when given).
    ``phantom``: a phantom model file put into the scene in place of its phantom
    (scenes/suturing/own_phantom.py); ``not_tissue``: bodies the verdicts do not judge as tissue
    (tasks/roles.py)."""
    from ..adf import load_scene, parse_indices
    from ..runner import Options, open_world

    diags: list = []
    scene = load_scene(Path(launch), parse_indices(indices) if isinstance(indices, str) else indices, diags)
    placed = None
    if phantom is not None:
        from ..scenes.suturing.own_phantom import PhantomError, compose, load_phantom

        try:
            # the needle's bed on the tissue as the engine collides a mesh (sweep.triangles)
            placed = compose(scene, load_phantom(Path(phantom), diags), triangles=engine != "mujoco")
        except PhantomError as exc:
            return {"pairs": [], "all_passed": False, "failure": f"setup: {exc}", "seed": seed}
        scene = placed.scene
    # many frames (the dataset, the GIF): the fastest renderer that works here (cameras.choose_renderer)
    options = options or Options(
        renderer="auto" if record or (gif and out is not None) else "tiny", solver_iterations=SOLVER_ITERATIONS
    )
    world = open_world(scene, options, gui=gui, engine=engine)
    # what the files ask for and the world did not make as asked (a phantom body whose collision
    # mesh is not in its low-resolution folder: AMBF does not make it, nor does the runner), said
    # at once and kept in the metrics: a phantom's skin left out was played without a word
    from ..diagnostics import Severity

    warned = [str(d) for d in list(diags) + list(world.diagnostics) if d.severity >= Severity.WARNING]
    if progress:
        for w in warned:
            print(w, file=sys.stderr)
    try:
        try:
            if placed is not None:  # a phantom's pairs, from the needle's end of its line of holes
                pairs = placed.pairs if pairs is None else sorted(pairs, key=_order_in(placed.pairs))
            elif pairs is None:
                from .suture import hole_pairs

                pairs = [p.index for p in hole_pairs(world)] or [1]
            task = SutureTask(world, list(pairs), seed=seed, not_tissue=not_tissue)
        except (SutureError, KeyError, ValueError) as exc:
            return {"pairs": [], "all_passed": False, "failure": f"setup: {exc}", "seed": seed}
        for k, found in task.check_sweep().items():
            if progress:  # said at once; the run goes on, and its physics judges the pair
                print(f"pair {k}, before the run: {found}", file=sys.stderr)
        metrics, obs, frames = play_task(
            world, task, Path(out) if out else None, record, every, gif and out is not None, progress, render_process
        )
        metrics.update(
            {
                "seed": seed,
                "scene": str(launch),
                "indices": indices if isinstance(indices, str) else None,
                "setup_joint_moves_m": getattr(task, "base_moves", {}),
                "driver": getattr(task, "driver", None),
                "puller": getattr(task, "puller", None),
                "engine": engine,
                "solver_iterations": options.solver_iterations if engine != "mujoco" else None,
                "warnings": warned + [str(d) for d in getattr(task, "plan_warnings", ())],
            }
        )
        if placed is not None:
            metrics["phantom"] = {
                "file": str(phantom),
                "pairs": placed.pairs,
                "placement": [[float(v) for v in row] for row in placed.placement],
                "needle_bed_raised_m": placed.lift_m,
                "needle_bed_turned_deg": placed.bed_turn_deg,
            }
        if out is not None:
            metrics["files"] = write_outputs(Path(out), metrics, obs, task, frames)
            from ..adf import atomic_write_text

            atomic_write_text(Path(out) / "metrics.json", json.dumps(finite(metrics), indent=2, allow_nan=False))
        return finite(metrics)
    finally:
        world.close()
