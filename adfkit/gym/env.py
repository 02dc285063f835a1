"""Gymnasium environments on the suturing scene (Gymnasium >= 1.0 API).

The scene is read once per environment and its world built, settled and snapshotted
(World.save_state); ``reset`` builds the world afresh from the scene model, restores the snapshot
into it (World.restore_state: a fresh world holds no history, so the same seed and actions give
the same observations bit for bit) and starts the arms, and with ``randomize_needle`` the needle
and its thread, at a seeded offset. The environments talk to the world only through the World
interface and drive the arms through adfkit.runner.PSM (servo_cp through the closed-form IK, servo_jaw, grasp).

Action, per arm (``arms``: psm1, or psm1 then psm2), 7 values in [-1, 1]: a translation of the
end-effector set-point along the world axes (x MAX_STEP m), a turn about the world axes at the
end-effector (x MAX_TURN rad), and the jaw (-1 closed ... +1 open; closing grasps what lies
between the fingers through the scene's constraint actuator, opening releases it).
"""

from __future__ import annotations

from dataclasses import replace

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from ..runner.rotations import rotation_exp
from ..tasks.suture import JAW_DEPTH
from . import scenes

MAX_STEP = 0.003  # m of set-point motion per env step at |action| = 1
MAX_TURN = 0.05  # rad per env step
GRASP_REACH = 0.004  # m from the point between the jaws to the needle's surface for a grasp
READY_HEIGHT = 0.03  # m: the acting arms start this far above the needle's grasp point
OBS_MODES = ("state", "rgb", "rgbd")
REWARD_TYPES = ("dense", "sparse")
POSE = spaces.Box(-np.inf, np.inf, (7,), np.float32)  # position (m), quaternion x, y, z, w


def _pose7(t: np.ndarray) -> np.ndarray:
    from ..runner.rotations import matrix_to_quat

    q = matrix_to_quat(t[:3, :3])
    if q[3] < 0:
        q = -q
    return np.concatenate([t[:3, 3], q]).astype(np.float32)


