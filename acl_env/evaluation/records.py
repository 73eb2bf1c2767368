"""Evaluation records: the one writer and reader of ``acl-evaluate --json`` documents.

A record is one JSON object::

    {"controllers": {name: summary},   # acl_env.evaluation.summarize, per controller
     "env_ids": {name: env id}, "env_kwargs": {name: env kwargs},
     "policy": "acl_env/data/policies/..." or null, "notes": [...], "ci": CI_NOTE,
     "same_cadence_phase_rate": float,            # when a same-cadence open loop ran
     "paired_vs_policy": {name: {metric: ...}}}   # when a policy ran beside other controllers

where a summary holds, per metric of :data:`~acl_env.evaluation.METRICS`, ``{"mean", "ci95",
"half_width", "n", "values"}`` (NaN written as null), and ``episodes``, ``seeds``,
``mean_phase_rate``, ``unstable``, ``rolled``. Older records may lack a metric; readers take what
is there through the accessors below.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from acl_env.evaluation.intervals import CI_NOTE
from acl_env.evaluation.summary import paired_differences
from acl_env.io import read_json, write_json

REFERENCE = "policy"  # the controller the others are paired against
# What a pretrained policy's policy.json summarises of each controller of its published record.
SUMMARY_METRICS = ("climb_per_gait_cycle_m", "slip_per_m", "energy_per_m", "falls")


def make_record(
    summaries: Mapping[str, dict[str, Any]],
    env_ids: Mapping[str, str],
    env_kwargs: Mapping[str, dict[str, Any]],
    policy: str | None,
    notes: Sequence[str],
    same_cadence_phase_rate: float | None = None,
    labels: Mapping[str, str] | None = None,
) -> dict[str, Any]:
    """The record of one evaluation; ``paired_vs_policy`` is added when a policy ran beside
    other controllers (:func:`~acl_env.evaluation.paired_differences`). ``labels``: what each
    controller is, in the reader's words (the keys stay the controllers' names)."""
    record: dict[str, Any] = {
        "controllers": dict(summaries),
        "labels": dict(labels or {}),
        "env_ids": dict(env_ids),
        "env_kwargs": dict(env_kwargs),
        "policy": policy,
        "notes": list(notes),
        "ci": CI_NOTE,
    }
    if same_cadence_phase_rate is not None:
        record["same_cadence_phase_rate"] = same_cadence_phase_rate
    if REFERENCE in summaries and len(summaries) > 1:
        record["paired_vs_policy"] = paired_differences(dict(summaries), REFERENCE)
    return record


def write_record(path: str | Path, record: Mapping[str, Any]) -> None:
    """Write ``record`` as strict JSON (NaN as null), atomically; ``ValueError`` if it is not
    one (checked as :func:`read_record` checks a file)."""
    check_record(record, str(path))
    write_json(path, dict(record))


def read_record(path: str | Path) -> dict[str, Any]:
    """The record in the JSON file at ``path``; ``ValueError`` naming the file when it cannot be
    read, is not JSON or is not an evaluation record."""
    try:
        record = read_json(path)
    except OSError as error:
        raise ValueError(f"{path}: cannot read it ({error.strerror})") from None
    check_record(record, str(path))
    return record


def check_record(record: Any, source: str = "record") -> None:
    """``ValueError`` naming ``source`` unless ``record`` has the shape of an evaluation record:
    ``controllers`` a mapping of summaries, each metric a mapping with a list of ``values``."""
    controllers = record.get("controllers") if isinstance(record, Mapping) else None
    if not isinstance(controllers, Mapping):
        raise ValueError(f"{source}: no 'controllers' (is it an acl-evaluate --json output?)")
    for name, summary in controllers.items():
        if not isinstance(summary, Mapping):
            raise ValueError(f"{source}: controller {name!r} is not a summary")
        for metric, value in summary.items():
            if isinstance(value, Mapping) and not isinstance(value.get("values", []), list):
                raise ValueError(f"{source}: {name}'s {metric} values are not a list")
    for key in ("env_ids", "env_kwargs", "paired_vs_policy"):
        if not isinstance(record.get(key) or {}, Mapping):
            raise ValueError(f"{source}: {key!r} is not a mapping")
    if not isinstance(record.get("notes") or [], list):
        raise ValueError(f"{source}: 'notes' is not a list")


# --- accessors -----------------------------------------------------------------------------------


def controller_names(record: Mapping[str, Any]) -> list[str]:
    """The controllers of the record, in its order."""
    return list(record["controllers"])


def controller_summary(record: Mapping[str, Any], controller: str) -> dict[str, Any]:
    """The summary of ``controller``; ``ValueError`` naming the controllers there are."""
    controllers = record["controllers"]
    if controller not in controllers:
        raise ValueError(f"no controller {controller!r} (it has {sorted(controllers)})")
    return controllers[controller]


def controller_env(record: Mapping[str, Any], controller: str) -> tuple[str | None, dict[str, Any]]:
    """The env id and env kwargs ``controller`` was played with (None and ``{}`` if unrecorded)."""
    env_id = (record.get("env_ids") or {}).get(controller)
    env_kwargs = (record.get("env_kwargs") or {}).get(controller) or {}
    return env_id, dict(env_kwargs)


def controller_metric(record: Mapping[str, Any], controller: str, metric: str) -> dict[str, Any]:
    """``{"mean", "ci95", "half_width", "n", "values"}`` of one metric of one controller;
    ``KeyError`` naming both when the record lacks it."""
    summary = controller_summary(record, controller)
    if not isinstance(summary.get(metric), Mapping):
        raise KeyError(f"{controller} has no {metric}")
    return summary[metric]


def metric_mean(record: Mapping[str, Any], controller: str, metric: str) -> float:
    """The mean of one metric of one controller; NaN when the record lacks it or it is null."""
    summary = controller_summary(record, controller)
    value = summary.get(metric)
    mean = value.get("mean") if isinstance(value, Mapping) else None
    return math.nan if mean is None else float(mean)


def metric_values(record: Mapping[str, Any], controller: str, metric: str) -> list[float]:
    """The per-episode values of one metric of one controller, in seed order (null as NaN)."""
    values = controller_metric(record, controller, metric).get("values") or []
    return [math.nan if v is None else float(v) for v in values]


def evaluation_summary(record_path: str | Path, shown: str | None = None) -> dict[str, Any]:
    """Per controller of a published evaluation record, the mean and 95 % half-width of
    :data:`SUMMARY_METRICS` (and the number of falls); the record named ``shown``, by default
    as :func:`~acl_env.evaluation.tasks.shown_path` shows it from the working folder."""
    from acl_env.evaluation.tasks import shown_path  # the env stack: imported when needed

    record = read_record(Path(record_path))
    controllers: dict[str, Any] = {}
    episodes = None
    for name, summary in record["controllers"].items():
        entry: dict[str, Any] = {}
        for metric in SUMMARY_METRICS:
            value = summary.get(metric) or {}
            entry[metric] = {"mean": value.get("mean"), "half_width": value.get("half_width")}
            if "count" in value:
                entry[metric]["count"] = value["count"]
        controllers[name] = entry
        episodes = summary.get("episodes", episodes)
    return {
        "record": shown if shown is not None else shown_path(record_path),
        "policy": record.get("policy"),
        "episodes": episodes,
        "interval": "mean and Student-t 95 % half-width over the episodes",
        "controllers": controllers,
    }
