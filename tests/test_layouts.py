"""The observation and action layouts (``acl_env.envs.observations``) are the env's spaces: sizes,
names, and what each block holds; the env's options as typed configs (``acl_env.envs.config``)."""

from __future__ import annotations

import inspect
import math

import gymnasium as gym
import numpy as np
import pytest

import acl_env
from acl_env.envs import ACLClimbEnv
from acl_env.envs.arguments import ARGUMENTS, DEFAULTS
from acl_env.envs.config import EnvConfig
from acl_env.envs.observations import (
    env_action_layout,
    env_observation_layout,
    names,
    size,
)

OPTIONS = [
    {},
    {"actuator_model": "sea"},
    {"privileged_obs": True},
    {"phase_rate_range": (0.5, 2.0), "gait_modulation": {"squeeze": 0.003}},
    {"actuator_model": "sea", "grip_target": 5.0, "grip_action_scale": 50.0},
    {"actuator_model": "sea", "grip_target": 5.0, "modulation_sections": 2, "n_joints": 8},
]


def _block(env: ACLClimbEnv, obs: np.ndarray, first: str) -> np.ndarray:
    """The entries of the block whose first entry is called ``first``."""
    start = 0
    for block in env_observation_layout(env):
        if block.names[0] == first:
            return obs[start : start + block.size]
        start += block.size
    raise KeyError(first)


@pytest.mark.parametrize("kwargs", OPTIONS)
def test_the_spaces_are_the_layouts(kwargs: dict) -> None:
    env = ACLClimbEnv(**kwargs)
    observations, actions = env_observation_layout(env), env_action_layout(env)
    assert env.observation_space.shape == (size(observations),)
    assert env.action_space.shape == (size(actions),)
    assert env.action_names == names(actions)
    assert len(set(names(observations))) == size(observations)  # every entry named once
    obs, _ = env.reset(seed=0)
    assert obs.shape == env.observation_space.shape
    # The blocks hold what they name.
    n = env.n_joints
    np.testing.assert_array_equal(_block(env, obs, "target_0"), env._base_target())
    angle = 2.0 * math.pi * env._keyframe / env.steps_per_cycle
    np.testing.assert_allclose(_block(env, obs, "phase_cos"), [math.cos(angle), math.sin(angle)])
    if kwargs.get("actuator_model") is None:  # the servo reads the joints without delay
        np.testing.assert_array_equal(_block(env, obs, "angle_0"), env.data.qpos[7 : 7 + n])
    if env.config.grip is not None:
        np.testing.assert_array_equal(_block(env, obs, "grip_force_0"), env._grip.force)
    if env.config.episode.privileged_obs:
        np.testing.assert_array_equal(_block(env, obs, "com_x"), env._com_view)
    env.close()


def test_the_compliant_task_observes_97_values_named_by_the_layout() -> None:
    env = gym.make("acl_env/ACLClimbCompliant-v1").unwrapped
    assert env.observation_space.shape == (97,)
    assert names(env_observation_layout(env))[-8:] == (
        *(f"grip_offset_{s}" for s in range(4)),
        *(f"grip_force_{s}" for s in range(4)),
    )
    assert env.action_names[-5:] == (*(f"grip_section_{s}" for s in range(4)), "cadence")
    env.close()


def test_the_signature_is_the_declared_arguments() -> None:
    """``ARGUMENTS`` is the constructor's signature, with its defaults; every registered id's
    keyword arguments are among them."""
    parameters = inspect.signature(ACLClimbEnv).parameters
    assert list(parameters) == [a.name for a in ARGUMENTS]
    assert {k: p.default for k, p in parameters.items()} == DEFAULTS
    for env_id in (k for k in gym.registry if k.startswith("acl_env/")):
        assert set(gym.spec(env_id).kwargs) <= set(DEFAULTS), env_id


def test_each_concern_is_a_typed_config() -> None:
    config = gym.make("acl_env/ACLClimbCompliant-v1").unwrapped.config
    assert isinstance(config, EnvConfig)
    assert config.physics.pole_radius == 0.075 and config.physics.frame_skip == 30
    assert config.actuator.model.name == "sea"
    assert config.actuator.values["spring_stiffness"] == 20.0
    assert config.gait.tuned_gait == "acl_sea" and config.gait.phase_rate_range == (0.5, 2.0)
    assert config.grip is not None and config.grip.action_scale > 0.0
    assert config.episode.cycles_per_episode == 2 and config.render.camera_name == "track"
    with pytest.raises(AttributeError):
        config.physics.pole_radius = 0.1  # type: ignore[misc]  # frozen: checked once


