"""Scripted expert policies for recording demonstrations: each reads only the observation
(ground-truth needle and PSM poses) and returns an action of the environment's action space.

    env = gym.make("adfkit/NeedlePick-v0"); expert = expert_for(env)
    obs, _ = env.reset(seed=3); expert.reset()
    while True:
        obs, r, term, trunc, info = env.step(expert(obs))
"""

from __future__ import annotations

import numpy as np

from ..runner.rotations import quat_to_matrix, rotation_log
from ..tasks.suture import JAW_DEPTH
from .env import MAX_STEP

HOVER = 0.012  # m above the grasp point before coming down
AT = 0.0015  # m: close enough to a waypoint


def jaw_point(pose7: np.ndarray) -> np.ndarray:
    """The point between the jaws, from an observed end-effector pose (position, quaternion)."""
    r = quat_to_matrix(np.asarray(pose7[3:], float))
    return np.asarray(pose7[:3], float) + JAW_DEPTH * r[:, 2]


def toward(here: np.ndarray, there: np.ndarray, gain: float = 0.8) -> np.ndarray:
    """Translation part of an action that moves ``here`` toward ``there`` (saturating at 1)."""
    return np.clip(gain * (there - here) / MAX_STEP, -1.0, 1.0)


class ReachExpert:
    """Straight to the grasp point, jaws open."""

    def reset(self) -> None:
        pass

    def __call__(self, obs) -> np.ndarray:
        a = np.zeros(7, np.float32)
        a[:3] = toward(jaw_point(obs["psm1_pose"]), obs["grasp_point"])
        a[6] = 1.0
        return a


class PickExpert:
    """Above the grasp point, down onto it, close the jaws (the actuator grasps), lift."""

    def __init__(self, lift: float = 0.015, close_steps: int = 3) -> None:
        self.lift, self.close_steps = lift, close_steps

    def reset(self) -> None:
        self.phase, self.count, self.rest = "hover", 0, None

    def __call__(self, obs) -> np.ndarray:
        a = np.zeros(7, np.float32)
        jaw = jaw_point(obs["psm1_pose"])
        g = np.asarray(obs["grasp_point"], float)
        if self.rest is None:
            self.rest = g.copy()
        if self.phase == "hover":
            target = g + [0, 0, HOVER]
            a[:3], a[6] = toward(jaw, target), 1.0
            if np.linalg.norm(target - jaw) < AT:
                self.phase = "down"
        elif self.phase == "down":
            a[:3], a[6] = toward(jaw, g), 1.0
            if np.linalg.norm(g - jaw) < AT:
                self.phase = "close"
        elif self.phase == "close":
            a[6] = -1.0
            self.count += 1
            if self.count >= self.close_steps:
                self.phase = "lift"
        else:
            a[:3] = toward(jaw, np.r_[self.rest[:2], self.rest[2] + self.lift])
            a[6] = -1.0
        return a


class SutureExpert:
    """The scripted suture's planner (adfkit.tasks.suture.SutureTask) turned into actions: each
    env step advances the planner by the env's control steps and returns the action that takes
    each arm's set-point where the planner put it (and the jaws). The planner reads the world
    (ground truth) and fixes the needle with the actuator itself when it grasps; the actions
    record what it did, so they can be replayed or learnt from."""

    def __init__(self, env) -> None:
        self.env = env.unwrapped

    def reset(self) -> None:
        from ..tasks.suture import SutureTask

        env = self.env
        self.task = SutureTask(env.world, [env.pair], seed=int(env.np_random.integers(1 << 30)), psm_names=env.arms)
        self.task.psms = {n: env.psms[n] for n in env.arms}  # the env's arms, the env's set-points
        self.plan = self.task.steps()
        self.done = False

    def __call__(self, obs) -> np.ndarray:
        from ..runner.psm import JAW_OPEN
        from .env import MAX_TURN

        env = self.env
        for _ in range(env.control_steps):
            if self.done:
                break
            try:
                next(self.plan)
            except StopIteration:
                self.done = True
        a = np.zeros(7 * len(env.arms), np.float32)
        for k, n in enumerate(env.arms):
            psm = env.psms[n]
            base = psm.base_in_world()
            want = base @ psm.setpoint_cp()
            have = base @ env._setpoint[n]
            a[7 * k : 7 * k + 3] = np.clip((want[:3, 3] - have[:3, 3]) / MAX_STEP, -1, 1)
            a[7 * k + 3 : 7 * k + 6] = np.clip(rotation_log(want[:3, :3] @ have[:3, :3].T) / MAX_TURN, -1, 1)
            jaw = sum(psm.art.targets[i] for i in psm.jaws)
            a[7 * k + 6] = np.clip(2.0 * jaw / JAW_OPEN - 1.0, -1.0, 1.0)
        return a


EXPERTS = {"NeedleReach": ReachExpert, "NeedlePick": PickExpert, "SutureOnePair": SutureExpert}


def expert_for(env):
    """The scripted expert of an environment (made by gym.make or directly)."""
    name = type(env.unwrapped).__name__
    if name not in EXPERTS:
        raise KeyError(f"no scripted expert for {name} (experts: {', '.join(EXPERTS)})")
    cls = EXPERTS[name]
    return cls(env) if cls is SutureExpert else cls()
