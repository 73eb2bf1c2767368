"""Evaluation: the protocol (roll out, measure, summarise), the baselines each task is judged
against, the records, running and the ``acl-evaluate`` command line.

- :mod:`acl_env.evaluation.protocol`: :func:`run_episode` and the metrics (:data:`METRICS`);
  :mod:`~acl_env.evaluation.contacts` (where the snake touches the pole),
  :mod:`~acl_env.evaluation.intervals` (95 % intervals), :mod:`~acl_env.evaluation.summary`
  (over episodes, paired differences), :mod:`~acl_env.evaluation.tables` (text tables) and
  :mod:`~acl_env.evaluation.open_loop` (the open-loop controllers); numpy and Gymnasium only.
  Their names are re-exported here, so that ``from acl_env.evaluation import run_episode`` works
  as it always has;
- :mod:`acl_env.evaluation.baselines`: the controllers and, per task, what it is judged against;
- :mod:`acl_env.evaluation.records`: the one reader and writer of ``acl-evaluate --json`` records;
- :mod:`acl_env.evaluation.runner`: running controllers in worker processes;
- :mod:`acl_env.evaluation.figures` and :mod:`acl_env.evaluation.cli`: plots, videos, the command;
- :mod:`acl_env.evaluation.compare`: ``acl-compare``, two evaluation records paired seed by seed;
- :mod:`acl_env.evaluation.export`: an SB3 policy folder exported as a pickle-free pretrained one
  (needs the ``train`` extra).

Nothing here but the exporter imports PyTorch, Stable-Baselines3 or PyYAML at import time: a
policy folder is loaded (:mod:`acl_env.training.policy`) only when a controller plays one.
"""

from acl_env.evaluation.contacts import ARC_BINS, PoleContacts, arc_bins, covering_arc_deg
from acl_env.evaluation.intervals import CI_NOTE, mean_ci95, student_t_quantile
from acl_env.evaluation.open_loop import cadence_action, constant_cadence_policy, zero_policy
from acl_env.evaluation.protocol import (
    METRICS,
    Episode,
    Policy,
    StepCallback,
    action_recorder,
    run_episode,
    steps_per_cycle,
)
from acl_env.evaluation.records import (
    controller_env,
    controller_metric,
    controller_names,
    controller_summary,
    make_record,
    metric_mean,
    metric_values,
    read_record,
    write_record,
)
from acl_env.evaluation.summary import PAIRED_METRICS, paired_differences, summarize
from acl_env.evaluation.tables import TABLE_ROWS, format_paired, format_table
from acl_env.io import jsonable

__all__ = [
    "ARC_BINS",
    "CI_NOTE",
    "METRICS",
    "PAIRED_METRICS",
    "TABLE_ROWS",
    "Episode",
    "PoleContacts",
    "Policy",
    "StepCallback",
    "action_recorder",
    "arc_bins",
    "cadence_action",
    "constant_cadence_policy",
    "controller_env",
    "controller_metric",
    "controller_names",
    "controller_summary",
    "covering_arc_deg",
    "format_paired",
    "format_table",
    "jsonable",
    "make_record",
    "mean_ci95",
    "metric_mean",
    "metric_values",
    "paired_differences",
    "read_record",
    "run_episode",
    "steps_per_cycle",
    "student_t_quantile",
    "summarize",
    "write_record",
    "zero_policy",
]
