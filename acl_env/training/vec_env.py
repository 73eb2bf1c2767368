"""A subprocess vector env with several envs per worker process.

SB3's ``SubprocVecEnv`` runs one process per env. On a machine with few cores and many envs that
means many processes taking turns on each core, and one message per env and step. Here ``n_workers``
processes each step a slice of the envs in turn and answer with one message: the trainer batches
inference over all envs while each core runs one worker. Semantics follow ``SubprocVecEnv``
(auto-reset with ``terminal_observation``, ``TimeLimit.truncated``, seeds and options applied at
the next reset, ``reset_infos``).

Workers ignore SIGINT and SIGTERM: a terminal's Ctrl-C (or a ``kill`` of the process group) goes
to the trainer, which stops at a consistent point and then closes them. ``close`` never hangs: a
worker that does not exit on ``close`` is killed, and an env left open at exit is closed before
multiprocessing's own exit handler would wait for workers that ignore its SIGTERM.
"""

from __future__ import annotations

import atexit
import contextlib
import itertools
import multiprocessing as mp
import signal
from collections.abc import Callable, Sequence
from multiprocessing.connection import Connection
from typing import Any

import gymnasium
import numpy as np
from stable_baselines3.common.vec_env.base_vec_env import (
    CloudpickleWrapper,
    VecEnv,
    VecEnvIndices,
    VecEnvObs,
    VecEnvStepReturn,
)
from stable_baselines3.common.vec_env.patch_gym import _patch_env
from stable_baselines3.common.vec_env.util import obs_space_info


