"""The three environments: what each rewards and when it is solved.

- NeedleReach: bring psm1's end-effector to the needle's grasp point (within REACH_TOLERANCE).
- NeedlePick: grasp the needle with psm1 and lift it LIFT above where it lay.
- SutureOnePair: drive the needle through entry hole 1 and then out of exit hole 1, detected as
  the challenge does, through the holes' ghost objects (entry first, then exit).

Dense rewards are negative distances (m, x10) plus stage bonuses; sparse rewards are 0 on
success and -1 otherwise (the SurRoL / Fetch convention).
"""
from __future__ import annotations

import numpy as np

from .env import SuturingEnv

REACH_TOLERANCE = 0.003   # m
LIFT = 0.01               # m


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


class SutureOnePair(SuturingEnv):
    arms = ("psm1", "psm2")
    pair = 1

    def _task_setup(self) -> None:
        self.entry = self._ghost("entry")
        self.exit = self._ghost("exit")

    def _ghost(self, word: str):
        want = f"{word}{self.pair}"
        hits = [g for g in self.world.ghosts if want in g.key.lower().replace(" ", "").replace("_", "")]
        if len(hits) != 1:
            raise ValueError(f"the scene has {len(hits)} ghost objects named like {want!r} "
                             f"(ghosts: {', '.join(g.key for g in self.world.ghosts)})")
        return hits[0]

    def _task_reset(self) -> None:
        self.entered = False
        self.passed = False

    def _goal(self) -> np.ndarray:
        return (self.world.ghost_pose(self.exit if self.entered else self.entry))[:3, 3]

    def _evaluate(self) -> dict:
        inside_entry = self.needle in self.world.overlapping(self.entry)
        inside_exit = self.needle in self.world.overlapping(self.exit)
        if inside_entry:
            self.entered = True
        if self.entered and inside_exit:
            self.passed = True
        held = self.holding("psm1") or self.holding("psm2")
        d_needle = float(np.linalg.norm(f32(self.grasp_point()) - f32(self._goal())))
        d_tool = float(np.linalg.norm(f32(self.tool_position("psm1")) - f32(self.grasp_point())))
        dense = (-10.0 * (d_tool if not held and not self.entered else d_needle)
                 + 1.0 * held + 2.0 * self.entered + 5.0 * self.passed)
        return {"dense": dense, "success": self.passed, "entered": self.entered, "held": held,
                "distance": d_needle}
