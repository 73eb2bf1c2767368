"""Running controllers: every controller on every seed, in worker processes or in this one."""

from __future__ import annotations

import multiprocessing
from collections.abc import Sequence
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed
from dataclasses import replace
from pathlib import Path
from typing import Any

import gymnasium
from tqdm import tqdm

from acl_env import cli
from acl_env.evaluation.baselines import (
    AT_POLICY_CADENCE,
    DEFAULT_TUNED_GAITS,
    Controller,
    build_controllers,
    is_policy,
    policy_name,
    read_policy,
)
from acl_env.evaluation.protocol import Episode, Policy, run_episode

_WORKER_CACHE: dict[str, tuple[gymnasium.Env, Policy]] = {}
# Envs a process keeps: a benchmark's cells each bring their own controllers, and an env holds
# about 9 MB; the least recently used is closed beyond this many.
WORKER_CACHE_SIZE = 16


def _env_and_policy(controller: Controller) -> tuple[gymnasium.Env, Policy]:
    """One env and policy per controller and process, reused across its episodes."""
    key = repr(controller)
    if key in _WORKER_CACHE:
        _WORKER_CACHE[key] = _WORKER_CACHE.pop(key)  # most recently used last
    else:
        while len(_WORKER_CACHE) >= WORKER_CACHE_SIZE:
            env, _ = _WORKER_CACHE.pop(next(iter(_WORKER_CACHE)))
            env.close()
        env = controller.make_env()
        _WORKER_CACHE[key] = (env, controller.make_policy(env))
    return _WORKER_CACHE[key]


def _run_task(controller: Controller, seed: int, gym_packages: Sequence[str]) -> Episode:
    """Worker task: one episode of one controller."""
    for name in gym_packages:
        cli.importable_module(name)
    env, policy = _env_and_policy(controller)
    return run_episode(env, policy, seed)


def run_controllers(
    controllers: Sequence[Controller],
    seeds: Sequence[int],
    pool: Executor | None,
    gym_packages: Sequence[str] = (),
    progress: bool = True,
) -> dict[str, list[Episode]]:
    """Every controller on every seed, in ``pool`` (or in this process when None)."""
    tasks = [(c, s) for c in controllers for s in seeds]
    results: dict[tuple[str, int], Episode] = {}
    with tqdm(total=len(tasks), desc="episodes", unit="ep", disable=not progress) as bar:
        if pool is None:
            for controller, seed in tasks:
                results[controller.name, seed] = _run_task(controller, seed, gym_packages)
                bar.update()
        else:
            futures = {
                pool.submit(_run_task, c, s, tuple(gym_packages)): (c.name, s) for c, s in tasks
            }
            for future in as_completed(futures):
                results[futures[future]] = future.result()
                bar.update()
    return {c.name: [results[c.name, s] for s in seeds] for c in controllers}


def make_pool(workers: int) -> Executor | None:
    """Worker processes for :func:`evaluate` (None: run in this process). Spawned, not forked:
    the parent may have loaded torch, which a forked child can deadlock on."""
    if workers <= 1:
        return None
    return ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))


def evaluate(
    controllers: Sequence[Controller],
    seeds: Sequence[int],
    workers: int = 2,
    gym_packages: Sequence[str] = (),
    progress: bool = True,
    pool: Executor | None = None,
) -> dict[str, list[Episode]]:
    """Run the controllers; the same-cadence open loops run last, at the mean rate of the policy
    (or of the policies, :func:`policies_controllers`).

    Episodes run in ``pool`` when given (reused across calls), else in ``workers`` processes.
    """
    first = [c for c in controllers if c.name not in AT_POLICY_CADENCE]
    later = [c for c in controllers if c.name in AT_POLICY_CADENCE]
    own_pool = pool is None
    if own_pool:
        pool = make_pool(workers)
    try:
        results = run_controllers(first, seeds, pool, gym_packages, progress)
        if later:
            played = [e for name, eps in results.items() if is_policy(name) for e in eps]
            rate = sum(e.keyframes for e in played) / sum(e.steps for e in played)
            later = [replace(c, phase_rate=float(rate)) for c in later]
            results |= run_controllers(later, seeds, pool, gym_packages, progress)
    finally:
        if own_pool and pool is not None:
            pool.shutdown()
    return {c.name: results[c.name] for c in controllers}


class PolicySetError(ValueError):
    """Policies that are not the seeds of one recipe: of other tasks, or of one folder name."""


def policies_controllers(
    policies: Sequence[str | Path],
    overrides: dict[str, Any],
    tuned_path: Path = DEFAULT_TUNED_GAITS,
    reward_weights: dict[str, float] | None = None,
    tuned_key: str | None = None,
    trust_pickles: bool = False,
) -> tuple[list[Controller], list[str]]:
    """Each policy (named :func:`policy_name`) and the analytic controllers the first is judged
    against (:func:`~acl_env.evaluation.baselines.build_controllers`), under ``overrides``; and
    that build's notes."""
    names = [policy_name(path) for path in policies]
    twice = sorted({name for name in names if names.count(name) > 1})
    if twice:
        raise PolicySetError(
            f"several policies share a folder name ({', '.join(twice)}): the records name each "
            "policy by its folder's name, so give each seed a folder of its own name"
        )
    own: list[Controller] = []
    analytic: list[Controller] = []
    notes: list[str] = []
    for index, path in enumerate(policies):
        folder = read_policy(path)
        controllers, built_notes = build_controllers(
            folder, overrides, reward_weights, tuned_path, tuned_key, trust_pickles
        )
        policy = next(c for c in controllers if c.name == "policy")
        if own and (policy.env_id, policy.env_kwargs) != (own[0].env_id, own[0].env_kwargs):
            raise PolicySetError(
                f"{path} was trained on another task than {policies[0]} (env kwargs "
                f"{policy.env_kwargs} against {own[0].env_kwargs}): the seeds of one recipe only"
            )
        own.append(replace(policy, name=names[index], label=Path(path).name))
        if index == 0:
            analytic, notes = [c for c in controllers if c.name != "policy"], built_notes
    return own + analytic, notes