def _worker(remote: Connection, parent_remote: Connection, fns: CloudpickleWrapper) -> None:
    """Serve commands for a slice of envs until ``close`` (or the trainer is gone)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    parent_remote.close()
    envs: list[gymnasium.Env] = [_patch_env(fn()) for fn in fns.var]
    reset_infos: list[dict[str, Any]] = [{} for _ in envs]
    while True:
        try:
            cmd, data = remote.recv()
        except EOFError:  # the trainer is gone
            break
        if cmd == "step":
            results = []
            for i, (env, action) in enumerate(zip(envs, data, strict=True)):
                obs, reward, terminated, truncated, info = env.step(action)
                done = terminated or truncated
                info["TimeLimit.truncated"] = truncated and not terminated
                if done:
                    info["terminal_observation"] = obs
                    obs, reset_infos[i] = env.reset()
                results.append((obs, reward, done, info))
            remote.send((results, list(reset_infos)))
        elif cmd == "reset":
            observations = []
            for i, (env, (seed, options)) in enumerate(zip(envs, data, strict=True)):
                obs, reset_infos[i] = env.reset(seed=seed, options=options)
                observations.append(obs)
            remote.send((observations, list(reset_infos)))
        elif cmd == "get_spaces":
            remote.send((envs[0].observation_space, envs[0].action_space))
        elif cmd == "get_attr":
            name, local = data
            remote.send([envs[i].get_wrapper_attr(name) for i in local])
        elif cmd == "set_attr":
            name, value, local = data
            for i in local:
                envs[i].set_wrapper_attr(name, value)
            remote.send(None)
        elif cmd == "env_method":
            name, args, kwargs, local = data
            remote.send([envs[i].get_wrapper_attr(name)(*args, **kwargs) for i in local])
        elif cmd == "is_wrapped":
            from stable_baselines3.common.env_util import is_wrapped

            remote.send([is_wrapped(envs[i], data[0]) for i in data[1]])
        elif cmd == "render":
            remote.send([env.render() for env in envs])
        elif cmd == "close":
            for env in envs:
                env.close()
            remote.close()
            break
        else:
            raise NotImplementedError(f"unknown command {cmd!r}")


class MultiEnvSubprocVecEnv(VecEnv):
    """``n_envs`` envs in ``n_workers`` processes (contiguous slices, sizes differing by <= 1)."""

    close_timeout_s = 10.0  # how long ``close`` waits for a worker before killing it

    def __init__(
        self,
        env_fns: Sequence[Callable[[], gymnasium.Env]],
        n_workers: int,
        start_method: str = "forkserver",
    ) -> None:
        n_envs = len(env_fns)
        if not 1 <= n_workers <= n_envs:
            raise ValueError(f"n_workers must be in [1, {n_envs}] (n_envs), got {n_workers}")
        bounds = np.linspace(0, n_envs, n_workers + 1).round().astype(int)
        self.slices = [range(int(a), int(b)) for a, b in itertools.pairwise(bounds)]
        self.where = [(w, i - s.start) for w, s in enumerate(self.slices) for i in s]
        ctx = mp.get_context(start_method)
        pipes = [ctx.Pipe() for _ in self.slices]
        self.remotes = [parent for parent, _ in pipes]
        self.processes = []
        for (parent, child), envs in zip(pipes, self.slices, strict=True):
            fns = CloudpickleWrapper([env_fns[i] for i in envs])
            process = ctx.Process(target=_worker, args=(child, parent, fns), daemon=True)
            process.start()
            self.processes.append(process)
            child.close()
        self.waiting = False
        self.closed = False
        atexit.register(self.close)  # runs before multiprocessing's exit handler (LIFO)
        self.remotes[0].send(("get_spaces", None))
        observation_space, action_space = self.remotes[0].recv()
        super().__init__(n_envs, observation_space, action_space)
        obs_space_info(observation_space)  # SB3's check that the space is supported

    def step_async(self, actions: np.ndarray) -> None:
        for remote, envs in zip(self.remotes, self.slices, strict=True):
            remote.send(("step", [actions[i] for i in envs]))
        self.waiting = True

    def step_wait(self) -> VecEnvStepReturn:
        results: list[Any] = []
        reset_infos: list[dict[str, Any]] = []
        for remote in self.remotes:
            worker_results, worker_reset_infos = remote.recv()
            results.extend(worker_results)
            reset_infos.extend(worker_reset_infos)
        self.waiting = False
        self.reset_infos = reset_infos
        obs, rewards, dones, infos = zip(*results, strict=True)
        return (
            np.stack(obs),
            np.array(rewards, dtype=np.float32),
            np.array(dones, dtype=bool),
            list(infos),
        )

    def reset(self) -> VecEnvObs:
        for remote, envs in zip(self.remotes, self.slices, strict=True):
            remote.send(("reset", [(self._seeds[i], self._options[i]) for i in envs]))
        observations: list[Any] = []
        self.reset_infos = []
        for remote in self.remotes:
            worker_obs, worker_reset_infos = remote.recv()
            observations.extend(worker_obs)
            self.reset_infos.extend(worker_reset_infos)
        self._reset_seeds()
        self._reset_options()
        return np.stack(observations)

    def close(self) -> None:
        """Ask the workers to close their envs and exit; kill any that has not within
        ``close_timeout_s`` (a pending step's reply is read first, or dropped)."""
        if self.closed:
            return
        for remote in self.remotes:
            with contextlib.suppress(OSError, EOFError, ValueError):
                if self.waiting and remote.poll(self.close_timeout_s):
                    remote.recv()
                remote.send(("close", None))
        self.waiting = False
        for process in self.processes:
            process.join(self.close_timeout_s)
            if process.is_alive():
                process.kill()
                process.join()
        for remote in self.remotes:
            remote.close()
        self.closed = True  # only now: a close cut short is done again at exit
        atexit.unregister(self.close)

    def get_images(self) -> Sequence[np.ndarray | None]:
        for remote in self.remotes:
            remote.send(("render", None))
        return [image for remote in self.remotes for image in remote.recv()]

    def _by_worker(self, indices: VecEnvIndices) -> dict[int, list[int]]:
        grouped: dict[int, list[int]] = {}
        for i in self._get_indices(indices):
            worker, local = self.where[i]
            grouped.setdefault(worker, []).append(local)
        return grouped

    def _ask(self, indices: VecEnvIndices, make: Callable[[list[int]], tuple[str, Any]]) -> list:
        grouped = self._by_worker(indices)
        for worker, local in grouped.items():
            self.remotes[worker].send(make(local))
        answers: list[Any] = []
        for worker in grouped:
            answers.extend(self.remotes[worker].recv() or [])
        return answers

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        return self._ask(indices, lambda local: ("get_attr", (attr_name, local)))

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        self._ask(indices, lambda local: ("set_attr", (attr_name, value, local)))

    def env_method(
        self,
        method_name: str,
        *method_args: Any,
        indices: VecEnvIndices = None,
        **method_kwargs: Any,
    ) -> list[Any]:
        return self._ask(
            indices, lambda local: ("env_method", (method_name, method_args, method_kwargs, local))
        )

    def env_is_wrapped(
        self, wrapper_class: type[gymnasium.Wrapper], indices: VecEnvIndices = None
    ) -> list[bool]:
        return self._ask(indices, lambda local: ("is_wrapped", (wrapper_class, local)))