def test_an_unknown_keyword_argument_is_a_type_error_naming_it() -> None:
    with pytest.raises(TypeError, match="unexpected keyword argument 'pole_radus'"):
        ACLClimbEnv(pole_radus=0.08)
    with pytest.raises(TypeError, match="unexpected keyword argument"):
        gym.make(acl_env.ACL_CLIMB_SEA_ID, spring_stifness=20.0)


@pytest.mark.parametrize("name", ["acl_climb_sea_ppo", "acl_climb_compliant_ppo"])
def test_a_policy_carries_its_entries_names_and_meets_the_same_layout(name: str) -> None:
    """The export writes the layouts' names into ``policy.json``; loading checks them against
    the env, so a policy meets an env whose entries are the ones it was trained on."""
    from acl_env import pretrained

    policy = pretrained.load_policy(name)
    env = gym.make(policy.env_id, **policy.env_kwargs)
    assert policy.observation_names == names(env_observation_layout(env.unwrapped))
    assert policy.action_names == env.unwrapped.action_names
    policy.check_spaces(env)
    swapped = list(policy.observation_names)
    swapped[0], swapped[1] = swapped[1], swapped[0]
    policy.observation_names = tuple(swapped)
    with pytest.raises(pretrained.SpaceMismatchError, match="observes 'angle_1' at entry 0"):
        policy.check_spaces(env)
    env.close()


def test_friction_step_makes_the_pole_slippery_at_a_drawn_step() -> None:
    """``friction_step``: the skin's and the pole's friction drop at one step drawn at reset,
    ``info["slippery"]`` from then on; the next reset restores the episode's friction."""
    env = ACLClimbEnv(friction_step=0.5, **{"steps_per_cycle": 20, "cycles_per_episode": 2})
    pole = env.model.geom("pole").id
    env.reset(seed=4)
    at = env._friction_step.at
    assert 1 <= at < 40
    flags = []
    for step in range(40):
        _, _, terminated, _, info = env.step(np.zeros(env.action_space.shape))
        flags.append(info["slippery"])
        expected = 0.5 if step >= at else 1.0
        assert env.model.geom_friction[pole, 0] == expected, step
        if terminated:
            break
    assert flags[: min(at, len(flags))] == [False] * min(at, len(flags))
    env.reset(seed=4)
    assert env.model.geom_friction[pole, 0] == 1.0 and env._friction_step.at == at
    plain = ACLClimbEnv(steps_per_cycle=20, cycles_per_episode=2)
    assert "slippery" not in plain.reset(seed=4)[1] and plain._friction_step is None
    with pytest.raises(ValueError, match="friction_step"):
        ACLClimbEnv(friction_step=-1.0)


def test_friction_step_randomised_draws_each_episode_its_friction() -> None:
    """``domain_randomization={"friction_step": (low, high)}``: every episode's pole changes to a
    friction drawn from the range, at a drawn step; the draws come after the others, so the
    episode's physics up to the step is the one without the event, bit for bit."""
    short = {"steps_per_cycle": 20, "cycles_per_episode": 2}
    ranges = {"friction": (0.7, 1.2)}
    env = ACLClimbEnv(domain_randomization={**ranges, "friction_step": (0.4, 0.6)}, **short)
    plain = ACLClimbEnv(domain_randomization=ranges, **short)
    pole = env.model.geom("pole").id
    drawn = set()
    for seed in range(3):
        obs, _ = env.reset(seed=seed)
        assert np.array_equal(obs, plain.reset(seed=seed)[0])
        assert env.model.geom_friction[pole, 0] == plain.model.geom_friction[pole, 0]
        step = env._friction_step
        assert 0.4 <= step.friction <= 0.6 and 1 <= step.at < 40
        drawn.add(step.friction)
        for _ in range(step.at + 1):
            *_, terminated, _, info = env.step(np.zeros(env.action_space.shape))
            if terminated:
                break
        else:
            assert info["slippery"] and env.model.geom_friction[pole, 0] == step.friction
    assert len(drawn) == 3
    with pytest.raises(ValueError, match="friction_step"):
        ACLClimbEnv(domain_randomization={"friction_step": (0.5, 9.0)})
    assert "friction_step" not in ACLClimbEnv(domain_randomization=True).config.randomization
    with pytest.raises(ValueError, match="both given"):
        ACLClimbEnv(friction_step=0.5, domain_randomization={"friction_step": (0.4, 0.6)})
