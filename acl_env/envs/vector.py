"""Many climbing worlds in one process: ``gym.make_vec(id, num_envs=N)`` for every ``acl_env`` id.

:class:`ACLClimbVectorEnv` holds N worlds of one task, each an :class:`~acl_env.envs.ACLClimbEnv`
with its own ``MjData``, random generator and domain randomisation, and steps them on a pool of
threads. MuJoCo releases Python's GIL inside ``mj_step``, so the worlds' physics runs on several
cores at once while their gait, observation and reward code takes turns. World ``i`` is exactly
the env ``gym.make(id)`` seeded ``seed + i``: the same observations, rewards, terminations, infos
and resets, bit for bit, as Gymnasium's ``SyncVectorEnv`` over those envs (tested). Autoreset
follows Gymnasium's ``NEXT_STEP`` mode: the step after a world ends returns its reset
observation, reward 0, and neither terminated nor truncated.

``threads`` (default: one per core, at most one per world) sets the pool; 1 steps the worlds in
the calling thread. ``vectorization_mode="sync"`` or ``"async"`` still gives Gymnasium's own
vector envs.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any, TypeVar

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space, concatenate, create_empty_array

from acl_env.envs.acl_climb import ACLClimbEnv
from acl_env.validation import check_int

T = TypeVar("T")
MAX_WORLDS = 4096
MAX_THREADS = 256


class ACLClimbVectorEnv(VectorEnv):
    """``num_envs`` worlds of the task the keyword arguments ``kwargs`` spell, stepped on
    ``threads`` threads (module docstring)."""

    metadata: dict[str, Any] = {  # noqa: RUF012  (Gymnasium's attribute)
        "autoreset_mode": AutoresetMode.NEXT_STEP,
        "render_modes": ACLClimbEnv.metadata["render_modes"],
        "render_fps": ACLClimbEnv.metadata["render_fps"],
    }

    def __init__(self, num_envs: int = 1, threads: int | None = None, **kwargs: Any) -> None:
        self.num_envs = check_int("num_envs", num_envs, 1, MAX_WORLDS)
        if threads is None:
            threads = min(self.num_envs, os.cpu_count() or 1)
        self.threads = check_int("threads", threads, 1, MAX_THREADS)
        self.envs = [ACLClimbEnv(**kwargs) for _ in range(self.num_envs)]
        first = self.envs[0]
        self.render_mode = first.render_mode
        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._observations = create_empty_array(self.single_observation_space, self.num_envs)
        self._rewards = np.zeros(self.num_envs, dtype=np.float64)
        self._terminations = np.zeros(self.num_envs, dtype=np.bool_)
        self._truncations = np.zeros(self.num_envs, dtype=np.bool_)
        self._autoreset = np.zeros(self.num_envs, dtype=np.bool_)
        self._pool = ThreadPoolExecutor(self.threads) if self.threads > 1 else None

    def _map(self, work: Callable[[int], T]) -> list[T]:
        """``work(i)`` for every world, in order; on the pool when there is one."""
        if self._pool is None:
            return [work(i) for i in range(self.num_envs)]
        return list(self._pool.map(work, range(self.num_envs)))

    def reset(
        self, *, seed: int | Sequence[int | None] | None = None, options: dict | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Reset every world: world ``i`` with ``seed + i`` (a list: one seed per world)."""
        if seed is None or isinstance(seed, int):
            seeds = [None if seed is None else seed + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(f"seed must give {self.num_envs} seeds, got {len(seeds)}")
        results = self._map(lambda i: self.envs[i].reset(seed=seeds[i], options=options))
        self._autoreset[:] = False
        infos = self._merged_infos([info for _, info in results])
        observations = [obs for obs, _ in results]
        concatenate(self.single_observation_space, observations, self._observations)
        return self._observations.copy(), infos

    def step(
        self, actions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """One step of every world; a world that ended on the last step is reset instead."""
        actions = np.asarray(actions)

        def one(i: int) -> tuple[Any, float, bool, bool, dict[str, Any]]:
            env = self.envs[i]
            if self._autoreset[i]:
                obs, info = env.reset()
                return obs, 0.0, False, False, info
            return env.step(actions[i])

        results = self._map(one)
        for i, (_, reward, terminated, truncated, _) in enumerate(results):
            self._rewards[i], self._terminations[i], self._truncations[i] = (
                reward,
                terminated,
                truncated,
            )
        infos = self._merged_infos([r[4] for r in results])
        concatenate(self.single_observation_space, [r[0] for r in results], self._observations)
        self._autoreset = self._terminations | self._truncations
        return (
            self._observations.copy(),
            self._rewards.copy(),
            self._terminations.copy(),
            self._truncations.copy(),
            infos,
        )

    def _merged_infos(self, infos: list[dict[str, Any]]) -> dict[str, Any]:
        """The worlds' infos as Gymnasium's vector envs give them (each key an array over the
        worlds, ``_key`` the mask of worlds that have it). When every world reports the same
        scalar keys, as the climbing env does, the arrays are built at once, with the dtypes
        ``VectorEnv._add_info`` gives (the first world's value's type); else through it."""
        keys = infos[0].keys()
        scalar = (bool, int, float, np.number)
        if all(info.keys() == keys for info in infos) and all(
            isinstance(v, scalar) for v in infos[0].values()
        ):
            merged: dict[str, Any] = {}
            for key in keys:
                kind = type(infos[0][key])
                merged[key] = np.array([info[key] for info in infos], dtype=kind)
                merged[f"_{key}"] = np.ones(self.num_envs, dtype=np.bool_)
            return merged
        merged = {}
        for i, info in enumerate(infos):
            merged = self._add_info(merged, info, i)
        return merged

    def render(self) -> tuple[Any, ...] | None:
        """Each world's frame (``render_mode`` as the single env's)."""
        if self.render_mode is None:
            return None
        return tuple(env.render() for env in self.envs)

    def close_extras(self, **kwargs: Any) -> None:
        """Close the worlds and the thread pool."""
        if self._pool is not None:
            self._pool.shutdown()
        for env in self.envs:
            env.close()


__all__ = ["ACLClimbVectorEnv"]
