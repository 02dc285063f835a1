"""AMBF's hinge and slider stops on a free multibody in MuJoCo (which and when: runner/
free_stops.py). Before each physics step the chain step (mujoco/chain.py) is read on MuJoCo's
state at the step's start; after MuJoCo's step the multibody's joints are taken to the velocities
it left them at by one impulse along the joints (M⁻¹ over them, the model's other dofs free:
motor_rows.joint_mobility), and every dof the impulse moved is carried on by it for the step
(semi-implicit, as Bullet integrates): the joints end the step where AMBF's solver leaves them,
q + dt·q̇, whatever MuJoCo's own limit and forces did within it, as the PyBullet runner's motors
at joint_commands.LIMIT_FORCE take them there. A joint resting on its stop is left to MuJoCo's
limit with Bullet's rate (limits.py). The world steps a control step's physics steps one by one
while such a multibody is free (world.py; ``watching``), and in one call of MuJoCo's while a drive
or a command holds every one: the corpus suturing set at rest, its two PSMs free, costs 1.81 ->
1.97 s of CPU for 10 s (bench/mujoco_run_speed.py), the look before each step done on all their
limited joints at once."""

from __future__ import annotations

import mujoco
import numpy as np

from ..free_stops import REST_SPEED, FreeStops


class LimitChains(FreeStops):
    def __init__(self, world) -> None:
        super().__init__(world)
        self._played: list[tuple] = []  # (articulation, velocities) the chain step gave this step
        self._watched: tuple = ()  # the free multibodies ``_limited`` is for
        self._limited = (np.zeros(0, int), np.zeros(0, int), np.zeros(0), np.zeros(0))  # qadr, vadr, lo, hi

    def watching(self) -> bool:
        watch = super().watching()
        key = tuple(id(art) for art, _l in self.free)
        if key != self._watched:  # the free multibodies' limited joints, as arrays
            rows = [(art.qadr[n], art.vadr[n], lo, hi) for art, limited in self.free for n, (lo, hi) in limited]
            q, v, lo, hi = zip(*rows) if rows else ((), (), (), ())
            self._limited = (np.array(q, int), np.array(v, int), np.array(lo, float), np.array(hi, float))
            self._watched = key
        return watch

    def before(self) -> None:
        """Before each physics step: the velocities of the multibodies the chain step plays. With
        none played, the free ones' limited joints are looked at all at once first, as
        ``velocities`` looks at each: none near a stop, nothing is handed over this step."""
        if not self.engaged:
            d, dt = self.world.data, self.world.dt
            qa, va, lo, hi = self._limited
            v = d.qvel[va]
            fast = np.abs(v) >= REST_SPEED
            if not fast.any():  # (most steps: every joint resting or slow)
                self.step += 1
                return
            q = d.qpos[qa]
            ahead = q + 2.0 * v * dt
            out = ((ahead > hi) & (v > 0.0)) | ((ahead < lo) & (v < 0.0))  # heading out across a limit
            if not np.any(fast & out):
                self.step += 1
                return
        self._played = self.velocities()

    def after(self) -> None:
        """After the physics step: their joints at those velocities, by an impulse along them."""
        if not self._played:
            return
        w = self.world
        m, d = w.model, w.data
        for art, qd in self._played:
            dofs = np.asarray(art.vadr, dtype=int)
            unit = np.zeros((len(dofs), m.nv))
            unit[np.arange(len(dofs)), dofs] = 1.0
            moved = np.zeros_like(unit)
            mujoco.mj_solveM(m, d, moved, unit)  # M⁻¹ of the step's start, a row per joint
            impulse = np.linalg.solve(moved[:, dofs], qd - d.qvel[dofs])
            dv = moved.T @ impulse
            d.qvel[:] += dv
            mujoco.mj_integratePos(m, d.qpos, dv, w.dt)
        self._played = []

    def _state_now(self) -> None:
        # the poses the last physics step left (MuJoCo computes them before it integrates)
        mujoco.mj_kinematics(self.world.model, self.world.data)
