"""Train a residual PPO policy on an acl_env environment with Stable-Baselines3 (``acl-train``).

The base gait runs inside the env; PPO learns the residual. Hyperparameters come from a
rl-baselines3-zoo YAML entry keyed by env id: the shipped recipe (``acl_env/data/ppo.yml``), or
``--config``'s, possibly a delta over the shipped one (:mod:`acl_env.training.config`). Every run
writes a folder ``runs/<env>__<exp>__<seed>__<time>/`` with ``model.zip``, ``vecnormalize.pkl``,
``config.yml`` (the exact merged config, itself a zoo config), ``args.json`` (every segment's
command line and resolved settings), ``summary.json`` (every segment's steps, wall time,
interruption, where the time went), ``checkpoints/`` and TensorBoard logs (``tb/``).

Ctrl-C or SIGTERM stops at a consistent point: the gradient update in progress completes, the
unfinished rollout is discarded, and the model, its VecNormalize statistics and its step count of
the last completed update are saved (atomically: a second signal cannot corrupt them), and the
process exits with status 0. Output that cannot be written (``| head``, or a ``tee`` killed by the
same Ctrl-C) is dropped and never stops the save; ``summary.json`` records it (``output_lost``).
A SIGINT ignored from the start (a background job: ``nohup acl-train ... &``) stays ignored;
SIGTERM always stops the run.
``--resume RUN`` continues that run with its own config, seed and checkpoint frequency, with a
fresh random stream derived from (seed, segment index).
"""

from __future__ import annotations

import argparse
import functools
import multiprocessing
import os
import signal
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from acl_env.io import GuardedOutput, console_script, guarded_output
from acl_env.training import warm_start
from acl_env.training.checks import ConfigError
from acl_env.training.config import algo_kwargs, normalize_kwargs, save_hyperparams

# The plan, the timers and the deferred signals live in modules of their own; their names stay
# importable from here (acl_env.training.trainer.plan_segment, ...).
from acl_env.training.plan import DEFAULT_CONFIG as DEFAULT_CONFIG
from acl_env.training.plan import DEFAULT_SETTINGS as DEFAULT_SETTINGS
from acl_env.training.plan import RECIPE_OPTIONS as RECIPE_OPTIONS
from acl_env.training.plan import Plan, make_parser, plan_segment
from acl_env.training.plan import segment_seed as segment_seed
from acl_env.training.runs import (
    ARGS_FILE,
    CHECKPOINT_DIR,
    CONFIG_FILE,
    MODEL_FILE,
    SUMMARY_FILE,
    VECNORMALIZE_FILE,
    checkpoint_paths,
    load_vecnormalize,
    read_json,
    save_model,
    write_json,
)
from acl_env.training.signals import deferred_signals, is_output_failure
from acl_env.training.timing import StepTimer as StepTimer
from acl_env.training.timing import Timed, timed_env, workers_cpu_seconds

if TYPE_CHECKING:  # SB3 is imported when a segment runs
    from acl_env.training.callbacks import SafeStopCallback, TimingCallback


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
    single env)."""
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import DummyVecEnv

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
    return make_vec_env(
        functools.partial(timed_env, env_id, subproc),
        n_envs=n_envs,
        seed=seed,
        env_kwargs=hyperparams.get("env_kwargs") or {},
        vec_env_cls=MultiEnvSubprocVecEnv if subproc else DummyVecEnv,
        vec_env_kwargs={"n_workers": n_workers({"workers": workers}, n_envs)} if subproc else None,
    )


def _new_run_dir(parent: Path, env_id: str, exp_name: str, seed: int) -> Path:
    """``<parent>/<env>__<exp>__<seed>__<time>``, the env id's namespace slash made ``_``."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    base = f"{env_id.replace('/', '_')}__{exp_name}__{seed}__{stamp}"
    parent.mkdir(parents=True, exist_ok=True)
    for suffix in ("", *(f"-{i}" for i in range(2, 100))):
        try:
            (parent / (base + suffix)).mkdir()
            return parent / (base + suffix)
        except FileExistsError:
            continue
    raise FileExistsError(f"too many runs named {base} in {parent}")


