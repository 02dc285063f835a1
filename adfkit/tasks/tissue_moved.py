"""Whether the tissue stood still through a suture. A phantom body with a mass that no joint holds
(``free``) is pushed by the needle, and a pair then fails for where its holes went, not for how
the needle was driven. The observer keeps each tissue body's pose at the start and says, at the
end, which moved or turned, and how far (metrics.json ``tissue_moved``); where a free body moved,
a failed pair's reason says so and `adfkit suture` prints it with the way to hold the phantom.
Hole bodies on springs (the challenge's phantom) move as they are meant to: listed, not blamed."""

from __future__ import annotations

import numpy as np

MOVED_M = 1e-3  # m: a tissue body that moved at least this far is named
TURNED_DEG = 1.0  # degrees: or turned at least this much


def _name(sb) -> str:
    return sb.body.name or sb.body.identifier


def free(sb) -> bool:
    """Whether a body has a mass and no joint of its file holds it as a child."""
    from ..model.tree import find_body

    if not (sb.body.mass or 0.0) > 0.0:
        return False
    joints = getattr(sb.model, "joints", None) or []
    return not any(find_body(sb.model, j.child, j) is sb.body for j in joints)


class TissueStart:
    """The tissue bodies' poses where the suture began."""

    def __init__(self, tissue: list) -> None:
        self.start = [(sb, np.array(sb.world_matrix(), dtype=float), free(sb)) for sb in tissue]

    def moved(self) -> list[dict]:
        """Each tissue body that moved or turned past the thresholds since the start: its name,
        how far it moved (m) and turned (degrees), whether it is ``free``; the farthest first."""
        out = []
        for sb, t0, loose in self.start:
            t = np.asarray(sb.world_matrix(), dtype=float)
            moved = float(np.linalg.norm(t[:3, 3] - t0[:3, 3]))
            r = t0[:3, :3].T @ t[:3, :3]
            turned = float(np.degrees(np.arccos(np.clip((np.trace(r) - 1.0) / 2.0, -1.0, 1.0))))
            if moved >= MOVED_M or turned >= TURNED_DEG:
                out.append({"body": _name(sb), "moved_m": moved, "turned_deg": turned, "free": loose})
        return sorted(out, key=lambda d: (-d["moved_m"], -d["turned_deg"]))


def said(moved: list[dict], most: int = 3) -> str:
    """The ``most`` farthest moved bodies in a few words, and how many more: 'Phantom 3.7 mm,
    16.0°; Skin 1.2 mm, 0.3°; and 2 more'."""
    out = "; ".join(f"{d['body']} {d['moved_m'] * 1000:.1f} mm, {d['turned_deg']:.1f}°" for d in moved[:most])
    return out + (f"; and {len(moved) - most} more" if len(moved) > most else "")
