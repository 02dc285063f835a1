"""What the suture's plan already knows will go wrong, said before the arms move: a grasp whose
tool, on the best path the planner found, comes into the tissue (a negative clearance). The
physics still judges the pair; the warning names the arm, the tissue body, where and when, so a
modeller reads the cause before the verdict (a phantom sloping 30 degrees across its holes was
played to a `reach` failure in the pick-up with nothing said of the -4.6 mm planned).

A mixin-free helper of SutureTask: it reads the task's plan (plan()) and its tissue and tools."""

from __future__ import annotations

import numpy as np

from ..diagnostics import Diagnostic, warning
from .clearance import Tissue

#: m into the tissue from which the plan's clearance is worth a warning (the tools' collision
#: margins and the field's reading between nodes make a few hundredths of a millimetre noise)
WARN_BELOW = -0.0001
#: the needle's bed that ``adfkit suture --phantom`` lays beside a phantom (own_phantom.TRAY)
BED = "SutureTray"


def _when(task, kind: str, k: int, at: int) -> str:
    """In words, when in the suture the plan's pose ``at`` (an index of its clear_at) comes."""
    p = task.pairs[k]
    if kind == "drive":
        if at == 0:
            return (
                "as it takes the needle from its bed" if k == 0 else f"as it takes the needle back over pair {p.index}"
            )
        if at == 1:
            return f"over {p.entry_name}, before insertion {p.index}"
        return f"in insertion {p.index}"
    _, poses, _ = task.pulls[k]
    return f"in pull {p.index}" if at < len(poses) - 1 else f"lifting the needle out of pull {p.index}"


def _nearest(task, arm: str, ee: np.ndarray, wide: bool) -> tuple[str, float, np.ndarray, object]:
    """The tissue body the tool comes nearest at end-effector pose ``ee``: (its name, the
    clearance m, the tool's point nearest it, the body's source location)."""
    tool = (task.tools_wide if wide else task.tools)[arm]
    pts, radii = tool.points(ee[None])
    pts = pts[0]
    best = None
    for sb in task.roles.tissue:
        d = Tissue([sb], triangles=task.tissue_shapes.triangles).exact(pts, pts.mean(axis=0), 0.05) - radii
        i = int(np.argmin(d))
        if best is None or d[i] < best[1]:
            best = (sb.name, float(d[i]), pts[i], getattr(sb.body, "source", None))
    return best


def _hint(body: str, arm: str) -> str:
    if body == BED:
        return (
            f"the needle's bed ({BED}) stands in {arm}'s way: --phantom lays it beside your line of holes, "
            "raised onto your tissue where that stands higher than the bundled slab (metrics.json: "
            "phantom.needle_bed_raised_m); tissue about level with the holes beside them leaves it lower, "
            "out of the way"
        )
    return (
        f"{body} stands in {arm}'s way there, on every grasp that reaches: the tissue around the holes "
        "rises toward the arm (a slope, a wall); lay the holes on a surface the arms face, or give them room"
    )


def plan_warnings(task) -> list[Diagnostic]:
    """A warning for each planned grasp (the driver's, pair by pair, and the puller's) whose
    tool comes more than WARN_BELOW into the tissue along the plan."""
    out = []
    for kind, grasps, arm in (("drive", task.drive_grasps, task.driver), ("pull", task.pull_grasps, task.puller)):
        for k, g in enumerate(grasps):
            if not g.clearance < WARN_BELOW or g.nearest_ee is None:
                continue
            wide = kind == "drive" and k == 0 and g.nearest_at == 0
            body, _, point, where = _nearest(task, arm, g.nearest_ee, wide)
            at = ", ".join(f"{v * 1000:.1f}" for v in point)
            out.append(
                warning(
                    "plan-tool-in-tissue",
                    f"pair {task.pairs[k].index}, the plan: {arm}'s tool comes {-g.clearance * 1000:.1f} mm into "
                    f"{body} {_when(task, kind, k, g.nearest_at)} (at ({at}) mm), on the grasp that keeps it "
                    "farthest from the tissue: the pair may fail there (tool-hit-tissue, pressed-on-tissue, "
                    "reach)",
                    where,
                    _hint(body, arm),
                )
            )
    return out
