"""The native vector env (``acl_env.envs.vector``): ``gym.make_vec`` of every id, world for world
equal to Gymnasium's ``SyncVectorEnv`` over ``gym.make`` envs, resets included."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import acl_env
from acl_env import RENAMED_IDS
from acl_env.envs.vector import ACLClimbVectorEnv

IDS = sorted(k for k in gym.registry if k.startswith("acl_env/") and k not in RENAMED_IDS)
SHORT = {"steps_per_cycle": 20, "cycles_per_episode": 1}  # 20-step episodes: resets within


def _play_both(env_id: str, steps: int, num_envs: int, **kwargs: Any) -> int:
    """Step the native and the sync vector env with the same random actions; assert every output
    equal, bit for bit; return how many episodes ended."""
    native = gym.make_vec(env_id, num_envs=num_envs, **kwargs)
    sync = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="sync", **kwargs)
    assert isinstance(native, ACLClimbVectorEnv)
    assert native.metadata["autoreset_mode"] == sync.metadata["autoreset_mode"]
    obs, info = native.reset(seed=11)
    expected_obs, expected_info = sync.reset(seed=11)
    np.testing.assert_array_equal(obs, expected_obs)
    assert info.keys() == expected_info.keys()
    rng, ended = np.random.default_rng(3), 0
    for t in range(steps):
        action = rng.uniform(-1.0, 1.0, native.action_space.shape).astype(np.float32)
        got, want = native.step(action), sync.step(action)
        for a, b in zip(got[:4], want[:4], strict=True):
            np.testing.assert_array_equal(a, b, err_msg=f"{env_id} step {t}")
        assert got[4].keys() == want[4].keys(), f"{env_id} step {t}"
        for key in got[4]:
            np.testing.assert_array_equal(got[4][key], want[4][key], err_msg=f"{key} step {t}")
            assert got[4][key].dtype == want[4][key].dtype, f"{key} step {t}"
        ended += int(got[2].sum() + got[3].sum())
    native.close()
    sync.close()
    return ended


@pytest.mark.parametrize("env_id", IDS)
def test_every_id_equals_the_sync_vector_env(env_id: str) -> None:
    assert _play_both(env_id, 45, 3, domain_randomization=True, **SHORT) >= 3


def test_500_steps_with_randomisation_cadence_and_grip() -> None:
    """The compliant task: the grip's 100 Hz loop, the cadence action, domain randomisation."""
    ended = _play_both(acl_env.ACL_CLIMB_COMPLIANT_ID, 500, 2, domain_randomization=True, **SHORT)
    assert ended >= 2 * 24  # every world reset 24 times or more


def test_threads_change_nothing() -> None:
    outputs = []
    for threads in (1, 2):
        env = gym.make_vec(acl_env.ACL_CLIMB_SEA_ID, num_envs=3, threads=threads, **SHORT)
        obs, _ = env.reset(seed=0)
        steps = [env.step(np.full(env.action_space.shape, 0.3, np.float32)) for _ in range(25)]
        outputs.append((obs, [s[0] for s in steps], [s[1] for s in steps]))
        env.close()
    for a, b in zip(*outputs, strict=True):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))


def test_bad_arguments_are_refused_by_name() -> None:
    with pytest.raises(ValueError, match="num_envs"):
        ACLClimbVectorEnv(num_envs=0)
    with pytest.raises(ValueError, match="threads"):
        ACLClimbVectorEnv(num_envs=2, threads=0)
    env = ACLClimbVectorEnv(num_envs=2, **SHORT)
    with pytest.raises(ValueError, match="2 seeds"):
        env.reset(seed=[1, 2, 3])
    env.close()


def test_sb3_thread_vec_env_equals_dummy_vec_env() -> None:
    """``acl-train --vec-env threads``: SB3's DummyVecEnv semantics, the envs on threads."""
    pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.vec_env import DummyVecEnv

    from acl_env.training.thread_vec_env import ThreadVecEnv

    def fns() -> list:
        return [lambda: gym.make(acl_env.ACL_CLIMB_SEA_ID, **SHORT) for _ in range(3)]

    threaded, plain = ThreadVecEnv(fns(), threads=2), DummyVecEnv(fns())
    for env in (threaded, plain):
        env.seed(7)
    np.testing.assert_array_equal(threaded.reset(), plain.reset())
    rng, ended = np.random.default_rng(1), 0
    for _ in range(45):
        action = rng.uniform(-1.0, 1.0, (3, *plain.action_space.shape)).astype(np.float32)
        for env in (threaded, plain):
            env.step_async(action)
        (obs, rew, done, info), (obs2, rew2, done2, info2) = threaded.step_wait(), plain.step_wait()
        np.testing.assert_array_equal(obs, obs2)
        np.testing.assert_array_equal(rew, rew2)
        np.testing.assert_array_equal(done, done2)
        for a, b in zip(info, info2, strict=True):
            assert a.keys() == b.keys()
            if "terminal_observation" in a:
                np.testing.assert_array_equal(a["terminal_observation"], b["terminal_observation"])
        ended += int(done.sum())
    assert ended >= 3
    threaded.close()
    plain.close()
