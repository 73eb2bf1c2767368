"""The envs and the PPO model of a training segment: the monitored envs (in worker processes or
in the trainer), their steps and the policy's inference timed, and the model new, warm-started
from a trained policy (``--init-from``) or resumed (``--resume``). SB3 and torch are imported
when a segment is set up, not with this module.
"""

from __future__ import annotations

import functools
import multiprocessing
import os
import time
from typing import Any

from acl_env.training import warm_start
from acl_env.training.config import algo_kwargs, normalize_kwargs
from acl_env.training.plan import Plan
from acl_env.training.runs import load_vecnormalize
from acl_env.training.timing import Timed, timed_env


def n_workers(settings: dict[str, Any], n_envs: int) -> int:
    """Worker processes: the setting, or one per CPU core; never more than envs."""
    return min(int(settings.get("workers") or os.cpu_count() or 1), n_envs)


def make_training_env(
    env_id: str,
    hyperparams: dict[str, Any],
    seed: int,
    vec_env: str = "subproc",
    workers: int | None = None,
) -> Any:
    """Monitored envs: spread over ``workers`` subprocesses (``subproc``, default one per core;
    forkserver, so workers start clean), or all in this process (``dummy``, and always for a
    single env), or in this process on ``workers`` threads (``threads``)."""
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import DummyVecEnv

    from acl_env.training.thread_vec_env import ThreadVecEnv
    from acl_env.training.vec_env import MultiEnvSubprocVecEnv

    n_envs = int(hyperparams.get("n_envs", 1))
    subproc = vec_env == "subproc" and n_envs > 1
    if subproc:
        # Workers fork from a server that has imported SB3 (and torch) once, instead of each
        # importing it again: 8 workers started in 43 s on a loaded 2-core machine without this.
        multiprocessing.set_forkserver_preload(
            [
                "stable_baselines3.common.vec_env.subproc_vec_env",
                "acl_env.training.vec_env",
                "acl_env.training.timing",
            ]
        )
    threads = vec_env == "threads" and n_envs > 1
    vec_class = ThreadVecEnv if threads else DummyVecEnv
    vec_kwargs = None
    if subproc or threads:
        count = n_workers({"workers": workers}, n_envs)
        vec_kwargs = {"n_workers": count} if subproc else {"threads": count}
    return make_vec_env(
        functools.partial(timed_env, env_id, subproc),
        n_envs=n_envs,
        seed=seed,
        env_kwargs=hyperparams.get("env_kwargs") or {},
        vec_env_cls=MultiEnvSubprocVecEnv if subproc else vec_class,
        vec_env_kwargs=vec_kwargs,
    )


def timed_ppo() -> type:
    """A subclass of SB3's PPO that adds up the seconds of its gradient updates (imports SB3 and
    torch)."""
    from stable_baselines3 import PPO

    class TimedPPO(PPO):
        """PPO that adds up the seconds of its gradient updates (not saved with the model)."""

        update_seconds = 0.0

        def train(self) -> None:
            start = time.perf_counter()
            super().train()
            self.update_seconds += time.perf_counter() - start

        def _excluded_save_params(self) -> list[str]:
            return [*super()._excluded_save_params(), "update_seconds"]

    return TimedPPO


def build_model(
    plan: Plan, ppo_class: type, timer: Timed, verbose: int
) -> tuple[Any, Any, list[Any] | None]:
    """Seed, the training envs (their steps timed by ``timer``) and the model, new, warm-started
    or resumed, and the callbacks of the recipe; the envs are closed if any of it fails."""
    import torch
    from stable_baselines3.common.utils import set_random_seed

    from acl_env.training.callbacks import callbacks_from_config

    settings, seed = plan.settings, plan.seed
    torch.set_num_threads(int(settings["torch_threads"]))
    set_random_seed(seed)
    env = make_training_env(
        plan.env_id, plan.hyperparams, seed, str(settings["vec_env"]), settings["workers"]
    )
    env.step_async = timer.wrap("env_step", env.step_async)
    env.step_wait = timer.wrap("env_step", env.step_wait)
    try:
        norm_kwargs = normalize_kwargs(plan.hyperparams)
        if plan.resume_model is not None:
            env, model = _resumed_model(plan, ppo_class, env, verbose)
        else:
            env, model = _new_model(plan, ppo_class, env, norm_kwargs, verbose)
        model.policy.forward = timer.wrap("policy_inference", model.policy.forward)
        config_callbacks = callbacks_from_config(plan.hyperparams.get("callback"))
    except BaseException:
        close_envs(env)
        raise
    return env, model, config_callbacks


def _resumed_model(plan: Plan, ppo_class: type, env: Any, verbose: int) -> tuple[Any, Any]:
    """The envs (under the run's VecNormalize statistics, where it has them) and the run's model
    at its last save, to continue training."""
    settings, seed, run_dir = plan.settings, plan.seed, plan.run_dir
    assert run_dir is not None and plan.resume_model is not None
    if plan.resume_vecnormalize is not None:
        # The plan checked the folder is trusted (--trust-pickles) and the file reads.
        env = load_vecnormalize(plan.resume_vecnormalize, env, trust_pickles=True)
        env.training = True
    model = ppo_class.load(plan.resume_model, env=env, device=settings["device"])
    model.set_random_seed(seed)
    model.tensorboard_log = str(run_dir / "tb")
    model.verbose = verbose
    print(f"resuming {plan.resume_model} at {model.num_timesteps} steps (seed {seed})")
    return env, model


def _new_model(
    plan: Plan, ppo_class: type, env: Any, norm_kwargs: dict[str, Any] | None, verbose: int
) -> tuple[Any, Any]:
    """The envs (under VecNormalize with ``norm_kwargs``, unless None) and a new model of the
    recipe, warm-started from a trained policy where the plan says so."""
    from stable_baselines3.common.vec_env import VecNormalize

    if norm_kwargs is not None:
        env = VecNormalize(env, **norm_kwargs)
    model = ppo_class(
        env=env,
        seed=plan.seed,
        device=plan.settings["device"],
        verbose=verbose,
        **algo_kwargs(plan.hyperparams),
    )
    if plan.init_from is not None:
        _warm_start(model, env, plan.init_from)
    return env, model


def _warm_start(model: Any, env: Any, start: warm_start.TrainedStart) -> None:
    """Start ``model`` (and ``env``'s normalisation) as the trained policy (checked by the plan)."""
    state = warm_start.transfer(
        start.state, model.policy.state_dict(), start.shared, start.observed
    )
    model.policy.load_state_dict(state)
    if start.normalization is not None:
        warm_start.copy_normalization(start.normalization, env, start.observed)
    print(
        f"warm start from {start.model}: {len(start.shared)} of {model.action_space.shape[0]} "
        "actions carried over"
    )


def close_envs(env: Any) -> None:
    """Close the envs and their workers; a step reply still pending is not worth reading."""
    if hasattr(env.unwrapped, "waiting"):
        env.unwrapped.waiting = False
    env.close()
