"""Where a training segment's time goes: seconds inside wrapped calls in the trainer
(:class:`Timed`), inside the envs' own ``step`` and ``reset`` in each worker (:class:`StepTimer`),
and the CPU seconds of the subprocess workers (:func:`workers_cpu_seconds`)."""

from __future__ import annotations

import functools
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import gymnasium

from acl_env.training.config import make_env, make_worker_env


class Timed:
    """Seconds spent inside wrapped callables, by name."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}

    def wrap(self, name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        self.seconds.setdefault(name, 0.0)

        @functools.wraps(fn)
        def timed(*a: Any, **kw: Any) -> Any:
            start = time.perf_counter()
            try:
                return fn(*a, **kw)
            finally:
                self.seconds[name] += time.perf_counter() - start

        return timed


def workers_cpu_seconds(env: Any) -> float:
    """CPU seconds (user + system) used so far by the subprocess workers of ``env``, from
    ``/proc`` (0 without workers or without ``/proc``)."""
    processes = getattr(env.unwrapped, "processes", None) or []
    total = 0.0
    for process in processes:
        try:
            fields = Path(f"/proc/{process.pid}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        total += (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    return total


class StepTimer(gymnasium.Wrapper):
    """Adds up the seconds spent in ``step`` and ``reset`` inside the worker (``step_seconds``),
    so that the trainer can tell the envs' own compute from transfer and waiting."""

    def __init__(self, env: gymnasium.Env) -> None:
        super().__init__(env)
        self.step_seconds = 0.0

    def step(self, action: Any) -> Any:
        start = time.perf_counter()
        try:
            return self.env.step(action)
        finally:
            self.step_seconds += time.perf_counter() - start

    def reset(self, **kwargs: Any) -> Any:
        start = time.perf_counter()
        try:
            return self.env.reset(**kwargs)
        finally:
            self.step_seconds += time.perf_counter() - start


def timed_env(env_id: str, worker: bool, **env_kwargs: Any) -> gymnasium.Env:
    """An env for the vector env: in a subprocess worker, one that leaves signals to the trainer."""
    env = make_worker_env(env_id, **env_kwargs) if worker else make_env(env_id, env_kwargs)
    return StepTimer(env)
