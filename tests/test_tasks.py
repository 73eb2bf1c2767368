"""The benchmark tasks are registered ids whose defaults are the shipped policies' tasks."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import yaml

import acl_env
from acl_env import shipped, tuned_gaits
from acl_env.evaluation.tasks import spelled_on_base


def _recipe() -> dict:
    return yaml.safe_load(shipped.recipe_path().read_text())


def _constructor_kwargs(env_id: str, env_kwargs: dict) -> dict:
    """What ACLClimbEnv is built with: the registration's kwargs under the call's, the tuned gait
    written out, tuples as lists (YAML has no tuples)."""
    kwargs = tuned_gaits.resolve({**gym.spec(env_id).kwargs, **env_kwargs})
    return {k: list(v) if isinstance(v, tuple) else v for k, v in kwargs.items()}


# The servo benchmark ids and the recipe entries whose env kwargs they register.
SERVO_BENCHMARKS = {
    acl_env.ACL_CLIMB_BENCHMARK_ID: acl_env.ACL_CLIMB_ID,
    acl_env.ACL_CLIMB_NOROLL_BENCHMARK_ID: acl_env.ACL_CLIMB_NOROLL_ID,
}
# The SEA ids and the servo benchmark ids whose tasks they are, on the SEA.
SEA_BENCHMARKS = {
    acl_env.ACL_CLIMB_SEA_ID: acl_env.ACL_CLIMB_BENCHMARK_ID,
    acl_env.ACL_CLIMB_NOROLL_SEA_ID: acl_env.ACL_CLIMB_NOROLL_BENCHMARK_ID,
}


@pytest.mark.parametrize(("task", "base"), list(SERVO_BENCHMARKS.items()))
def test_benchmark_id_is_the_shipped_recipes_task(task: str, base: str) -> None:
    """The recipe for a benchmark id trains what the shipped recipe on its base id trains (the
    shipped policy's task): the same hyperparameters, and the id's defaults plus domain
    randomisation build the env the base entry's env kwargs build."""
    recipe = _recipe()
    new, old = dict(recipe[task]), dict(recipe[base])
    new_kwargs, old_kwargs = new.pop("env_kwargs"), old.pop("env_kwargs")
    assert new == old
    assert set(new_kwargs) == {"domain_randomization"}  # only the training choice is left
    assert _constructor_kwargs(task, new_kwargs) == _constructor_kwargs(base, old_kwargs)


@pytest.mark.parametrize(("task", "servo"), list(SEA_BENCHMARKS.items()))
def test_sea_id_is_the_servo_task_on_the_sea(task: str, servo: str) -> None:
    """ACLClimb-v3 (NoRoll-v5) trains with ACLClimb-v2's (NoRoll-v4's) hyperparameters, on its
    task with the SEA and the gait tuned there, and randomises the SEA's parameters."""
    recipe = _recipe()
    new, old = dict(recipe[task]), dict(recipe[servo])
    new_kwargs = new.pop("env_kwargs")
    old.pop("env_kwargs")
    assert new == old
    assert set(new_kwargs) == {"domain_randomization"}
    assert {"spring_stiffness", "motor_speed_limit", "control_latency"} <= set(
        new_kwargs["domain_randomization"]
    )
    own = tuned_gaits.resolve(gym.spec(task).kwargs)
    theirs = tuned_gaits.resolve(gym.spec(servo).kwargs)
    shape = {"squeeze", "gait_kwargs"}
    assert {k: v for k, v in own.items() if k not in shape | {"actuator_model"}} == {
        k: v for k, v in theirs.items() if k not in shape
    }
    assert own["actuator_model"] == "sea"
    assert own["gait_kwargs"] != theirs["gait_kwargs"]  # the gait tuned on the SEA


@pytest.mark.parametrize(("task", "base"), list(acl_env.BENCHMARK_BASES.items()))
def test_benchmark_id_steps_as_its_base_with_the_recipes_kwargs(task: str, base: str) -> None:
    """Bit for bit: the same seeded actions on the benchmark id with no kwargs and on its base id
    with the kwargs that spell it (the shipped recipe's, less domain randomisation; for the SEA
    ids, with the SEA and its gait) give the same steps."""
    _, kwargs = spelled_on_base(task, {})
    envs = [gym.make(task), gym.make(base, **kwargs)]
    assert envs[0].action_space == envs[1].action_space
    assert envs[0].observation_space == envs[1].observation_space
    _assert_step_alike(envs, seeds=(3,), steps=15)


def _assert_step_alike(envs: list[gym.Env], seeds: tuple[int, ...], steps: int) -> None:
    """The two envs, reset with each seed and given the same random actions, step alike: the
    same observations, rewards, terminations and infos, bit for bit."""
    rng = np.random.default_rng(0)
    for seed in seeds:
        obs = [env.reset(seed=seed)[0] for env in envs]
        np.testing.assert_array_equal(obs[0], obs[1])
        for _ in range(steps):
            action = rng.uniform(-1, 1, envs[0].action_space.shape).astype(np.float32)
            results = [env.step(action) for env in envs]
            np.testing.assert_array_equal(results[0][0], results[1][0])
            assert results[0][1:4] == results[1][1:4]


def test_the_paper_default_gait_env_stays_registered() -> None:
    """ACLClimb-v1 is still the paper's default gait with a plain joint residual."""
    env = gym.make(acl_env.ACL_CLIMB_ID).unwrapped
    assert (
        env.config.gait.residual_scale == pytest.approx(0.2)
        and env.config.gait.phase_rate_range is None
    )
    assert env.config.gait.squeeze == pytest.approx(0.008)


@pytest.mark.parametrize("old_id", sorted(acl_env.RENAMED_IDS))
def test_an_old_id_is_its_new_id_step_for_step(old_id: str) -> None:
    """A renamed id makes the same env as its new name: the same observations and rewards,
    bit for bit, under the same seed and actions (its deprecation note aside)."""
    import warnings

    new_id = acl_env.RENAMED_IDS[old_id]
    with warnings.catch_warnings():  # the old id's note, and Gymnasium's for an older version
        warnings.simplefilter("ignore", DeprecationWarning)
        old = gym.make(old_id, cycles_per_episode=1)
        new = gym.make(new_id, cycles_per_episode=1)
    assert old.unwrapped.spec.kwargs == new.unwrapped.spec.kwargs
    (obs_a, _), (obs_b, _) = old.reset(seed=3), new.reset(seed=3)
    assert np.array_equal(obs_a, obs_b)
    rng = np.random.default_rng(0)
    for _ in range(30):
        action = rng.uniform(-1.0, 1.0, size=old.action_space.shape).astype(np.float32)
        a, b = old.step(action), new.step(action)
        assert np.array_equal(a[0], b[0]) and a[1:4] == b[1:4]


def test_robust_v3_is_v1_with_the_privileged_block_and_an_asymmetric_critic() -> None:
    """ACLClimbRobust-v3 steps as ACLClimbRobust-v1 with ``privileged_obs=True``, bit for bit,
    under domain randomisation; its recipe is v1's with the asymmetric critic and 1M steps, so
    that a run on v1 with those arguments (experiments/robust_ablation's asymmetric critic arm)
    trained v3's recipe and exports as v3's."""
    from acl_env.evaluation.tasks import most_specific_task

    v1, v3 = acl_env.ACL_CLIMB_ROBUST_ID, acl_env.ACL_CLIMB_ROBUST_V3_ID
    recipe = _recipe()
    new, old = dict(recipe[v3]), dict(recipe[v1])
    assert (new.pop("policy"), old.pop("policy")) == (
        "acl_env.training.networks.AsymmetricCriticPolicy",
        "MlpPolicy",
    )
    assert (new.pop("n_timesteps"), old.pop("n_timesteps")) == (1e6, 3e6)
    assert new == old
    randomization = recipe[v1]["env_kwargs"]["domain_randomization"]
    envs = [
        gym.make(v3, domain_randomization=randomization),
        gym.make(v1, privileged_obs=True, domain_randomization=randomization),
    ]
    assert envs[0].observation_space == envs[1].observation_space
    _assert_step_alike(envs, seeds=(3, 4), steps=40)
    dr = {"domain_randomization": randomization}
    assert most_specific_task(v1, {"privileged_obs": True, **dr}) == (v3, dr)
    assert most_specific_task(v1, dr) == (v1, dr)
    # An argument that undoes one of v1's defaults keeps v1's name.
    wider = {"privileged_obs": True, "residual_scale": 0.16}
    assert most_specific_task(v1, wider) == (v1, wider)
