"""Two traces side by side: the bodies matched by name (two of one name by where they start),
each one's position and orientation gap at every common sample, the joints' values likewise,
and what one side created and the other did not; the verdict against the tolerances."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .spread import Nudge, within
from .traces import KINDS, Trace


@dataclass
class Gap:
    """One matched body's (or joint's) gap over the common samples."""

    name: str
    position: np.ndarray  # (S,) m (a joint: its value's gap, rad or m)
    angle: np.ndarray  # (S,) degrees (a joint: zeros)

    @property
    def max_position(self) -> float:
        return float(np.nanmax(self.position)) if self.position.size else 0.0

    @property
    def max_angle(self) -> float:
        return float(np.nanmax(self.angle)) if self.angle.size else 0.0


@dataclass
class Comparison:
    ambf: Trace
    adfkit: Trace
    times: np.ndarray
    bodies: list[Gap]
    joints: list[Gap]
    only_in_ambf: list[dict]
    only_in_adfkit: list[dict]
    tolerance_m: float
    tolerance_deg: float
    notes: list[str] = field(default_factory=list)
    tips: list[str] = field(default_factory=list)  # the tool tips' names (traces.tool_tips)
    # each side's joints standing open (openings.py), by side: "ambf" and the engine's
    opening: dict = field(default_factory=dict)
    # what the adfkit world met on the way (runner/stability.py: a MuJoCo state reset, NaN, a flung
    # body), each with its time: its poses from then on are not the physics' answer
    unstable: list[str] = field(default_factory=list)
    # a matched body whose pose stops being a number on one side (AMBF's world blowing up, as under
    # a zero joint axis or a zero moment of inertia in contact): side, name, the first such time
    not_a_number: list[dict] = field(default_factory=list)
    # a matched body of AMBF's flung by its solver (faster than runner.stability.FLUNG_SPEED between two
    # samples: AMBF's world blowing up, as its thread at its capsules' inertia moved off its plane by
    # 1 nm), the first such time and the speed; adfkit's own are in ``unstable`` (its world's watch)
    flung: list[dict] = field(default_factory=list)
    # AMBF against itself with its dynamic roots nudged (spread.py), by body name: the largest position
    # (m) and angle (°) gap to its unnudged run; None: not measured (no --spread)
    spread: dict[str, tuple[float, float]] | None = None
    nudge: Nudge | None = None
    spread_notes: list[str] = field(default_factory=list)  # what the nudged AMBF run met (flung, NaN)

    def past(self, g: Gap) -> bool:
        """The body's gap passes a tolerance."""
        return g.max_position > self.tolerance_m or g.max_angle > self.tolerance_deg

    def within_spread(self, g: Gap) -> bool:
        """The body's gap passes a tolerance but is within AMBF's own spread (spread.within)."""
        s = (self.spread or {}).get(g.name)
        return (
            s is not None
            and self.past(g)
            and within(g.max_position, g.max_angle, *s, self.tolerance_m, self.tolerance_deg)
        )

    @property
    def tip_gaps(self) -> list[Gap]:
        """The tool tips' gaps, the worst first."""
        return [g for g in self.bodies if g.name in self.tips]

    @property
    def worst(self) -> tuple[Gap | None, Gap | None]:
        """The bodies with the largest position and angle gaps."""
        if not self.bodies:
            return None, None
        return max(self.bodies, key=lambda g: g.max_position), max(self.bodies, key=lambda g: g.max_angle)

    def failures(self) -> list[str]:
        """Why the sides disagree past the tolerances (empty: they agree)."""
        out = [
            f"{g.name}: {g.max_position * 1e3:.3f} mm, {g.max_angle:.3f}°"
            for g in self.bodies
            if self.past(g) and not self.within_spread(g)
        ]
        out += [f"only in AMBF: {d['kind']} {d['name']}" for d in self.only_in_ambf]
        out += [f"only in adfkit: {d['kind']} {d['name']}" for d in self.only_in_adfkit]
        out += [f"adfkit {self.adfkit.side} unstable: {u}" for u in self.unstable]
        out += [
            f"{'AMBF' if d['side'] == 'ambf' else 'adfkit ' + d['side']}'s {d['name']} is not a number from {d['from_s']:.3f} s"
            for d in self.not_a_number
        ]
        out += [f"AMBF's {d['name']} is flung ({d['speed_m_s']:.3g} m/s) from {d['from_s']:.3f} s" for d in self.flung]
        return out

    def as_json(self) -> dict:
        pos, ang = self.worst
        return {
            "engine": self.adfkit.side,
            "seconds": float(self.times[-1]) if self.times.size else 0.0,
            "samples": int(self.times.size),
            "tolerance_m": self.tolerance_m,
            "tolerance_deg": self.tolerance_deg,
            "agree": not self.failures(),
            "bodies_compared": len(self.bodies),
            "bodies": [
                {
                    "name": g.name,
                    "max_position_gap_m": g.max_position,
                    "max_angle_gap_deg": g.max_angle,
                    "final_position_gap_m": float(g.position[-1]) if g.position.size else 0.0,
                    "final_angle_gap_deg": float(g.angle[-1]) if g.angle.size else 0.0,
                    "at_s": float(self.times[int(np.nanargmax(g.position))]) if g.position.size else 0.0,
                }
                | self._spread_json(g)
                for g in self.bodies
            ],
            "largest_position_gap": {"name": pos.name, "m": pos.max_position} if pos else None,
            "largest_angle_gap": {"name": ang.name, "deg": ang.max_angle} if ang else None,
            "joints": [{"name": g.name, "max_value_gap": g.max_position} for g in self.joints],
            "tool_tips": [
                {"name": g.name, "max_position_gap_m": g.max_position, "max_angle_gap_deg": g.max_angle}
                for g in self.tip_gaps
            ],
            "only_in_ambf": self.only_in_ambf,
            "only_in_adfkit": self.only_in_adfkit,
            "wall_s": {"ambf": self.ambf.wall_s, self.adfkit.side: self.adfkit.wall_s},
            "notes": self.notes,
            "adfkit_unstable": self.unstable,
            "not_a_number": self.not_a_number,
            "flung": self.flung,
            "joint_opening": {side: o.as_json() for side, o in self.opening.items()},
        } | ({"ambf_spread": self.spread_summary()} if self.spread is not None else {})

    def _spread_json(self, g: Gap) -> dict:
        if self.spread is None:
            return {}
        pos, ang = self.spread.get(g.name, (None, None))
        return {
            "ambf_spread_position_m": pos,
            "ambf_spread_angle_deg": ang,
            "within_ambf_spread": self.within_spread(g),
        }

    def spread_summary(self) -> dict:
        """AMBF's own spread for the JSON and the text: the nudge, the largest spreads, and the
        bodies past the tolerances within it."""
        spread = self.spread or {}
        pos = max(spread.items(), key=lambda kv: kv[1][0], default=None)
        ang = max(spread.items(), key=lambda kv: kv[1][1], default=None)
        n = self.nudge
        return {
            "nudge_m": n.by_m if n else None,
            "nudges": n.directions if n else [],
            "nudged_bodies": n.moved if n else [],
            "not_nudged": n.not_moved if n else [],
            "largest_position": {"name": pos[0], "m": pos[1][0]} if pos else None,
            "largest_angle": {"name": ang[0], "deg": ang[1][1]} if ang else None,
            "past_tolerance": sum(1 for g in self.bodies if self.past(g)),
            "within_ambf_spread": [g.name for g in self.bodies if self.within_spread(g)],
            "nudged_run": self.spread_notes,
        }