def _summary(plan: Plan, segments: list[dict[str, Any]], total_steps: int) -> dict[str, Any]:
    done = [s for s in segments if s.get("status") != "running"]
    steps = sum(int(s.get("steps", 0)) for s in done)
    wall = sum(float(s.get("wall_time_s", 0.0)) for s in done)
    last = segments[-1]
    return {
        "env_id": plan.env_id,
        "total_steps": total_steps,
        "steps": steps,
        "wall_time_s": wall,
        "env_steps_per_s": steps / wall if wall > 0 else 0.0,
        "n_envs": last.get("n_envs"),
        "torch_threads": last.get("torch_threads"),
        "interrupted": bool(last.get("interrupted", False)),
        "interruptions": sum(bool(s.get("interrupted")) for s in segments),
        "segments": segments,
    }


def _previous_segments(history: dict[str, Any]) -> list[dict[str, Any]]:
    """Earlier segments; a summary from before segments were recorded becomes one segment, and a
    segment left ``running`` (the process was killed) is marked ``lost``."""
    if not history:
        return []
    if "segments" not in history:
        old = {k: v for k, v in history.items() if k not in ("env_id", "total_steps")}
        return [{"segment": 0, **old, "start_steps": 0, "end_steps": history.get("total_steps")}]
    segments = [dict(s) for s in history["segments"]]
    for s in segments:
        if s.get("status") == "running":
            s["status"] = "lost"
    return segments


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


def run_segment(
    plan: Plan,
    extra_callbacks: Sequence[Any] = (),
    verbose: int = 1,
    restore_signals: bool = True,
) -> Path:
    """Build the envs and the model, learn, save; return the run folder. SIGINT and SIGTERM are
    deferred while it runs (see :func:`deferred_signals`), and stdout and stderr are guarded (see
    :func:`guarded_output`): output that cannot be written is dropped, and the work is saved."""
    with guarded_output() as output:
        return _run_segment(plan, extra_callbacks, verbose, restore_signals, output)


def _timed_ppo() -> type:
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


