"""Gymnasium environments on the suturing scene (issue 18). Importing this package registers

    adfkit/NeedleReach-v0     psm1's jaws to the needle's grasp point
    adfkit/NeedlePick-v0      grasp the needle with psm1 and lift it
    adfkit/SutureOnePair-v0   needle through entry hole 1 and out of exit hole 1 (psm1 + psm2)

    import gymnasium as gym, adfkit.gym
    env = gym.make("adfkit/NeedlePick-v0", obs_mode="rgb", render_mode="rgb_array")

Keyword arguments (SuturingEnv): obs_mode "state"|"rgb"|"rgbd", reward_type "dense"|"sparse",
render_mode "rgb_array", engine "pybullet"|"mujoco", scene/indices (a launch file; default the
project's suturing scene), image_size, control_steps, randomize, exact_reset (False: resets in
place, faster, repeat a seed only to ~1e-8 m). Scripted experts for demonstrations:
adfkit.gym.experts.
"""

from __future__ import annotations

try:
    import gymnasium
except ImportError as exc:  # pragma: no cover - depends on the install
    raise ImportError("adfkit.gym needs Gymnasium: pip install 'adfkit[gym]'") from exc

from .env import SuturingEnv  # noqa: E402,F401
from .tasks import NeedlePick, NeedleReach, SutureOnePair  # noqa: E402,F401

#: id -> (class, max episode steps)
ENVS = {
    "adfkit/NeedleReach-v0": ("NeedleReach", 100),
    "adfkit/NeedlePick-v0": ("NeedlePick", 200),
    "adfkit/SutureOnePair-v0": ("SutureOnePair", 1000),
}

for _id, (_cls, _steps) in ENVS.items():
    if _id not in gymnasium.registry:
        gymnasium.register(id=_id, entry_point=f"adfkit.gym.tasks:{_cls}", max_episode_steps=_steps)
