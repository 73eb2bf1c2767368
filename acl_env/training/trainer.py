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

Here the segment runs; the command line is :mod:`~acl_env.training.arguments`, its checks
:mod:`~acl_env.training.plan`, the envs and the model :mod:`~acl_env.training.model_setup`, and
the records of ``args.json`` and ``summary.json`` :mod:`~acl_env.training.segments`.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from acl_env.io import GuardedOutput, console_script, guarded_output, write_json
from acl_env.training.arguments import make_parser
from acl_env.training.checks import ConfigError
from acl_env.training.model_setup import build_model, close_envs, timed_ppo
from acl_env.training.plan import Plan, plan_segment
from acl_env.training.runs import (
    CHECKPOINT_DIR,
    MODEL_FILE,
    SUMMARY_FILE,
    VECNORMALIZE_FILE,
    checkpoint_paths,
    save_model,
)
from acl_env.training.segments import (
    Learned,
    complete_segment,
    open_segment,
    previous_segments,
    run_summary,
    time_split,
)
from acl_env.training.signals import deferred_signals, is_output_failure
from acl_env.training.timing import Timed, workers_cpu_seconds

if TYPE_CHECKING:  # SB3 is imported when a segment runs
    from acl_env.training.callbacks import SafeStopCallback


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


def _run_segment(
    plan: Plan,
    extra_callbacks: Sequence[Any],
    verbose: int,
    restore_signals: bool,
    output: GuardedOutput,
) -> Path:
    """:func:`run_segment` under guarded output."""
    from acl_env.training.callbacks import SafeStopCallback, TimingCallback

    ppo_class = timed_ppo()  # SB3 and torch imported before the setup is timed
    setup_start = time.perf_counter()
    timer = Timed()
    env, model, config_callbacks = build_model(plan, ppo_class, timer, verbose)
    stop, timing = SafeStopCallback(), TimingCallback()
    start_steps = model.num_timesteps
    segments = previous_segments(plan.history)
    with deferred_signals(stop.request_stop, restore=restore_signals):
        try:  # whatever happens, the workers are closed before this process may exit
            run_dir, segment = open_segment(plan, model, env, segments, start_steps)
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
            time_s = time_split(timer, timing, model, env, learned, setup_s, save_s)
            complete_segment(
                segment,
                learned,
                (steps, model.num_timesteps),
                (interrupted, discarded),
                stop.stop_signal,
                time_s,
                output,
            )
            write_json(
                run_dir / SUMMARY_FILE, run_summary(plan, [*segments, segment], model.num_timesteps)
            )
        finally:
            close_envs(env)
    if learned.error is not None:
        raise learned.error
    print(
        f"{steps} env steps in {learned.learn_s:.1f} s: "
        f"{segment['env_steps_per_s']:.0f} env steps/s"
        + (f" (interrupted; {discarded} untrained rollout steps discarded)" if interrupted else "")
    )
    print(f"saved {run_dir / MODEL_FILE} at {model.num_timesteps} steps")
    return run_dir


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


def _learn(model: Any, env: Any, plan: Plan, callbacks: list[Any]) -> Learned:
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
    return Learned(error, output_error, learn_s, cpu_s)


def _interruption(stop: SafeStopCallback, learned: Learned) -> tuple[bool, int]:
    """Whether a signal or a lost output cut the segment short and, if so, the untrained rollout
    steps rolled back (:meth:`SafeStopCallback.rollback`)."""
    signalled = stop.stop_signal is not None and stop.stopped_early
    # An output failure that escaped the guards left learn() in or just after a rollout.
    cut = learned.output_error is not None and not stop.training_ended
    interrupted = learned.error is None and (signalled or cut)
    # An error may have cut a gradient update: then only the checkpoints stand.
    discarded = stop.rollback() if interrupted else 0
    return interrupted, discarded


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
