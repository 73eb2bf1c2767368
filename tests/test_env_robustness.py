"""Plain outputs on every outcome (JSON-ready ``info``), copies (pickle, deepcopy) taken
mid-episode that continue exactly where the original was, and ``render_mode="human"`` refused
without a display. Vector envs and the pickle of a stepped env are checked in tests/test_env.py."""

from __future__ import annotations

import copy
import itertools
import json
import pickle
from collections.abc import Callable
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

from acl_env import ACL_CLIMB_BENCHMARK_ID, ACL_CLIMB_ID
from acl_env.envs import ACLClimbEnv
from acl_env.envs.lifecycle import no_display_reason
from acl_env.envs.termination import fell

SHORT = {"steps_per_cycle": 20, "cycles_per_episode": 1}
PLAIN = (bool, int, float, str)


@pytest.fixture(autouse=True)
def _mujoco_log_in_tmp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """MuJoCo appends its warnings to MUJOCO_LOG.TXT in the working folder: keep it in tmp."""
    monkeypatch.chdir(tmp_path)


def assert_plain(info: dict[str, Any]) -> None:
    """Every value a plain Python scalar (not a NumPy one), and the whole dict JSON-ready."""
    for key, value in info.items():
        assert type(value) in PLAIN, f"info[{key!r}] is {type(value).__name__}"
    json.dumps(info)


def step_until(env: ACLClimbEnv, stop: Callable[[dict[str, Any]], bool], limit: int) -> tuple:
    for _ in range(limit):
        out = env.step(np.zeros(env.action_space.shape))
        if stop(out[4]) or out[2] or out[3]:
            return out
    raise AssertionError(f"no stop within {limit} steps")


def test_info_is_plain_python_on_steps_falls_and_instabilities() -> None:
    env = ACLClimbEnv(kp=2.0)  # weak springs: the snake slides off (docs/robot_and_contact.md)
    _, info = env.reset(seed=0)
    assert_plain(info)
    _, reward, terminated, truncated, info = env.step(np.zeros(20))
    assert_plain(info)
    assert type(reward) is float and type(terminated) is bool and type(truncated) is bool
    _, reward, terminated, truncated, info = step_until(env, lambda i: i["fell"], 200)
    assert info["fell"] is True and terminated is True
    assert_plain(info)
    assert type(reward) is float and type(truncated) is bool

    env = ACLClimbEnv()
    env.reset(seed=0)
    env.model.opt.timestep = 5.0  # guaranteed divergence
    _, reward, terminated, truncated, info = env.step(np.ones(20))
    assert info["unstable"] is True and terminated is True
    assert_plain(info)
    assert type(reward) is float


def test_truncation_info_is_plain() -> None:
    env = ACLClimbEnv(**SHORT)
    env.reset(seed=0)
    _, _, terminated, truncated, info = step_until(env, lambda i: False, 25)
    assert truncated is True and terminated is False
    assert_plain(info)


COPIES: dict[str, Callable[[Any], Any]] = {
    "pickle": lambda env: pickle.loads(pickle.dumps(env)),
    "deepcopy": copy.deepcopy,
}
CONFIGS = {
    "plain": {},
    "randomized": {
        "domain_randomization": True,
        "phase_rate_range": (0.5, 1.5),
        "privileged_obs": True,
        "obs_history": 2,
        "base_gait": "rolling_helix",
    },
}


def run(env: gym.Env, actions: np.ndarray) -> list[tuple]:
    out = []
    for action in actions:
        obs, reward, terminated, truncated, info = env.step(action)
        out.append((obs.copy(), reward, terminated, truncated, info))
        if terminated or truncated:
            break
    return out


def assert_same_steps(a: list[tuple], b: list[tuple]) -> None:
    assert len(a) == len(b)
    for (obs_a, *rest_a), (obs_b, *rest_b) in zip(a, b, strict=True):
        np.testing.assert_array_equal(obs_a, obs_b)
        assert rest_a == rest_b


@pytest.mark.parametrize("config", sorted(CONFIGS))
@pytest.mark.parametrize("how", sorted(COPIES))
def test_copy_mid_episode_continues_exactly(how: str, config: str) -> None:
    """A copy taken after reset and steps continues bit-identically: physics (with this
    episode's randomised pole, friction, gains, masses), gait phase, counters and noise RNG."""
    env = ACLClimbEnv(**SHORT, **CONFIGS[config])
    rng = np.random.default_rng(5)
    actions = rng.uniform(-1, 1, (30, *env.action_space.shape)).astype(np.float32)
    env.reset(seed=11)
    run(env, actions[:6])
    clone = COPIES[how](env)
    assert clone is not env and clone.data is not env.data and clone.model is not env.model
    assert clone.mujoco_renderer.data is clone.data
    # The copy and the original step on independently, to the same results.
    tail_original = run(env, actions[6:])
    tail_clone = run(clone, actions[6:])
    assert len(tail_original) == SHORT["steps_per_cycle"] - 6  # ran to truncation
    assert_same_steps(tail_original, tail_clone)
    # Their RNGs are in the same state too: the next unseeded resets agree.
    obs_a, info_a = env.reset()
    obs_b, info_b = clone.reset()
    np.testing.assert_array_equal(obs_a, obs_b)
    assert info_a == info_b


def test_copy_of_a_fresh_env_behaves_as_a_fresh_env() -> None:
    env = ACLClimbEnv(**SHORT, domain_randomization=True)
    clone = pickle.loads(pickle.dumps(env))
    actions = np.random.default_rng(1).uniform(-1, 1, (8, 20)).astype(np.float32)
    env.reset(seed=3)
    clone.reset(seed=3)
    assert_same_steps(run(env, actions), run(clone, actions))


