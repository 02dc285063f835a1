"""Drilling a voxel volume with a spherical burr along a tool path, as AMBF's volumetric
drilling plugins do: the burr is coupled by a spring to a target that moves along the path;
the solid voxels inside the burr push it back (:meth:`EditableVolume.burr_step`), so it
advances into bone only as fast as the burr wears the voxels away; tissue voxels inside it are
worn at ``removal_rate`` and removed, counted per label; a protected tissue touched is reported.

The burr's motion is quasi-static (admittance): each control step of ``dt`` it moves by
dt·(F_coupling + F_contact)/damping. With the defaults below one step is stable for any
contact (dt·stiffness/damping = 0.5) and the burr lags its target by 0.4 mm in free air at
10 mm/s; against bone it stops where the contact force balances the coupling's, which is
capped at ``max_force``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ...geometry.voxels_edit import BlockSurface, EditableVolume


@dataclass
class DrillParams:
    speed: float = 0.01  # m/s of the target along the path
    dt: float = 1e-3  # s per control step
    removal_rate: float = 25.0  # 1/s: a tissue voxel inside the burr is gone after 1/rate s
    stiffness: float = 20_000.0  # N/m of the bone's contact penalty
    coupling: float = 1000.0  # N/m between the target and the burr
    max_force: float = 5.0  # N: the coupling's force is capped here (the hand's push)
    damping: float = 40.0  # N·s/m of the burr's motion
    dwell: float = 0.25  # s the target rests at the last waypoint


@dataclass
class DrillState:
    t: float = 0.0
    steps: int = 0
    removed: np.ndarray | None = None  # per label id
    first_touch: dict[int, tuple[float, list[float]]] = field(default_factory=dict)  # protected label -> (t, where)
    trace: list[tuple[float, float, float, float, float, float, float, float, float]] = field(default_factory=list)
    # per step: t, burr x, y, z (world), contact force x, y, z (world, N), deepest penetration (m),
    # the coupling's pull (N, at most max_force)


class DrillTask:
    """The burr, its path and the volume; :meth:`step` is one control step."""

    def __init__(
        self,
        volume: EditableVolume,
        volume_pose: np.ndarray,
        radius: float,
        start: np.ndarray,
        waypoints: np.ndarray,
        params: DrillParams | None = None,
        protected: set[str] | None = None,
        surface: BlockSurface | None = None,
    ):
        self.vol, self.pose, self.radius = volume, np.asarray(volume_pose, dtype=float), float(radius)
        self.rot, self.origin = self.pose[:3, :3], self.pose[:3, 3]
        self.p = params or DrillParams()
        self.surface = surface
        self.points = np.vstack([np.asarray(start, dtype=float)[None, :], np.asarray(waypoints, dtype=float)])
        seg = np.linalg.norm(np.diff(self.points, axis=0), axis=1)
        self.cum = np.concatenate([[0.0], np.cumsum(seg)])
        self.burr = self.points[0].copy()
        names = volume.label_names
        self.protected_ids = np.array([i for i, n in enumerate(names) if n in (protected or set())], dtype=np.int64)
        self.state = DrillState(removed=np.zeros(len(names), dtype=np.int64))

    @property
    def length(self) -> float:
        return float(self.cum[-1])

    @property
    def duration(self) -> float:
        return self.length / self.p.speed + self.p.dwell

    @property
    def total_steps(self) -> int:
        return int(math.ceil(self.duration / self.p.dt - 1e-9))

    def target(self, t: float) -> np.ndarray:
        s = min(self.p.speed * t, self.cum[-1])
        k = int(np.searchsorted(self.cum, s, side="right")) - 1
        k = min(max(k, 0), len(self.points) - 2) if len(self.points) > 1 else 0
        if len(self.points) == 1:
            return self.points[0]
        span = self.cum[k + 1] - self.cum[k]
        a = 0.0 if span <= 0 else (s - self.cum[k]) / span
        return self.points[k] + a * (self.points[k + 1] - self.points[k])

    def step(self) -> None:
        st, p = self.state, self.p
        st.t += p.dt
        st.steps += 1
        local = self.rot.T @ (self.burr - self.origin)
        contact, sl, gone = self.vol.burr_step(
            local,
            self.radius,
            p.stiffness,
            p.removal_rate * p.dt,
            self.protected_ids if len(self.protected_ids) else None,
        )
        st.removed += contact.removed
        if gone is not None and self.surface is not None:
            self.surface.mark(sl, gone)
        for lid in self.protected_ids:
            if contact.touched[lid] and int(lid) not in st.first_touch:
                st.first_touch[int(lid)] = (st.t, self.burr.tolist())
        f_contact = self.rot @ contact.force
        pull = p.coupling * (self.target(st.t) - self.burr)
        n = np.linalg.norm(pull)
        if n > p.max_force:
            pull *= p.max_force / n
        self.burr = self.burr + p.dt * (pull + f_contact) / p.damping
        st.trace.append((st.t, *self.burr.tolist(), *f_contact.tolist(), contact.depth, float(np.linalg.norm(pull))))

    def run(self, on_step: Callable[[DrillTask], None] | None = None) -> DrillState:
        for _ in range(self.total_steps):
            self.step()
            if on_step is not None:
                on_step(self)
        return self.state


__all__ = ["DrillParams", "DrillState", "DrillTask"]