def angle_deg(qa: np.ndarray, qb: np.ndarray) -> np.ndarray:
    """The rotation between quaternions x y z w (…, 4), degrees: 2·atan2(|v|, |w|) of the
    relative quaternion, well conditioned near 0 (an arccos of the dot product turns AMBF's
    quaternions, unit to 4e-10, into 0.003° for the same rotation)."""
    qa = qa / np.linalg.norm(qa, axis=-1, keepdims=True)
    qb = qb / np.linalg.norm(qb, axis=-1, keepdims=True)
    xa, ya, za, wa = np.moveaxis(qa, -1, 0)
    xb, yb, zb, wb = np.moveaxis(qb, -1, 0)
    # conj(qa) * qb
    w = wa * wb + xa * xb + ya * yb + za * zb
    x = wa * xb - xa * wb - ya * zb + za * yb
    y = wa * yb + xa * zb - ya * wb - za * xb
    z = wa * zb - xa * yb + ya * xb - za * wb
    return np.degrees(2 * np.arctan2(np.sqrt(x * x + y * y + z * z), np.abs(w)))


def match(names_a: list[str], names_b: list[str], start_a: np.ndarray, start_b: np.ndarray) -> list[tuple[int, int]]:
    """Pairs (i, j) of the same name; several of one name on both sides are paired by nearest
    starting position (AMBF keeps two bodies of one name apart by where they are)."""
    pairs = []
    by_b: dict[str, list[int]] = {}
    for j, n in enumerate(names_b):
        by_b.setdefault(n, []).append(j)
    by_a: dict[str, list[int]] = {}
    for i, n in enumerate(names_a):
        by_a.setdefault(n, []).append(i)
    for n, ia in by_a.items():
        jb = list(by_b.get(n, []))
        for i in sorted(ia, key=lambda i: min((np.linalg.norm(start_a[i] - start_b[j]) for j in jb), default=0.0)):
            if not jb:
                break
            j = min(jb, key=lambda j: np.linalg.norm(start_a[i] - start_b[j]))
            jb.remove(j)
            pairs.append((i, j))
    return pairs


