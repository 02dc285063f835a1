"""The three environments: what each rewards and when it is solved.

- NeedleReach: bring psm1's end-effector to the needle's grasp point (within REACH_TOLERANCE).
- NeedlePick: grasp the needle with psm1 and lift it LIFT above where it lay.
- SutureOnePair: drive the needle's tip through entry hole 1 and then out of exit hole 1, detected
  as the challenge (and adfkit suture's metrics) do: the tip crossing each hole ghost, in order.

Dense rewards are negative distances (m, x10) plus stage bonuses; sparse rewards are 0 on
success and -1 otherwise (the SurRoL / Fetch convention).
"""

from __future__ import annotations

import numpy as np

from .env import SuturingEnv

REACH_TOLERANCE = 0.003  # m
LIFT = 0.01  # m


def f32(x) -> np.ndarray:
    """Rewards are computed from positions rounded to the micrometre: a restored world repeats
    a step to ~1e-9 m, not always bit for bit (Bullet keeps some solver state across a
    restore), and a seeded reset plus the same actions must give the same rewards (Gymnasium's
    determinism check)."""
    return np.round(np.asarray(x, float), 6)


class NeedleReach(SuturingEnv):
    arms = ("psm1",)

    def _goal(self) -> np.ndarray:
        return self.grasp_point()

    def _evaluate(self) -> dict:
        d = float(np.linalg.norm(f32(self.tool_position()) - f32(self.grasp_point())))
        return {"dense": -10.0 * d, "success": d < REACH_TOLERANCE, "distance": d}


class NeedlePick(SuturingEnv):
    arms = ("psm1",)

    def _task_reset(self) -> None:
        self._rest_z = float(f32(self.grasp_point())[2])

    def _goal(self) -> np.ndarray:
        g = self.grasp_point()
        if self.holding():
            return np.array([g[0], g[1], self._rest_z + LIFT])
        return g

    def _evaluate(self) -> dict:
        g = f32(self.grasp_point())
        d = float(np.linalg.norm(f32(self.tool_position()) - g))
        held = self.holding()
        lift = float(g[2] - self._rest_z)
        dense = -10.0 * d + (1.0 + 100.0 * min(max(lift, 0.0), LIFT) if held else 0.0)
        return {"dense": dense, "success": bool(held and lift >= LIFT), "distance": d, "held": held, "lift": lift}


class _TipWatch:
    """What adfkit.tasks.metrics.SutureObserver reads of a task: the world, the hole pair, the
    needle and its tip (the challenge's check: the tip through entry k, then out of exit k)."""

    def __init__(self, world, pair: int, psms: dict) -> None:
        from ..tasks.suture import find_needle, hole_pairs

        self.world, self.psms = world, psms  # the arms: robots, not tissue, to the observer
        self.needle, self.geom = find_needle(world)
        self.pairs = [p for p in hole_pairs(world) if p.index == pair]
        if not self.pairs:
            raise ValueError(f"the scene has no entry/exit hole ghost pair {pair}")
        self.holder = self.held_ee_in_needle = None
        self.phase, self.phase_log = "env", []

    def needle_pose(self) -> np.ndarray:
        return self.needle.world_matrix()

    def tip_world(self) -> np.ndarray:
        return (self.needle_pose() @ np.r_[self.geom.tip, 1.0])[:3]


class SutureOnePair(SuturingEnv):
    arms = ("psm1", "psm2")
    pair = 1

    def _task_setup(self) -> None:
        self.watch = _TipWatch(self.world, self.pair, self.psms)
        p = self.watch.pairs[0]
        self.entry, self.exit = p.entry, p.exit

    def _task_reset(self) -> None:
        from ..tasks.metrics import SutureObserver

        self.observer = SutureObserver(self.watch)
        self.observer.observe()

    def _goal(self) -> np.ndarray:
        r = self.observer.pair_results()[0]
        return self.world.ghost_pose(self.exit if r["entry_passed_s"] is not None else self.entry)[:3, 3]

    def _evaluate(self) -> dict:
        if self.world.sim_time > self.observer.tip_path[-1][0]:
            self.observer.observe()
        r = self.observer.pair_results()[0]
        entered = r["entry_passed_s"] is not None
        held = self.holding("psm1") or self.holding("psm2")
        d_tip = float(np.linalg.norm(f32(self.watch.tip_world()) - f32(self._goal())))
        d_tool = float(np.linalg.norm(f32(self.tool_position("psm1")) - f32(self.grasp_point())))
        dense = -10.0 * (d_tool if not held and not entered else d_tip) + 1.0 * held + 2.0 * entered + 5.0 * r["passed"]
        return {"dense": dense, "success": bool(r["passed"]), "entered": entered, "held": held, "distance": d_tip}
