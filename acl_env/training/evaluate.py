"""Deprecated: evaluation lives in :mod:`acl_env.evaluation` (``baselines``, ``runner``,
``figures``, ``records``, ``cli``). This module re-exports what it held, with a warning."""

from __future__ import annotations

import os

# --video renders offscreen; MuJoCo picks its GL backend when first imported, so say it now.
os.environ.setdefault("MUJOCO_GL", "egl")

import warnings

from acl_env.evaluation.baselines import (
    AT_POLICY_CADENCE,
    DEFAULT_POLICY,
    DEFAULT_TUNED_GAITS,
    GAIT_KWARGS,
    POLICY_ACTION_KWARGS,
    POLICY_GAIT,
    SAME_CADENCE,
    TASKS,
    TRAINING_ONLY_KWARGS,
    TUNED_KEYS,
    TUNED_SAME_CADENCE,
    Controller,
    TunedGaitsError,
    build_controllers,
    default_tuned_key,
    env_setting,
    evaluation_env_kwargs,
    is_non_rolling,
    shown_path,
    tuned_gait,
)
from acl_env.evaluation.cli import main, make_parser, run
from acl_env.evaluation.figures import plot_heights, record_video
from acl_env.evaluation.protocol import (
    CI_NOTE,
    Episode,
    Policy,
    constant_cadence_policy,
    format_paired,
    format_table,
    mean_ci95,
    paired_differences,
    run_episode,
    summarize,
    zero_policy,
)
from acl_env.evaluation.runner import evaluate, make_pool, run_controllers

warnings.warn(
    "acl_env.training.evaluate is deprecated: import from acl_env.evaluation "
    "(baselines, runner, figures, records, cli)",
    DeprecationWarning,
    stacklevel=2,
)

# Non-rolling tasks whose tuned entry is not the default non-rolling one (now TASKS' data).
TUNED_KEYS_BY_ENV = {
    env_id: task.tuned_key
    for env_id, task in TASKS.items()
    if task.non_rolling and task.tuned_key != TUNED_KEYS[True]
}

__all__ = [
    "AT_POLICY_CADENCE",
    "CI_NOTE",
    "DEFAULT_POLICY",
    "DEFAULT_TUNED_GAITS",
    "GAIT_KWARGS",
    "POLICY_ACTION_KWARGS",
    "POLICY_GAIT",
    "SAME_CADENCE",
    "TRAINING_ONLY_KWARGS",
    "TUNED_KEYS",
    "TUNED_KEYS_BY_ENV",
    "TUNED_SAME_CADENCE",
    "Controller",
    "Episode",
    "Policy",
    "TunedGaitsError",
    "build_controllers",
    "constant_cadence_policy",
    "default_tuned_key",
    "env_setting",
    "evaluate",
    "evaluation_env_kwargs",
    "format_paired",
    "format_table",
    "is_non_rolling",
    "main",
    "make_parser",
    "make_pool",
    "mean_ci95",
    "paired_differences",
    "plot_heights",
    "record_video",
    "run",
    "run_controllers",
    "run_episode",
    "shown_path",
    "summarize",
    "tuned_gait",
    "zero_policy",
]

if __name__ == "__main__":  # python -m acl_env.training.evaluate, as before
    run()