def _only(a: dict[str, list[str]], b: dict[str, list[str]]) -> list[dict]:
    out = []
    for kind in KINDS:
        rest = list(b.get(kind, []))
        for n in a.get(kind, []):
            if n in rest:
                rest.remove(n)
            else:
                out.append({"kind": kind, "name": n})
    return out


def compare(ambf: Trace, adfkit: Trace, tolerance_m: float = 1e-3, tolerance_deg: float = 1.0) -> Comparison:
    """The two traces side by side at their common sample times."""
    ta, tb = np.round(ambf.times, 6), np.round(adfkit.times, 6)
    common = np.intersect1d(ta, tb)
    ia = np.searchsorted(ta, common)
    ib = np.searchsorted(tb, common)
    from ..runner.stability import FLUNG_SPEED

    bodies, nan, flung = [], [], []
    dt = np.diff(common)
    if ambf.poses.size and adfkit.poses.size:
        for i, j in match(ambf.body_names, adfkit.body_names, ambf.poses[0, :, :3], adfkit.poses[0, :, :3]):
            pa, pb = ambf.poses[ia, i], adfkit.poses[ib, j]
            bodies.append(
                Gap(ambf.body_names[i], np.linalg.norm(pa[:, :3] - pb[:, :3], axis=1), angle_deg(pa[:, 3:], pb[:, 3:]))
            )
            for side, p in ((ambf.side, pa), (adfkit.side, pb)):
                bad = ~np.isfinite(p).all(axis=1)
                if bad.any():
                    nan.append({"side": side, "name": ambf.body_names[i], "from_s": float(common[np.argmax(bad)])})
            if dt.size:  # AMBF's world blowing up: a body thrown faster than anything in a scene moves
                with np.errstate(invalid="ignore"):
                    speed = np.linalg.norm(np.diff(pa[:, :3], axis=0), axis=1) / dt
                fast = speed > FLUNG_SPEED
                if fast.any():
                    k = int(np.argmax(fast))
                    flung.append(
                        {"name": ambf.body_names[i], "from_s": float(common[k + 1]), "speed_m_s": float(speed[k])}
                    )
    joints = []
    for i, j in match(
        ambf.joint_names,
        adfkit.joint_names,
        np.zeros((len(ambf.joint_names), 3)),
        np.zeros((len(adfkit.joint_names), 3)),
    ):
        va, vb = ambf.joints[ia, i], adfkit.joints[ib, j]
        if np.all(np.isnan(va)) or np.all(np.isnan(vb)):
            continue
        gap = va - vb
        if ambf.joint_names[i] in ambf.angular_joints:  # AMBF reads an angle in (-π, π]: 2π apart is no gap
            gap = (gap + np.pi) % (2.0 * np.pi) - np.pi
        joints.append(Gap(ambf.joint_names[i], np.abs(gap), np.zeros(len(common))))
    bodies.sort(key=lambda g: -g.max_position)
    joints.sort(key=lambda g: -g.max_position)
    return Comparison(
        ambf,
        adfkit,
        common,
        bodies,
        joints,
        _only(ambf.made, adfkit.made),
        _only(adfkit.made, ambf.made),
        tolerance_m,
        tolerance_deg,
        not_a_number=nan,
        flung=flung,
    )
