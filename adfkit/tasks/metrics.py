"""Metrics of a suture episode, like the challenge's: per hole pair whether the needle tip
passed its entry then its exit (through the hole ghosts, in order), the time of each phase,
the needle's final pose, the thread pulled through the tissue, the grasp's drift, the largest
constraint error, the real-time factor and whether anything exploded.

``SutureObserver.observe()`` is called once per control step after the world stepped; it
reads the world (ground truth) and the task's state, never commands anything.
"""
from __future__ import annotations

import math

import numpy as np

from ..runner.rotations import invert, matrix_to_quat

HOLE_TOLERANCE = 0.0005   # m beyond the ghost box's sides that still counts as through the hole


def _half_extents(ghost) -> np.ndarray:
    g = getattr(ghost, "geometry", None)
    if g is not None and g.x is not None and g.y is not None:
        return np.array([g.x, g.y, g.z or 0.0]) / 2 * (ghost.scale or 1.0)
    r = getattr(g, "radius", None) if g is not None else None
    return np.array([r, r, r]) if r else np.array([0.0025, 0.0025, 0.0002])


class SutureObserver:
    def __init__(self, task, error_every: int = 10, drift_every: int = 5) -> None:
        self.task, self.world = task, task.world
        self.error_every, self.drift_every = error_every, drift_every
        self.n = 0
        self.tip_path: list[list[float]] = []        # [t, x, y, z]
        self.crossings: dict[str, list] = {}        # ghost name -> [(t, inward)]
        self.prev_local: dict[str, np.ndarray] = {}
        self.max_constraint_error = 0.0
        self.max_drift = 0.0
        self.drift_samples = 0
        self.drift_by_phase: dict[str, float] = {}
        self.thread_seen: dict[int, set] = {p.index: set() for p in task.pairs}
        self.thread = [sb for sb in self.world.bodies
                       if sb.model is task.needle.model and "thread" in (sb.body.name or sb.body.identifier).lower()]
        self._thread_ids = {id(sb) for sb in self.thread}
        self.ghosts = [(p.index, "entry", p.entry_name, p.entry) for p in task.pairs] + \
                      [(p.index, "exit", p.exit_name, p.exit) for p in task.pairs]
        self.half = {name: _half_extents(g.ghost) for _, _, name, g in self.ghosts}

    def observe(self) -> None:
        t = self.world.sim_time
        tip = self.task.tip_world()
        self.tip_path.append([t, *map(float, tip)])
        for _k, _kind, name, g in self.ghosts:
            local = (invert(self.world.ghost_pose(g)) @ np.r_[tip, 1.0])[:3]
            prev = self.prev_local.get(name)
            self.prev_local[name] = local
            if prev is None or (prev[2] > 0) == (local[2] > 0):
                continue
            s = prev[2] / (prev[2] - local[2])
            at = prev + s * (local - prev)
            h = self.half[name] + HOLE_TOLERANCE
            if abs(at[0]) <= h[0] and abs(at[1]) <= h[1]:
                self.crossings.setdefault(name, []).append((t, bool(prev[2] > 0)))
        for p in self.task.pairs:
            for sb in p.exit.overlapping:
                if id(sb) in self._thread_ids:
                    self.thread_seen[p.index].add(id(sb))
        self.n += 1
        if self.n % self.error_every == 0:
            self.max_constraint_error = max(self.max_constraint_error, self.world.constraint_error())
        if self.n % self.drift_every == 0 and self.task.holder is not None and self.task.held_ee_in_needle is not None:
            psm = self.task.psms[self.task.holder]
            ee = psm.base_in_world() @ psm.measured_cp()
            expected = ee @ invert(self.task.held_ee_in_needle)
            drift = float(np.linalg.norm(expected[:3, 3] - self.task.needle_pose()[:3, 3]))
            self.max_drift = max(self.max_drift, drift)
            kind = self.task.phase.split()[0]
            self.drift_by_phase[kind] = max(self.drift_by_phase.get(kind, 0.0), drift)
            self.drift_samples += 1

    def element_length(self) -> float:
        if len(self.thread) < 2:
            return 0.0
        c = np.array([sb.com_position() for sb in self.thread])
        return float(np.median(np.linalg.norm(np.diff(c, axis=0), axis=1)))

    def pair_results(self) -> list[dict]:
        out = []
        for p in self.task.pairs:
            e = self.crossings.get(p.entry_name, [])
            x = self.crossings.get(p.exit_name, [])
            t_in = next((t for t, inward in e if inward), None)
            t_out = next((t for t, inward in x if not inward and (t_in is None or t > t_in)), None)
            out.append({"pair": p.index, "entry": p.entry_name, "exit": p.exit_name,
                        "entry_passed_s": t_in, "exit_passed_s": t_out,
                        "passed": t_in is not None and t_out is not None and t_out > t_in,
                        "thread_elements_through": len(self.thread_seen[p.index])})
        return out

    def phases(self) -> list[dict]:
        log = self.task.phase_log
        out = []
        for i, (name, t0) in enumerate(log):
            t1 = log[i + 1][1] if i + 1 < len(log) else self.world.sim_time
            out.append({"phase": name, "start_s": t0, "duration_s": t1 - t0})
        return out

    def metrics(self, wall_s: float, failure: str | None = None) -> dict:
        rep = self.world.report()
        n = self.task.needle_pose()
        pairs = self.pair_results()
        through = sum(p["thread_elements_through"] for p in pairs) * self.element_length()
        return {
            "pairs": pairs,
            "all_passed": (bool(pairs) and all(p["passed"] for p in pairs) and failure is None
                           and not rep.get("instabilities")),   # an engine that blew up passes nothing
            "failure": failure,
            "phases": self.phases(),
            "needle_final_pose": {"position": [float(v) for v in n[:3, 3]],
                                  "orientation": [float(v) for v in matrix_to_quat(n[:3, :3])]},
            "thread_length_through_tissue_m": through,
            "grasp_drift_max_m": self.max_drift if self.drift_samples else None,
            "grasp_drift_by_phase_m": self.drift_by_phase,
            "max_constraint_error_m": max(self.max_constraint_error, rep["max_constraint_error_m"]),
            "simulated_time_s": self.world.sim_time,
            "physics_wall_time_s": self.world.wall_time,
            "episode_wall_time_s": wall_s,
            "real_time_factor": self.world.sim_time / wall_s if wall_s > 0 else None,
            "physics_real_time_factor": (self.world.sim_time / self.world.wall_time) if self.world.wall_time else None,
            "exploded": bool(rep["exploded"] or rep["nan"] or rep.get("instabilities")),
            "exploded_bodies": rep["exploded"] + rep["nan"] + [e["body"] for e in rep.get("instabilities", [])
                                                                if e["body"]],
            "instabilities": rep.get("instabilities", []),   # runner/stability.py: time, body, kind, message
            "control_steps": self.n,
            "clipped_setpoints": self.task.clipped,
        }


def finite(obj):
    """The metrics with every non-finite float replaced by None (strict JSON)."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite(v) for v in obj]
    if isinstance(obj, (np.floating, np.integer)):
        return finite(obj.item())
    return obj
