"""`adfkit score-needle-pose GT.json EST.json`: the challenge's needle pose score (position
error in m, orientation error in rad); the JSON format is in adfkit/tasks/pose_score.py."""

from __future__ import annotations

import json
from pathlib import Path

NAME = "score-needle-pose"
HELP = "position (m) and orientation (rad) error of an estimated needle pose against ground truth"


def add_arguments(p) -> None:
    p.add_argument("gt", help="ground-truth pose JSON")
    p.add_argument("est", help="estimated pose JSON (same number of poses)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")


def _load(path: str, what: str):
    from ..diagnostics import AdfError, SourceLocation, error
    from ..tasks.pose_score import PoseFormatError, read_poses

    p = Path(path)
    if not p.is_file():
        raise AdfError(error("no-file", f"{path} does not exist", None, f"give the {what} pose JSON file"))
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        line, col = getattr(exc, "lineno", 0), getattr(exc, "colno", 0)
        raise AdfError(
            error(
                "bad-json",
                f"not JSON: {exc}",
                SourceLocation(path, line, col),
                'e.g. {"position": [x, y, z], "orientation": [qx, qy, qz, qw]}',
            )
        ) from None
    try:
        return read_poses(doc)
    except PoseFormatError as exc:
        raise AdfError(
            error(
                "bad-pose",
                str(exc),
                SourceLocation(path, 1, 1),
                'e.g. {"position": [x, y, z], "orientation": [qx, qy, qz, qw]}',
            )
        ) from None


def run(args) -> int:
    from ..diagnostics import AdfError, SourceLocation, error
    from ..tasks.pose_score import pose_errors

    gt, est = _load(args.gt, "ground-truth"), _load(args.est, "estimated")
    if len(gt) != len(est):
        raise AdfError(
            error(
                "pose-count",
                f"{len(gt)} ground-truth poses against {len(est)} estimates",
                SourceLocation(args.est, 1, 1),
                "give one estimate per ground-truth pose",
            )
        )
    errs = [pose_errors(g, e) for g, e in zip(gt, est)]
    out = {
        "poses": [{"position_error_m": p, "orientation_error_rad": o} for p, o in errs],
        "mean_position_error_m": sum(p for p, _ in errs) / len(errs),
        "mean_orientation_error_rad": sum(o for _, o in errs) / len(errs),
    }
    if args.json:
        print(json.dumps(out, indent=2, allow_nan=False))
    else:
        for i, (p, o) in enumerate(errs):
            print(f"pose {i}: position error {p:.6f} m, orientation error {o:.6f} rad")
        if len(errs) > 1:
            print(f"mean: {out['mean_position_error_m']:.6f} m, {out['mean_orientation_error_rad']:.6f} rad")
    return 0