class SuturingEnv(gym.Env):
    """Base of the three tasks; a subclass sets ``arms`` and defines _task_reset, _evaluate."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 25}
    arms: tuple = ("psm1",)

    def __init__(
        self,
        obs_mode: str = "state",
        reward_type: str = "dense",
        render_mode: str | None = None,
        engine: str = "pybullet",
        scene=None,
        indices: str | None = None,
        image_size: tuple = (128, 96),
        render_size: tuple = (320, 240),
        control_steps: int = 5,
        randomize: float = 0.008,
        randomize_needle: float = 0.0,
        settle_seconds: float = 0.5,
        setup_joints: bool = True,
        exact_reset: bool = True,
    ) -> None:
        if obs_mode not in OBS_MODES:
            raise ValueError(f"obs_mode {obs_mode!r}: choose one of {', '.join(OBS_MODES)}")
        if reward_type not in REWARD_TYPES:
            raise ValueError(f"reward_type {reward_type!r}: choose one of {', '.join(REWARD_TYPES)}")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode {render_mode!r}: only 'rgb_array' (or None)")
        self.obs_mode, self.reward_type, self.render_mode = obs_mode, reward_type, render_mode
        self.control_steps, self.randomize = int(control_steps), float(randomize)
        self.randomize_needle, self.exact_reset = float(randomize_needle), bool(exact_reset)
        self._image_size, self._render_size = tuple(image_size), tuple(render_size)
        self._visuals, self._setup_joints = obs_mode != "state" or render_mode is not None, setup_joints
        if engine not in ("pybullet", "mujoco"):
            raise ValueError(f"engine {engine!r}: choose 'pybullet' or 'mujoco'")
        self._engine, self._model = engine, scenes.load(scene, indices)
        self.world = None
        self._open()
        if obs_mode != "state" and not self._cameras:
            raise ValueError(f"obs_mode {obs_mode!r}: the scene has no camera")
        self.world.run(settle_seconds)
        self._ready()
        self.world.run(settle_seconds)
        self._home = {n: p.setpoint_cp() for n, p in self.psms.items()}
        self._home_jaw = {n: p.measured_jaw() for n, p in self.psms.items()}
        self._snapshot = self.world.save_state()
        self._rest = [b.world_matrix() for b in [self.needle] + self.built.carried]
        self.action_space = spaces.Box(-1.0, 1.0, (7 * len(self.arms),), np.float32)
        obs = {}
        for n in self.psms:
            obs[f"{n}_pose"] = POSE
            obs[f"{n}_jaw"] = spaces.Box(-np.inf, np.inf, (1,), np.float32)
        obs["needle_pose"] = POSE
        obs["grasp_point"] = spaces.Box(-np.inf, np.inf, (3,), np.float32)
        obs["goal"] = spaces.Box(-np.inf, np.inf, (3,), np.float32)
        if obs_mode != "state":
            h, w = int(image_size[1]), int(image_size[0])
            for c in self._cameras:
                obs[f"{c.name}_rgb"] = spaces.Box(0, 255, (h, w, 3), np.uint8)
                if obs_mode == "rgbd":
                    obs[f"{c.name}_depth"] = spaces.Box(0.0, np.float32(c.far), (h, w, 1), np.float32)
        self.observation_space = spaces.Dict(obs)
        self._setpoint: dict = {}
        self._closed: dict = {}

    def _open(self) -> None:
        """(Re)build the world from the scene model with the environment's set-up: the arms,
        the task's objects, the arms' links not colliding with the needle (the grasp is the
        actuator's). Every call makes the same world in the same order, so a snapshot of one
        restores exactly into the next (World.restore_state)."""
        old = self.world
        self.built = b = scenes.build(self._model, self._engine, self.arms, self._visuals, self._setup_joints)
        self.world, self.psms, self.needle = b.world, b.psms, b.needle
        if old is not None:
            self.world.adopt(old)  # its renderer's view of the scene, built once
            old.close()
        w, h = (int(v) for v in self._image_size)
        self._cameras = [replace(c, width=w, height=h) for c in self.world.cameras]
        w, h = (int(v) for v in self._render_size)
        cam0 = self.world.cameras[0] if self.world.cameras else None
        self._render_camera = replace(cam0, width=w, height=h) if cam0 is not None else None
        self._task_setup()
        for body in self.world.bodies:  # the grasp is the actuator's; the fingers never shove the needle
            if any(body.articulation is self.psms[n].art for n in self.arms):
                self.world.set_collision(body, self.needle, False)

    # ---- Gymnasium API ------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        # a fresh world restored from the snapshot: the same seed and actions then give the same
        # observations bit for bit; exact_reset=False restores the world in place (~2 ms instead of
        # ~0.1 s), which keeps its contact order and repeats only to ~1e-8 m
        if self.exact_reset:
            self._open()
        self.world.restore_state(self._snapshot)
        self._setpoint = {n: self._home[n].copy() for n in self.arms}
        if self.randomize > 0:
            # the arms start at a seeded offset from their ready pose (teleported: nothing they
            # touch moves, so a seeded reset is exact); the needle only with randomize_needle
            for n in self.arms:
                psm = self.psms[n]
                base = psm.base_in_world()
                ee = base @ self._home[n]
                ee[:3, 3] += self.np_random.uniform(-self.randomize, self.randomize, size=3)
                try:
                    target = np.linalg.inv(base) @ ee
                    psm.reset_jp(psm.kin.ik(target))
                    self._setpoint[n] = target
                except ValueError:
                    pass
        if self.randomize_needle > 0:
            dx, dy = self.np_random.uniform(-self.randomize_needle, self.randomize_needle, size=2)
            for body, rest in zip([self.needle] + self.built.carried, self._rest):
                pose = rest.copy()
                pose[:3, 3] += (dx, dy, 0.0)
                self.world.place_body(body, pose)
        self._closed = {n: False for n in self.arms}
        self._steps = 0
        self._events_seen = len(self.world.watch.events)  # instabilities of earlier episodes are theirs
        self._task_reset()
        obs = self._observe()
        return obs, self._info(self._evaluate())

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=float).reshape(len(self.arms), 7), -1.0, 1.0)
        unreachable = 0
        for n, act in zip(self.arms, a):
            unreachable += self._command(n, act)
        self.world.step(self.control_steps)
        self._steps += 1
        ev = self._evaluate()
        obs = self._observe()
        reward = float(ev["dense"]) if self.reward_type == "dense" else (0.0 if ev["success"] else -1.0)
        bad = not all(np.all(np.isfinite(v)) for k, v in obs.items() if not k.endswith("_depth"))
        info = self._info(ev)
        info["unreachable_setpoints"] = unreachable
        events = self.world.watch.events[self._events_seen :]  # the engine blew up (runner/stability.py)
        if bad or events:
            bad = True
            info["unstable"] = [str(e) for e in events] or ["the observation holds NaN or Inf"]
        return obs, reward, bool(ev["success"] or bad), False, info

    def render(self):
        if self.render_mode != "rgb_array" or self._render_camera is None:
            return None
        return self._render_camera.render(self.world)["rgb"]

    def close(self):
        if getattr(self, "world", None) is not None:
            self.world.close()
            self.world = None

    # ---- arms ---------------------------------------------------------------------------
    def _command(self, name: str, act: np.ndarray) -> int:
        """Move arm ``name``'s set-point by the action; returns 1 when the IK refused it (the
        set-point then stays where it was)."""
        psm = self.psms[name]
        base = psm.base_in_world()
        world_sp = base @ self._setpoint[name]
        goal = world_sp.copy()
        goal[:3, 3] += act[:3] * MAX_STEP
        goal[:3, :3] = rotation_exp(act[3:6] * MAX_TURN) @ world_sp[:3, :3]
        target = np.linalg.inv(base) @ goal
        refused = 0
        try:
            psm.servo_cp(target)
            self._setpoint[name] = target
        except ValueError:
            refused = 1
        close = act[6] < 0.0
        if close and not self._closed[name]:
            self._grasp(name)
        elif not close and self._closed[name]:
            self.world.release(self._actuator(name))
        if not close:
            from ..runner.psm import JAW_OPEN

            psm.servo_jaw((act[6] + 1.0) / 2.0 * JAW_OPEN)
        self._closed[name] = close
        return refused

    def _ready(self) -> None:
        """Start pose of the acting arms: jaws open, READY_HEIGHT above the needle's grasp
        point (the home orientation kept); an arm that cannot go there stays home."""
        from ..runner.psm import JAW_OPEN

        above = self.grasp_point() + (0.0, 0.0, READY_HEIGHT)
        for n in self.arms:
            psm = self.psms[n]
            base = psm.base_in_world()
            ee = base @ psm.setpoint_cp()
            ee[:3, 3] = above - JAW_DEPTH * ee[:3, 2]
            try:
                psm.servo_cp(np.linalg.inv(base) @ ee)
            except ValueError:
                pass
            psm.servo_jaw(JAW_OPEN)

    def _actuator(self, name: str):
        return next(a for a in self.world.actuators if f"/{name}/" in a.key or f"/{name}/" in a.parent.key)

    def _grasp(self, name: str) -> bool:
        """Close the jaws; the scene's constraint actuator holds the needle when its wire lies
        within GRASP_REACH of the point between the jaws (only the needle: the environments'
        grasps never take a thread element or another body)."""
        self.psms[name].servo_jaw(0.0)
        if self.world.nearest_point(self.needle, self.tool_position(name), GRASP_REACH) is None:
            return False
        self.world.actuate(self._actuator(name), self.needle)
        return True

    def tool_position(self, name: str = "psm1") -> np.ndarray:
        """World position of the point between the arm's jaws (JAW_DEPTH along the end-effector's z)."""
        psm = self.psms[name]
        ee = psm.base_in_world() @ psm.measured_cp()
        return ee[:3, 3] + JAW_DEPTH * ee[:3, 2]

    def grasp_point(self) -> np.ndarray:
        return (self.needle.world_matrix() @ self.built.grasp_in_needle)[:3, 3]

    def holding(self, name: str = "psm1") -> bool:
        return self.world.grasped(name) is self.needle

    # ---- observation --------------------------------------------------------------------
    def _observe(self) -> dict:
        obs = {}
        for n, psm in self.psms.items():
            obs[f"{n}_pose"] = _pose7(psm.base_in_world() @ psm.measured_cp())
            obs[f"{n}_jaw"] = np.array([psm.measured_jaw()], np.float32)
        obs["needle_pose"] = _pose7(self.needle.world_matrix())
        obs["grasp_point"] = self.grasp_point().astype(np.float32)
        obs["goal"] = np.asarray(self._goal(), np.float32)
        if self.obs_mode != "state":
            for c in self._cameras:
                frame = c.render(self.world)
                obs[f"{c.name}_rgb"] = frame["rgb"]
                if self.obs_mode == "rgbd":
                    d = np.nan_to_num(frame["depth"], nan=c.far, posinf=c.far, neginf=0.0)
                    obs[f"{c.name}_depth"] = np.clip(d, 0.0, c.far).astype(np.float32)[:, :, None]
        return obs

    def _info(self, ev: dict) -> dict:
        return {
            "is_success": bool(ev["success"]),
            **{k: v for k, v in ev.items() if k not in ("dense", "success")},
            "sim_time": self.world.sim_time,
        }

    # ---- task hooks -----------------------------------------------------------------------
    def _task_setup(self) -> None:
        """Whenever the world is built (before the scene settles and the snapshot is taken, and on
        each reset): the task's own objects on the world."""

    def _task_reset(self) -> None:
        """After each reset."""

    def _goal(self) -> np.ndarray:
        raise NotImplementedError

    def _evaluate(self) -> dict:
        raise NotImplementedError
