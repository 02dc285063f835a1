"""Gymnasium environments on the suturing scene (adfkit/gym): the Gymnasium API checker, random
play without NaN, resets from the world's snapshot, and the scripted experts."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")
pytest.importorskip("pybullet")

import adfkit.gym  # noqa: E402,F401
from adfkit.gym import scenes  # noqa: E402
from adfkit.gym.experts import expert_for  # noqa: E402

try:
    SCENE = scenes.default_scene()
except scenes.SceneUnavailable as exc:
    SCENE = None
    WHY = str(exc)


def _need_scene():
    if SCENE is None:
        pytest.skip(WHY)


_made: dict = {}


def make(env_id: str, **kw):
    _need_scene()
    key = (env_id, tuple(sorted(kw.items())))
    if key not in _made:
        _made[key] = gym.make(env_id, **kw)
    return _made[key]


@pytest.fixture(scope="module", autouse=True)
def _close_envs():
    yield
    for env in _made.values():
        env.close()
    _made.clear()


IDS = ["adfkit/NeedleReach-v0", "adfkit/NeedlePick-v0", "adfkit/SutureOnePair-v0"]


def _check(env_id, **kw):
    """Gymnasium's checker, its warning that the same seed and actions gave observations, rewards
    or infos that are only close (not equal) turned into an error. The spec stays, so the checker
    compares two seeded resets (it does only for a registered, deterministic env); the close
    check (it builds a second copy from the spec) is left out."""
    from gymnasium.utils.env_checker import check_env

    env = make(env_id, **kw).unwrapped
    with warnings.catch_warnings():
        warnings.filterwarnings("error", message=".*(not equal although similar|non-deterministic)")
        check_env(env, skip_render_check=True, skip_close_check=True)
    assert env.action_space.shape == (7 * len(env.arms),)


def test_check_env_reach():
    _check("adfkit/NeedleReach-v0")


@pytest.mark.slow
@pytest.mark.parametrize("env_id", IDS[1:])
def test_check_env_pick_and_suture(env_id):
    _check(env_id)


def _random_play(env_id, steps):
    env = make(env_id)
    obs, _ = env.reset(seed=7)
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(steps):
        obs, r, term, trunc, info = env.step(rng.uniform(-1, 1, env.action_space.shape).astype(np.float32))
        for k, v in obs.items():
            assert np.all(np.isfinite(v)), k
        assert np.isfinite(r)
        assert "unstable" not in info
        worst = max(worst, float(np.abs(obs["needle_pose"][:3]).max()))
        if term or trunc:
            obs, _ = env.reset()
    assert worst < 5.0  # the needle stays in the scene (metres)


@pytest.mark.slow
@pytest.mark.parametrize("env_id", IDS)
def test_200_random_steps_without_nan(env_id):
    _random_play(env_id, 200)


def test_random_steps_reach_short():
    _random_play("adfkit/NeedleReach-v0", 30)


def test_reset_restores_the_snapshot():
    env = make("adfkit/NeedlePick-v0")
    a, _ = env.reset(seed=11)
    expert = expert_for(env)
    expert.reset()
    obs = a
    for _ in range(40):  # grasp and lift: the reset must undo a grasp too
        obs, *_ = env.step(expert(obs))
    assert env.unwrapped.holding()
    b, _ = env.reset(seed=11)
    assert not env.unwrapped.holding()
    for k in a:
        assert np.array_equal(a[k], b[k]), k
    c, _ = env.reset(seed=12)
    assert not np.allclose(a["psm1_pose"][:3], c["psm1_pose"][:3], atol=1e-4)  # seeds differ


class Played(list):
    """The observations of a play, with ``states``: every body's pose and velocity in double
    precision at each of them (what a failed bit-for-bit comparison reports)."""

    states: list


def _bodies(world) -> dict:
    return {sb.key: sum(map(tuple, sb.state()), ()) for sb in world.bodies if sb.uid is not None and sb.uid >= 0}


def _play(env, seed: int, actions) -> Played:
    """The observations after reset(seed=seed) and after each of ``actions``."""
    obs, _ = env.reset(seed=seed)
    out, out.states = Played([obs]), [_bodies(env.unwrapped.world)]
    for a in actions:
        obs, *_ = env.step(a)
        out.append(obs)
        out.states.append(_bodies(env.unwrapped.world))
    return out


def _assert_bit_for_bit(a: Played, b: Played) -> None:
    """The two plays' observations equal bit for bit. A rare failure names its cause: the message
    says where the bodies' double-precision states first parted and the process's floating-point
    and Bullet settings then."""
    for i, (x, y) in enumerate(zip(a, b)):
        for k in x:
            if not np.array_equal(x[k], y[k]):
                pytest.fail(f"step {i} {k}: {float(np.abs(x[k] - y[k]).max()):.3g} apart; {_parted(a, b)}")


def _parted(a: Played, b: Played) -> str:
    import os
    import threading

    import pybullet as pb

    step = next((i for i, (x, y) in enumerate(zip(a.states, b.states)) if x != y), None)
    where = "the bodies' states equal in double precision at every step"
    if step is not None:
        x, y = a.states[step], b.states[step]
        gap = {k: max(abs(u - v) for u, v in zip(x[k], y[k])) for k in x if x[k] != y.get(k)}
        worst = sorted(gap, key=gap.get, reverse=True)[:4]
        where = (
            f"the states parted at step {step} in {len(gap)} bodies ({', '.join(f'{k} {gap[k]:.3g}' for k in worst)})"
        )
    cids = [c for c in range(64) if pb.isConnected(c)]
    fp = (np.array([5e-324]) * 1.0)[0] == 0.0, (np.float64(1.0) / np.float64(3.0)).hex()
    tasks = len(os.listdir("/proc/self/task")) if os.path.isdir("/proc/self/task") else None
    return (
        f"{where}; denormals flushed {fp[0]}, 1/3 = {fp[1]}, PyBullet clients {cids}, "
        f"threads {threading.active_count()} Python / {tasks} in all"
    )


def _worst(a: list, b: list, key: str) -> float:
    return max(float(np.abs(x[key].astype(float) - y[key].astype(float)).max()) for x, y in zip(a, b))


def _actions(env, n: int, seed: int = 3) -> list:
    rng = np.random.default_rng(seed)
    return [rng.uniform(-1, 1, env.action_space.shape).astype(np.float32) for _ in range(n)]


@pytest.mark.parametrize("kw", [{}, {"randomize_needle": 0.004}], ids=["arms", "arms-and-needle"])
def test_the_same_seed_and_actions_give_the_same_observations_bit_for_bit(kw):
    env = make("adfkit/NeedleReach-v0", **kw)
    actions = _actions(env, 12)
    first = _play(env, 5, actions)
    for _ in range(2):  # a third run too: nothing of an earlier episode carries over
        _assert_bit_for_bit(first, _play(env, 5, actions))
    other = _play(env, 6, actions)
    assert _worst(first[:1], other[:1], "psm1_pose") > 1e-4  # another seed starts elsewhere
    if kw:
        assert _worst(first[:1], other[:1], "needle_pose") > 1e-4
    else:
        assert np.array_equal(first[0]["needle_pose"], other[0]["needle_pose"])


def test_a_world_made_between_two_replays_leaves_them_bit_for_bit():
    """Another world of the process made and stepped between two seeded replays, with its own
    contact threshold (which Bullet holds once for the process: runner/pybullet/bullet_globals.py),
    changes nothing of them; before each world put its own in force, the replays parted at the
    first step."""
    from adfkit.runner import Options, open_world

    env = make("adfkit/NeedleReach-v0")
    actions = _actions(env, 4)
    a = _play(env, 5, actions)
    other = open_world(env.unwrapped._model, Options(visuals=False, contact_threshold=0.001))
    try:
        other.step(2)
        b = _play(env, 5, actions)
    finally:
        other.close()
    _assert_bit_for_bit(a, b)


def test_a_grasp_and_lift_replay_bit_for_bit():
    """The expert's actions (grasp, lift) replayed after the same seeded reset: the grasp's
    constraint and collision filters are gone with the world, nothing of them stays."""
    env = make("adfkit/NeedlePick-v0")
    expert = expert_for(env)
    obs, _ = env.reset(seed=4)
    expert.reset()
    actions = []
    for _ in range(30):
        actions.append(expert(obs))
        obs, *_ = env.step(actions[-1])
    assert env.unwrapped.holding()
    a, b = _play(env, 4, actions), _play(env, 4, actions)
    _assert_bit_for_bit(a, b)
    assert a[-1]["needle_pose"][2] > a[0]["needle_pose"][2] + 0.005  # it was lifted


@pytest.mark.slow
@pytest.mark.parametrize("env_id", IDS[1:])
def test_the_same_seed_and_actions_replay_bit_for_bit_in_every_env(env_id):
    env = make(env_id)
    actions = _actions(env, 20)
    a, b, other = _play(env, 8, actions), _play(env, 8, actions), _play(env, 9, actions)
    _assert_bit_for_bit(a, b)
    for name in env.unwrapped.arms:
        assert _worst(a[:1], other[:1], f"{name}_pose") > 1e-4


def test_a_reset_in_place_is_only_close():
    """The negative control: exact_reset=False restores the snapshot into the same world, which
    keeps its contact order, so the same seed and actions drift apart (by micrometres: the needle
    22 um with its hulls' 0.1 mm collision margins, 1.4 um when PyBullet gave them 1 mm) and the
    checker's warning, made an error, fires."""
    env = make("adfkit/NeedleReach-v0", exact_reset=False)
    actions = _actions(env, 12)
    a, b = _play(env, 5, actions), _play(env, 5, actions)
    assert 0.0 < _worst(a, b, "needle_pose") < 1e-4
    with pytest.raises(UserWarning, match="not equal although similar"):
        _check("adfkit/NeedleReach-v0", exact_reset=False)


def test_sparse_reward_and_image_observations():
    env = make(
        "adfkit/NeedleReach-v0", obs_mode="rgbd", reward_type="sparse", image_size=(32, 24), render_mode="rgb_array"
    )
    obs, _ = env.reset(seed=0)
    cams = [k[:-4] for k in obs if k.endswith("_rgb")]
    assert len(cams) >= 2  # the stereo pair
    assert obs[cams[0] + "_rgb"].shape == (24, 32, 3) and obs[cams[0] + "_rgb"].dtype == np.uint8
    assert obs[cams[0] + "_depth"].shape == (24, 32, 1)
    assert env.observation_space.contains(obs)
    obs, r, *_ = env.step(np.zeros(7, np.float32))
    assert r == -1.0
    assert env.render().ndim == 3
    world = env.unwrapped.world  # the resized cameras drew with the renderer chosen, no fall-back
    assert not [d for d in world.diagnostics if d.rule == "runner-renderer"]


def test_image_observations_replay_bit_for_bit_and_the_view_is_built_once():
    env = make(
        "adfkit/NeedleReach-v0", obs_mode="rgbd", reward_type="sparse", image_size=(32, 24), render_mode="rgb_array"
    )
    actions = _actions(env, 3)
    a = _play(env, 2, actions)
    view = env.unwrapped.world._mj_view
    b = _play(env, 2, actions)
    _assert_bit_for_bit(a, b)
    assert a[-1]["cameraL_rgb"].std() > 0  # a picture, not a blank
    if env.unwrapped.world.renderer == "mujoco":  # the MuJoCo view passed from world to world
        assert view is not None and env.unwrapped.world._mj_view is view and view.world is env.unwrapped.world


def _solve(env_id, seeds):
    env = make(env_id)
    expert = expert_for(env)
    solved = 0
    for s in seeds:
        obs, _ = env.reset(seed=s)
        expert.reset()
        while True:
            obs, r, term, trunc, info = env.step(expert(obs))
            if term or trunc:
                break
        solved += bool(info["is_success"])
    return solved


@pytest.mark.parametrize("env_id", ["adfkit/NeedleReach-v0", "adfkit/NeedlePick-v0"])
def test_expert_solves_a_few_seeds(env_id):
    assert _solve(env_id, range(3)) == 3


@pytest.mark.slow
@pytest.mark.parametrize("env_id", ["adfkit/NeedleReach-v0", "adfkit/NeedlePick-v0"])
def test_expert_solves_90_percent_of_20_seeds(env_id):
    assert _solve(env_id, range(100, 120)) >= 18


@pytest.mark.slow
def test_suture_expert_passes_pair_1():
    # the scripted suture's planner as actions: ~430 env steps (~9 s simulated) a seed
    assert _solve("adfkit/SutureOnePair-v0", [0, 1]) == 2


def test_mujoco_engine_is_a_clear_error_or_works():
    _need_scene()
    try:
        from adfkit.runner.mujoco.world import MujocoWorld

        complete = all(hasattr(MujocoWorld, m) for m in scenes.NEEDS)
    except ImportError:
        complete = False
    if not complete:
        with pytest.raises(NotImplementedError, match="MuJoCo back end"):
            gym.make("adfkit/NeedleReach-v0", engine="mujoco")
    with pytest.raises(ValueError, match="engine"):
        gym.make("adfkit/NeedleReach-v0", engine="ode")


def test_dataset_command_refuses_bad_options(tmp_path, capsys):
    from adfkit.cli import main

    assert main(["dataset", "--env", "adfkit/NoSuchTask-v0", "--out", str(tmp_path)]) == 2
    assert "no scripted expert" in capsys.readouterr().err
    assert main(["dataset", "--episodes", "0", "--out", str(tmp_path)]) == 2
    assert main(["dataset", "--scene", str(tmp_path / "none.yaml"), "--out", str(tmp_path)]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_an_engine_instability_terminates_the_episode_with_its_reason():
    """What the world's stability watch met during a step (runner/stability.py) ends the episode,
    with the event in ``info``; the next episode starts clean."""
    from adfkit.runner.stability import Instability

    env = make("adfkit/NeedleReach-v0")
    env.reset(seed=1)
    zero = np.zeros(env.action_space.shape, dtype=np.float32)
    _, _, term, _, info = env.step(zero)
    assert not term and "unstable" not in info
    env.unwrapped.world.watch.add(Instability(0.1, "BODY Needle", "state-reset", "MuJoCo reset the state"))
    _, _, term, _, info = env.step(zero)
    assert term and info["unstable"] == ["t = 0.100 s (BODY Needle): MuJoCo reset the state"]
    env.reset(seed=2)
    _, _, term, _, info = env.step(zero)
    assert not term and "unstable" not in info