def test_copy_through_gym_make_wrappers() -> None:
    env = gym.make(ACL_CLIMB_ID, **SHORT)
    actions = np.random.default_rng(2).uniform(-1, 1, (12, 20)).astype(np.float32)
    env.reset(seed=4)
    run(env, actions[:3])
    clone = copy.deepcopy(env)
    assert_same_steps(run(env, actions[3:]), run(clone, actions[3:]))


def test_every_camera_renders_its_own_view_at_the_smallest_size() -> None:
    """``camera_name`` picks the camera (each view differs); 1 x 1 is the smallest image."""
    model = ACLClimbEnv().model
    cameras = [model.camera(i).name for i in range(model.ncam)]
    assert len(cameras) >= 2
    frames = {}
    for camera in cameras:
        env = ACLClimbEnv(render_mode="rgb_array", width=64, height=48, camera_name=camera)
        env.reset(seed=0)
        frames[camera] = env.render()
        assert frames[camera].shape == (48, 64, 3) and frames[camera].std() > 5.0
        env.close()
    for a, b in itertools.pairwise(cameras):
        assert not np.array_equal(frames[a], frames[b]), (a, b)
    env = ACLClimbEnv(render_mode="rgb_array", width=1, height=1)
    env.reset(seed=0)
    assert env.render().shape == (1, 1, 3)
    env.close()


# --- plain outputs on every outcome (the lifecycle table) -----------------------------------------


def tiny(**kwargs: Any) -> ACLClimbEnv:
    return ACLClimbEnv(**{"n_joints": 4, "steps_per_cycle": 8, **kwargs})


def assert_plain_step(out: tuple) -> None:
    _, reward, terminated, truncated, info = out
    assert type(reward) is float and type(terminated) is bool and type(truncated) is bool
    for key, value in info.items():
        assert type(value) in PLAIN, f"info[{key!r}] is {type(value).__name__}"
    json.dumps({"reward": reward, "terminated": terminated, "truncated": truncated, **info})


@pytest.mark.parametrize(
    ("kwargs", "flag"),
    [
        ({"kp": 1e-3}, "fell"),  # limp: off the pole
        ({"friction": 1e-3}, "fell"),  # slippery
        ({"roll_limit": 0.5, "n_joints": 20, "steps_per_cycle": 20}, "rolled"),
        ({"cycles_per_episode": 1, "steps_per_cycle": 2, "n_joints": 20}, "truncated"),
    ],
    ids=["limp fall", "slippery fall", "rolled", "truncated"],
)
def test_outcomes_are_plain_python_and_json(kwargs: dict[str, Any], flag: str) -> None:
    env = tiny(**kwargs)
    _, info = env.reset(seed=0)
    json.dumps(info)
    for _ in range(100):
        out = env.step(np.zeros(env.action_space.shape))
        assert_plain_step(out)
        if out[2] or out[3]:
            break
    assert out[3] if flag == "truncated" else (out[2] and out[4][flag] is True)


def test_fell_is_a_plain_bool_for_numpy_contact_flags() -> None:
    assert fell(1.0, 1.0, 0.2, np.True_, np.True_) is True
    assert fell(1.0, 1.0, 0.2, np.False_, np.False_) is True
    assert fell(1.0, 1.0, 0.2, np.True_, np.False_) is False


# --- render_mode="human" without a display -------------------------------------------------------

NO_WINDOW = [
    ({"DISPLAY": None, "WAYLAND_DISPLAY": None, "MUJOCO_GL": None}, "linux"),
    ({"DISPLAY": "", "WAYLAND_DISPLAY": "", "MUJOCO_GL": "glfw"}, "linux"),
    ({"DISPLAY": ":0", "MUJOCO_GL": "egl"}, "linux"),
    ({"DISPLAY": ":0", "MUJOCO_GL": "osmesa"}, "linux"),
    ({"WAYLAND_DISPLAY": "wayland-0", "MUJOCO_GL": " EGL "}, "linux"),
]


@pytest.mark.parametrize(("env_vars", "platform"), NO_WINDOW)
def test_human_rendering_without_a_window_is_refused_before_glfw(
    env_vars: dict[str, str | None], platform: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    for key, value in env_vars.items():
        if value is None:
            monkeypatch.delenv(key, raising=False)
        else:
            monkeypatch.setenv(key, value)
    monkeypatch.setattr("sys.platform", platform)
    with pytest.raises(ValueError, match="render_mode") as caught:
        tiny(render_mode="human")
    assert "DISPLAY" in str(caught.value) and "MUJOCO_GL" in str(caught.value)
    with pytest.raises(ValueError, match="DISPLAY"):
        gym.make(ACL_CLIMB_BENCHMARK_ID, render_mode="human", n_joints=4, steps_per_cycle=8)


def test_a_display_that_goes_away_is_refused_at_the_first_render(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Built where a display was named, reset (which renders) where none is: a Python error,
    raised before MuJoCo's viewer is made (GLFW is never touched here)."""
    monkeypatch.setenv("DISPLAY", ":99")
    monkeypatch.delenv("MUJOCO_GL", raising=False)
    env = tiny(render_mode="human")
    monkeypatch.delenv("DISPLAY")
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr("sys.platform", "linux")
    with pytest.raises(ValueError, match="MUJOCO_GL"):
        env.reset(seed=0)
    assert not env.mujoco_renderer._viewers  # no window was attempted


def test_no_display_reason_elsewhere() -> None:
    assert no_display_reason({}, "darwin") == ""
    assert no_display_reason({"DISPLAY": ":0"}, "linux") == ""
    assert "MUJOCO_GL=egl" in no_display_reason({"MUJOCO_GL": "egl"}, "win32")
