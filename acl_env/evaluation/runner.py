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

from acl_env.evaluation.baselines import (
    AT_POLICY_CADENCE,
    DEFAULT_TUNED_GAITS,
    Controller,
    build_controllers,
    read_policy,
)
from acl_env.evaluation.protocol import Episode, Policy, run_episode
from acl_env.training import cli

_WORKER_CACHE: dict[str, tuple[gymnasium.Env, Policy]] = {}


def _env_and_policy(controller: Controller) -> tuple[gymnasium.Env, Policy]:
    """One env and policy per controller and process, reused across its episodes."""
    key = repr(controller)
    if key not in _WORKER_CACHE:
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


# A policy's controller name when several policies (the training seeds of one recipe) play.
POLICY_PREFIX = "policy:"


def is_policy(name: str) -> bool:
    """Whether controller ``name`` is a policy: ``policy``, or one of several."""
    return name == "policy" or name.startswith(POLICY_PREFIX)


def policy_name(path: str | Path) -> str:
    """A policy's controller name among several: ``policy:<folder name>``."""
    return f"{POLICY_PREFIX}{Path(path).name}"


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
    own: list[Controller] = []
    analytic: list[Controller] = []
    notes: list[str] = []
    for index, path in enumerate(policies):
        folder = read_policy(path)
        controllers, built_notes = build_controllers(
            folder, overrides, reward_weights, tuned_path, tuned_key, trust_pickles
        )
        policy = next(c for c in controllers if c.name == "policy")
        own.append(replace(policy, name=policy_name(path), label=Path(path).name))
        if index == 0:
            analytic, notes = [c for c in controllers if c.name != "policy"], built_notes
    return own + analytic, notes
