"""A picture of the collision shapes around one hole pair, as the suture's physics sees them:
the phantom's boxes, the boundary capsules of Entry k and Exit k, their ghosts, and the arc
the planner drives the needle's tip along (with the wire's thickness). Side view in the
needle's plane and top view.

    python -m adfkit.tasks.hole_figure [LAUNCH] [--pair K] [--out docs/suture-hole.png]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np


def _boxes(body) -> list[tuple[np.ndarray, np.ndarray]]:
    out = []
    for s in body.compound_collision_shape or []:
        if (s.shape or "").lower() != "box" or s.geometry is None:
            continue
        c = s.offset.position if s.offset is not None and s.offset.position is not None else None
        c = np.array([c.x, c.y, c.z]) if c is not None else np.zeros(3)
        h = np.array([s.geometry.x, s.geometry.y, s.geometry.z]) / 2
        out.append((c - h, c + h))
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


def draw(launch: Path, pair: int, out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Polygon, Rectangle

    from ..adf import load_scene
    from ..runner import Options, open_world
    from .holes import opening_half_extents
    from .needle import wire_radius
    from .suture import SutureTask

    world = open_world(load_scene(launch), Options(renderer="tiny"))
    try:
        task = SutureTask(world, [pair], seed=0)
        p = task.pairs[0]
        b, psi_x, beyond, _, _ = task.arc_frame(p)
        wire = wire_radius(task)
        psi = np.linspace(-task.approach, psi_x + beyond, 200)
        r = task.geom.radius
        arc = np.array([(b @ np.r_[r * math.cos(a), r * math.sin(a), 0.0, 1.0])[:3] for a in psi])
        y_k = world.ghost_pose(p.entry)[1, 3]
        phantom = next(sb for sb in task.tissue() if "phantom" in (sb.body.name or "").lower())
        boxes = _boxes(phantom.body)
        holes = [(p.entry, "Entry"), (p.exit, "Exit")]
        half = opening_half_extents(p.entry.parent.body)
        fig, axes = plt.subplots(1, 2, figsize=(10, 4.4), dpi=80)
        side, top = axes
        for lo, hi in boxes:
            if lo[1] <= y_k <= hi[1]:
                side.add_patch(Rectangle((lo[0], lo[2]), hi[0] - lo[0], hi[2] - lo[2], fc="#e8b4a8", ec="#a0544a"))
            if hi[2] > 0.017:
                top.add_patch(
                    Rectangle((lo[0], lo[1]), hi[0] - lo[0], hi[1] - lo[1], fc="#e8b4a8", ec="#a0544a", alpha=0.8)
                )
        for g, _kind in holes:
            for a, c, rad in _capsules(g.parent):
                if abs(a[1] - c[1]) > 1e-6:  # across the needle's plane: a circle in the side view
                    side.add_patch(Circle((a[0], a[2]), rad, fc="#5a3030"))
                else:
                    side.plot([a[0], c[0]], [a[2], c[2]], color="#5a3030", lw=1, ls="--")
                top.plot([a[0], c[0]], [a[1], c[1]], color="#5a3030", lw=2.5, solid_capstyle="round")
            gp = world.ghost_pose(g)
            geo = g.ghost.geometry
            corners = np.array(
                [[sx * geo.x / 2, 0.0, sz * geo.z / 2, 1.0] for sx, sz in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
            )
            w = corners @ gp.T
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
        side.set_xlim(-0.014, 0.014)
        side.set_ylim(0.012, 0.034)
        top.set_xlim(-0.014, 0.014)
        top.set_ylim(y_k - 0.011, y_k + 0.011)
        side.set_title(f"side view in the needle's plane (y = {y_k * 1000:.0f} mm)", fontsize=10)
        top.set_title(
            f"top view: pair {pair}, opening {2 * half[0] * 1000:.1f} x {2 * half[1] * 1000:.1f} mm", fontsize=10
        )
        for ax, lab in ((side, "z (m)"), (top, "y (m)")):
            ax.set_aspect("equal")
            ax.set_xlabel("x (m)")
            ax.set_ylabel(lab)
            ax.tick_params(labelsize=7)
        side.legend(loc="upper right", fontsize=8)
        fig.suptitle(
            "collision shapes: phantom boxes (pink), boundary capsules (dark), ghosts (red), "
            "the planned tip arc (blue)",
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
    ap.add_argument("--out", default="docs/suture-hole.png")
    a = ap.parse_args(argv)
    draw(Path(a.launch), a.pair, Path(a.out))
    print(a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