def _build_model(
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
        _close(env)
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


def _open_segment(
    plan: Plan, model: Any, env: Any, segments: list[dict[str, Any]], start_steps: int
) -> tuple[Path, dict[str, Any]]:
    """The run folder (made, with its config, for a new run), ``args.json`` updated, and this
    segment's entry, recorded as ``running`` in ``summary.json``."""
    import torch

    run_dir = plan.run_dir
    if run_dir is None:
        run_dir = _new_run_dir(plan.run_parent, plan.env_id, plan.exp_name, plan.seed)
        save_hyperparams(run_dir / CONFIG_FILE, plan.env_id, plan.hyperparams)
    model.tensorboard_log = str(run_dir / "tb")
    _record_args(run_dir, plan)
    segment: dict[str, Any] = {
        "segment": plan.segment,
        "status": "running",
        "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "seed": plan.seed,
        "start_steps": start_steps,
        "n_envs": env.num_envs,
        "vec_env": plan.settings["vec_env"],
        "workers": len(getattr(env.unwrapped, "processes", [])),
        "torch_threads": torch.get_num_threads(),
    }
    write_json(run_dir / SUMMARY_FILE, _summary(plan, [*segments, segment], start_steps))
    print(f"run folder: {run_dir}")
    return run_dir, segment


def _callbacks(
    plan: Plan,
    model: Any,
    run_dir: Path,
    first: Sequence[Any],
    config_callbacks: list[Any] | None,
    extra_callbacks: Sequence[Any],
) -> list[Any]:
    """``first`` (timing and safe stop), rollout checkpoints into ``run_dir``, the recipe's
    callbacks (or the reward terms' logger) and ``extra_callbacks``, in that order."""
    from acl_env.training.callbacks import InfoTermsCallback, RolloutCheckpointCallback

    def save_checkpoint(steps: int) -> None:
        (run_dir / CHECKPOINT_DIR).mkdir(exist_ok=True)
        save_model(model, *checkpoint_paths(run_dir, steps))

    return [
        *first,
        RolloutCheckpointCallback(int(plan.settings["checkpoint_freq"]), save_checkpoint),
        *(config_callbacks or [InfoTermsCallback()]),
        *extra_callbacks,
    ]


@dataclass
class _Learned:
    """How ``model.learn`` went: the error it raised (raised again after the save) or the output
    failure that ended it (the work is saved all the same), its wall time and CPU seconds."""

    error: BaseException | None
    output_error: BaseException | None
    learn_s: float
    cpu_s: dict[str, float]


def _learn(model: Any, env: Any, plan: Plan, callbacks: list[Any]) -> _Learned:
    """Learn the segment's steps with ``callbacks``; an exception is recorded, not raised."""
    from stable_baselines3.common.callbacks import CallbackList

    start, cpu_start = time.perf_counter(), time.process_time()
    workers_cpu_start = workers_cpu_seconds(env)
    error: BaseException | None = None
    output_error: BaseException | None = None
    try:
        model.learn(
            total_timesteps=plan.segment_steps,
            callback=CallbackList(callbacks),
            tb_log_name="PPO",
            reset_num_timesteps=plan.resume_model is None,
            progress_bar=plan.progress_bar,
        )
    except BaseException as exc:  # recorded; an error is raised again after the save
        if is_output_failure(exc):
            output_error = exc  # a writer gave up on a closed output: save all the same
        else:
            error = exc
    learn_s = time.perf_counter() - start
    cpu_s = {
        "trainer": time.process_time() - cpu_start,
        "workers": workers_cpu_seconds(env) - workers_cpu_start,
    }
    return _Learned(error, output_error, learn_s, cpu_s)


def _interruption(stop: SafeStopCallback, learned: _Learned) -> tuple[bool, int]:
    """Whether a signal or a lost output cut the segment short and, if so, the untrained rollout
    steps rolled back (:meth:`SafeStopCallback.rollback`)."""
    signalled = stop.stop_signal is not None and stop.stopped_early
    # An output failure that escaped the guards left learn() in or just after a rollout.
    cut = learned.output_error is not None and not stop.training_ended
    interrupted = learned.error is None and (signalled or cut)
    # An error may have cut a gradient update: then only the checkpoints stand.
    discarded = stop.rollback() if interrupted else 0
    return interrupted, discarded


def _time_split(
    timer: Timed,
    timing: TimingCallback,
    model: Any,
    env: Any,
    learned: _Learned,
    setup_s: float,
    save_s: float,
) -> dict[str, Any]:
    """Where the segment's seconds went (``summary.json``'s ``time_s``)."""
    seconds = timer.seconds
    worker_s = None  # after an error a worker may be dead or hold a pending reply
    if learned.error is None:
        worker_s = float(sum(env.get_attr("step_seconds")))
    update_s = model.update_seconds
    rollout_other = timing.rollout_s - seconds["env_step"] - seconds["policy_inference"]
    return {
        "env_step": seconds["env_step"],
        "env_compute_all_envs": worker_s,
        "policy_inference": seconds["policy_inference"],
        "rollout_other": rollout_other,
        "gradient_update": update_s,
        "other": learned.learn_s - timing.rollout_s - update_s,
        "setup": setup_s,
        "cpu_trainer": learned.cpu_s["trainer"],
        "cpu_workers": learned.cpu_s["workers"],
        "final_save": save_s,
    }


def _complete_segment(
    segment: dict[str, Any],
    learned: _Learned,
    steps: tuple[int, int],
    interruption: tuple[bool, int],
    stop_signal: int | None,
    time_s: dict[str, Any],
    output: GuardedOutput,
) -> None:
    """Complete the segment's entry: its status, ``steps`` (done, and the count it ended at),
    speed, interruption (whether, and the rollout steps discarded), seconds, error and the output
    that was lost."""
    error, learn_s = learned.error, learned.learn_s
    (done, end_steps), (interrupted, discarded) = steps, interruption
    segment.update(
        status="failed" if error else "interrupted" if interrupted else "completed",
        end_steps=end_steps,
        steps=done,
        wall_time_s=learn_s,
        env_steps_per_s=done / learn_s if learn_s > 0 else 0.0,
        interrupted=interrupted,
        signal=signal.Signals(stop_signal).name if stop_signal else None,
        discarded_rollout_steps=discarded,
        time_s=time_s,
    )
    if error is not None:
        segment["error"] = f"{type(error).__name__}: {error}"
    lost, output_error = output.lost, learned.output_error
    if output_error is not None:
        lost.setdefault("output", f"{type(output_error).__name__}: {output_error}")
    if lost:
        segment["output_lost"] = lost  # from then on that output went to os.devnull


def _run_segment(
    plan: Plan,
    extra_callbacks: Sequence[Any],
    verbose: int,
    restore_signals: bool,
    output: GuardedOutput,
) -> Path:
    """:func:`run_segment` under guarded output."""
    from acl_env.training.callbacks import SafeStopCallback, TimingCallback

    ppo_class = _timed_ppo()  # SB3 and torch imported before the setup is timed
    setup_start = time.perf_counter()
    timer = Timed()
    env, model, config_callbacks = _build_model(plan, ppo_class, timer, verbose)
    stop, timing = SafeStopCallback(), TimingCallback()
    start_steps = model.num_timesteps
    segments = _previous_segments(plan.history)
    with deferred_signals(stop.request_stop, restore=restore_signals):
        try:  # whatever happens, the workers are closed before this process may exit
            run_dir, segment = _open_segment(plan, model, env, segments, start_steps)
            callbacks = _callbacks(
                plan, model, run_dir, [timing, stop], config_callbacks, extra_callbacks
            )
            setup_s = time.perf_counter() - setup_start
            learned = _learn(model, env, plan, callbacks)
            interrupted, discarded = _interruption(stop, learned)
            save_start = time.perf_counter()
            if learned.error is None:
                save_model(model, run_dir / MODEL_FILE, run_dir / VECNORMALIZE_FILE)
            save_s = time.perf_counter() - save_start
            steps = model.num_timesteps - start_steps
            time_s = _time_split(timer, timing, model, env, learned, setup_s, save_s)
            _complete_segment(
                segment,
                learned,
                (steps, model.num_timesteps),
                (interrupted, discarded),
                stop.stop_signal,
                time_s,
                output,
            )
            write_json(
                run_dir / SUMMARY_FILE, _summary(plan, [*segments, segment], model.num_timesteps)
            )
        finally:
            _close(env)
    if learned.error is not None:
        raise learned.error
    print(
        f"{steps} env steps in {learned.learn_s:.1f} s: "
        f"{segment['env_steps_per_s']:.0f} env steps/s"
        + (f" (interrupted; {discarded} untrained rollout steps discarded)" if interrupted else "")
    )
    print(f"saved {run_dir / MODEL_FILE} at {model.num_timesteps} steps")
    return run_dir


def _close(env: Any) -> None:
    """Close the envs and their workers; a step reply still pending is not worth reading."""
    if hasattr(env.unwrapped, "waiting"):
        env.unwrapped.waiting = False
    env.close()


def _record_args(run_dir: Path, plan: Plan) -> None:
    """``args.json``: the first segment's command line and settings; resumes under ``resumes``."""
    entry = {
        "argv": plan.argv,
        "args": plan.args,
        "settings": plan.settings,
        "time": time.strftime("%Y-%m-%d %H:%M:%S"),
    }
    path = run_dir / ARGS_FILE
    if plan.segment > 0 and path.is_file():
        record = read_json(path)
        record.setdefault("resumes", []).append(entry)
    else:
        record = entry
    write_json(path, record)


def train(argv: Sequence[str] | None = None, restore_signals: bool = True) -> Path:
    """Check the command line, then train; return the run folder. A refused command line exits
    with status 2 and a one-line message, before any work."""
    argv = list(sys.argv[1:] if argv is None else argv)
    with guarded_output():  # a closed stdout (``| true``) fails no write
        parser = make_parser()
        args = parser.parse_args(argv)
        try:
            plan = plan_segment(args, argv)
        except (ConfigError, argparse.ArgumentTypeError) as error:
            parser.error(str(error))
        return run_segment(plan, restore_signals=restore_signals)


def main(argv: Sequence[str] | None = None) -> None:
    """Train from the command line (``acl-train``); signals after the save are ignored."""
    train(argv, restore_signals=False)


# The console script (pyproject.toml) and ``python -m acl_env.training.trainer``.
run = console_script(main)

if __name__ == "__main__":
    run()
