"""A picture of the collision shapes around one hole pair, as the suture's physics sees them:
the phantom's boxes, the boundary capsules of Entry k and Exit k, their ghosts, and the arc
the planner drives the needle's tip along (with the wire's thickness). Side view in the
needle's plane and top view.

    python -m adfkit.tasks.hole_figure [LAUNCH] [--pair K] [--phantom MODEL.yaml] [--out docs/suture-hole.png]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np


def _box_corners(sb) -> list[np.ndarray]:
    """The 8 corners (8, 3) of each box of a tissue body's collision, in the world."""
    from ..model.semantics import ShapeKind, collision_primitives
    from ..runner.rotations import pose_to_matrix

    t = sb.world_matrix()
    out = []
    for p in collision_primitives(sb.body) or []:
        if p.kind is not ShapeKind.BOX:
            continue
        g = p.geometry
        h = np.array([g.x or 0.0, g.y or 0.0, g.z or 0.0]) / 2
        c = np.array([[sx, sy, sz, 1.0] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * np.r_[h, 1.0]
        out.append((c @ (t @ pose_to_matrix(p.pose)).T)[:, :3])
    return out


def _capsules(sb) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """(end a, end b, radius) of each capsule of a hole body, in the world."""
    t = sb.world_matrix()
    out = []
    for s in sb.body.compound_collision_shape or []:
        if (s.shape or "").lower() != "capsule":
            continue
        o = s.offset.position
        c = np.array([o.x, o.y, o.z])
        axis = {"x": 0, "y": 1, "z": 2}[(s.geometry.axis or "z").lower()]
        d = np.zeros(3)
        d[axis] = (s.geometry.height or 0.0) / 2
        a, b = c - d, c + d
        out.append(((t @ np.r_[a, 1])[:3], (t @ np.r_[b, 1])[:3], float(s.geometry.radius)))
    return out


def _hull(points: np.ndarray) -> np.ndarray:
    from scipy.spatial import ConvexHull

    return points[ConvexHull(points).vertices]


def draw(launch: Path, pair: int, out: Path, phantom: Path | None = None) -> None:
    """The figure of pair ``pair`` of the scene (with ``phantom`` in place of its phantom,
    as `adfkit suture --phantom` plays it), in the pair's frame: x from entry to exit, z up."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Polygon

    from ..adf import load_scene
    from ..runner import Options, open_world
    from ..runner.rotations import invert
    from .holes import boundary_body, ghost_box, hole_frame, hole_label, opening_half_extents
    from .needle import wire_radius
    from .suture import SutureTask

    scene = load_scene(launch)
    if phantom is not None:
        from ..scenes.suturing.own_phantom import compose, load_phantom

        scene = compose(scene, load_phantom(Path(phantom), [])).scene
    world = open_world(scene, Options(renderer="tiny", visuals=False))
    try:
        task = SutureTask(world, [pair], seed=0)
        p = task.pairs[0]
        b, psi_x, beyond, _, _ = task.arc_frame(p)
        wire = wire_radius(task)
        e, x = hole_frame(world, p.entry)[:3, 3], hole_frame(world, p.exit)[:3, 3]
        ax_x = x - e
        ax_x[2] = 0.0
        ax_x /= np.linalg.norm(ax_x)
        f = np.eye(4)
        f[:3, 0], f[:3, 1], f[:3, 2], f[:3, 3] = ax_x, np.cross([0.0, 0.0, 1.0], ax_x), [0.0, 0.0, 1.0], (e + x) / 2
        inv = invert(f)

        def local(pts):
            return np.asarray(pts) @ inv[:3, :3].T + inv[:3, 3]

        psi = np.linspace(-task.approach, psi_x + beyond, 200)
        r = task.geom.radius
        arc = local([(b @ np.r_[r * math.cos(a), r * math.sin(a), 0.0, 1.0])[:3] for a in psi])
        holes = {id(boundary_body(g) or g.parent) for g in (p.entry, p.exit)}
        half = opening_half_extents(boundary_body(p.entry).body) if boundary_body(p.entry) else None
        fig, axes = plt.subplots(1, 2, figsize=(10, 4.4), dpi=80)
        side, top = axes
        z_hole = float(local([e])[0, 2])
        for sb in task.tissue():
            if id(sb) in holes:
                continue
            for corners in _box_corners(sb):
                c = local(corners)
                if c[:, 1].min() <= 0.0 <= c[:, 1].max():
                    side.add_patch(Polygon(_hull(c[:, [0, 2]]), fc="#e8b4a8", ec="#a0544a"))
                if c[:, 2].max() > z_hole - 0.005:
                    top.add_patch(Polygon(_hull(c[:, [0, 1]]), fc="#e8b4a8", ec="#a0544a", alpha=0.8))
        for g in (p.entry, p.exit):
            body = boundary_body(g)
            for a, c, rad in _capsules(body) if body is not None else []:
                a, c = local([a])[0], local([c])[0]
                if abs(a[1] - c[1]) > 1e-6:  # across the needle's plane: a circle in the side view
                    side.add_patch(Circle((a[0], a[2]), rad, fc="#5a3030"))
                else:
                    side.plot([a[0], c[0]], [a[2], c[2]], color="#5a3030", lw=1, ls="--")
                top.plot([a[0], c[0]], [a[1], c[1]], color="#5a3030", lw=2.5, solid_capstyle="round")
            gp = world.ghost_pose(g)
            box = ghost_box(g)
            if box is None:
                continue
            corners = np.array(
                [[sx * box[0] / 2, 0.0, sz * box[2] / 2, 1.0] for sx, sz in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
            )
            w = local((corners @ gp.T)[:, :3])
            side.add_patch(Polygon(w[:, [0, 2]], fc=(0.8, 0.04, 0.02, 0.45), ec="none"))
        side.plot(
            arc[:, 0],
            arc[:, 2],
            color="#2060c0",
            lw=max(1.0, 2 * wire * 1000 * 5.5),
            solid_capstyle="butt",
            label=f"needle wire ({2 * wire * 1000:.1f} mm)",
        )
        side.plot(arc[:, 0], arc[:, 2], color="white", lw=0.5)
        top.plot(arc[:, 0], arc[:, 1], color="#2060c0", lw=2)
        for ax in (side, top):
            ax.set_xlim(-0.014, 0.014)
        side.set_ylim(z_hole - 0.010, z_hole + 0.012)
        top.set_ylim(-0.011, 0.011)
        label = f"{hole_label(p.entry)} to {hole_label(p.exit)}"
        side.set_title(f"side view in the needle's plane ({label})", fontsize=10)
        opening = f", opening {2 * half[0] * 1000:.1f} x {2 * half[1] * 1000:.1f} mm" if half is not None else ""
        top.set_title(f"top view: pair {pair}{opening}", fontsize=10)
        for ax, lab in ((side, "up (m)"), (top, "across (m)")):
            ax.set_aspect("equal")
            ax.set_xlabel("from entry to exit (m)")
            ax.set_ylabel(lab)
            ax.tick_params(labelsize=7)
        side.legend(loc="upper right", fontsize=8)
        fig.suptitle(
            "collision shapes: tissue boxes (pink), boundary capsules (dark), ghosts (red), the planned tip arc (blue)",
            fontsize=9,
        )
        fig.tight_layout()
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = out.with_suffix(".tmp.png")
        fig.savefig(tmp)
        plt.close(fig)
        tmp.replace(out)
    finally:
        world.close()


def main(argv=None) -> int:
    root = Path(__file__).resolve().parents[2]
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("launch", nargs="?", default=str(root / "sample_scenes" / "suturing" / "launch.yaml"))
    ap.add_argument("--pair", type=int, default=1)
    ap.add_argument(
        "--phantom", help="a phantom model file, in the scene in place of its phantom (adfkit suture --phantom)"
    )
    ap.add_argument("--out", default="docs/suture-hole.png")
    a = ap.parse_args(argv)
    draw(Path(a.launch), a.pair, Path(a.out), Path(a.phantom) if a.phantom else None)
    print(a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
