"""SB3's ``DummyVecEnv`` with its envs stepped on a pool of threads (``acl-train --vec-env
threads``).

Everything runs in the trainer's process, as with ``dummy``; the envs' steps run on ``threads``
threads, so that MuJoCo's ``mj_step``, which releases the GIL, runs on several cores while the
envs' Python takes turns. The semantics are ``DummyVecEnv``'s (auto-reset with
``terminal_observation``, ``TimeLimit.truncated``): each env is stepped, and reset when done,
exactly as there, only not one after the other.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from copy import deepcopy
from typing import Any

import gymnasium
import numpy as np
from stable_baselines3.common.vec_env import DummyVecEnv
from stable_baselines3.common.vec_env.base_vec_env import VecEnvStepReturn


class ThreadVecEnv(DummyVecEnv):
    """``DummyVecEnv`` whose ``step_wait`` steps the envs on ``threads`` threads (default: one
    per core, at most one per env)."""

    def __init__(
        self, env_fns: list[Callable[[], gymnasium.Env]], threads: int | None = None
    ) -> None:
        super().__init__(env_fns)
        self.threads = threads or min(self.num_envs, os.cpu_count() or 1)
        self._pool = ThreadPoolExecutor(self.threads)

    def _step_one(self, i: int) -> None:
        """Step env ``i`` (reset it when done) into the buffers' row ``i``, as DummyVecEnv."""
        obs, self.buf_rews[i], terminated, truncated, self.buf_infos[i] = self.envs[i].step(
            self.actions[i]
        )
        self.buf_dones[i] = terminated or truncated
        self.buf_infos[i]["TimeLimit.truncated"] = truncated and not terminated
        if self.buf_dones[i]:
            self.buf_infos[i]["terminal_observation"] = obs
            obs, self.reset_infos[i] = self.envs[i].reset()
        self._save_obs(i, obs)

    def step_wait(self) -> VecEnvStepReturn:
        list(self._pool.map(self._step_one, range(self.num_envs)))
        return (
            self._obs_from_buf(),
            np.copy(self.buf_rews),
            np.copy(self.buf_dones),
            deepcopy(self.buf_infos),
        )

    def close(self) -> None:
        self._pool.shutdown()
        super().close()

    def __getstate__(self) -> dict[str, Any]:  # the pool does not pickle
        raise TypeError("ThreadVecEnv does not pickle")


__all__ = ["ThreadVecEnv"]
