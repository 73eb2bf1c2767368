"""Play policies and every analytic controller of their task on every cell of the task's
condition grid, on the same seeds, and record per cell and controller what each achieved.

Per cell the controllers are those :func:`acl_env.evaluation.baselines.build_controllers` judges
the first policy against, with the cell's conditions as overrides, and each policy given (the
training seeds of one recipe). The open loops at the policy's cadence run at the policies' mean
cadence in that cell. The record is rewritten after every cell, so an interrupted run resumes
where it stopped (:func:`run_benchmark` with the same settings and record path).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from pathlib import Path
from typing import Any

import numpy as np

from acl_env.benchmark.grid import Cell, Grid
from acl_env.evaluation.baselines import AT_POLICY_CADENCE, DEFAULT_TUNED_GAITS, build_controllers
from acl_env.evaluation.protocol import Episode
from acl_env.evaluation.runner import evaluate, policies_controllers
from acl_env.evaluation.tasks import OBSERVATION_ONLY_KWARGS, shown_path
from acl_env.io import jsonable, read_json, write_json

FORMAT = "acl_env.benchmark/1"
# Per episode and controller; success is neither a fall nor a net descent.
METRICS = ("climb_per_gait_cycle_m", "slip_per_m", "energy_per_m", "touched_arc_deg")


def success(episode: Episode) -> bool:
    """The episode held the pole and climbed: no fall, and a positive climb."""
    return not episode.fell and episode.climb > 0.0


def cell_result(episodes: Sequence[Episode]) -> dict[str, Any]:
    """What one controller achieved in one cell: success rate and falls, and per metric the
    mean over the episodes where it is defined and the per-episode values (seed order)."""
    per_episode = [e.metrics() for e in episodes]
    result: dict[str, Any] = {
        "episodes": len(episodes),
        "success_rate": float(np.mean([success(e) for e in episodes])),
        "falls": int(sum(e.fell for e in episodes)),
        "mean_phase_rate": float(
            sum(e.keyframes for e in episodes) / max(1, sum(e.steps for e in episodes))
        ),
    }
    for metric in METRICS:
        values = [m[metric] for m in per_episode]
        finite = [v for v in values if math.isfinite(v)]
        result[metric] = {
            "mean": float(np.mean(finite)) if finite else math.nan,
            "values": values,
        }
    return result


class SettingsMismatch(ValueError):
    """A record to resume that was made with other settings."""


def run_cell(
    policies: Sequence[Path],
    cell_kwargs: dict[str, Any],
    seeds: Sequence[int],
    pool: Executor | None,
    tuned_path: Path = DEFAULT_TUNED_GAITS,
    known: dict[str, dict[str, Any]] | None = None,
) -> tuple[dict[str, dict[str, Any]], dict[str, str]]:
    """Every controller of one cell on ``seeds``: ``{controller: cell_result}``, and each
    controller's label (what it is, in the reader's words). Those in ``known`` (their results
    in this cell, from another record: :func:`reusable`) are taken from it, not played."""
    known = known or {}
    controllers, _ = policies_controllers(policies, cell_kwargs, tuned_path)
    playing = [c for c in controllers if c.name not in known]
    results = evaluate(playing, seeds, workers=1, pool=pool, progress=False)
    labels = {c.name: c.title for c in controllers}
    return {
        c.name: known[c.name] if c.name in known else cell_result(results[c.name])
        for c in controllers
    }, labels


def reusable(wanted: dict[str, Any], other: dict[str, Any]) -> list[str]:
    """The analytic controllers whose results ``other`` (a record) holds as a run with settings
    ``wanted`` would play them: the same seeds and fixed conditions, and the same env and
    keyword arguments, whichever task's record it is (a controller is its env and arguments;
    those that only add observations aside).
    Not those at the policies' cadence, which is the policies' own. Episodes are deterministic
    in their seed, so a cell of ``other`` with the same conditions is what playing them again
    would give."""
    theirs = other.get("settings", {})
    if other.get("format") != FORMAT or any(
        theirs.get(key) != wanted[key] for key in ("seeds", "fixed")
    ):
        return []
    return [
        name
        for name, spec in wanted["controllers"].items()
        if name not in AT_POLICY_CADENCE
        and _plays(theirs.get("controllers", {}).get(name)) == _plays(spec)
    ]


def _plays(spec: dict[str, Any] | None) -> dict[str, Any] | None:
    """What an analytic controller's results depend on: its record's entry less the env kwargs
    that only add observations, which an open loop does not read."""
    if spec is None:
        return None
    kwargs = {k: v for k, v in spec["env_kwargs"].items() if k not in OBSERVATION_ONLY_KWARGS}
    return {**spec, "env_kwargs": kwargs}


def controller_table(policies: Sequence[Path], tuned_path: Path) -> dict[str, dict[str, Any]]:
    """What each analytic controller is at the task's defaults: the env it plays, its keyword
    arguments, and an open loop's cadence (the policy's in a cell, for those at its cadence)."""
    if policies:
        controllers, _ = policies_controllers(policies, {}, tuned_path)
    else:
        controllers, _ = build_controllers(None, {}, None, tuned_path)
    return {
        c.name: {"env_id": c.env_id, "env_kwargs": c.env_kwargs, "phase_rate": c.phase_rate}
        for c in controllers
        if c.policy_dir is None
    }


def settings(
    task: str, policies: Sequence[Path], grid: Grid, seeds: Sequence[int], tuned_path: Path
) -> dict[str, Any]:
    """What a record was made with, as its JSON reads back: a resumed run must match it, its
    analytic controllers included (code that plays other gaits does not resume its record)."""
    return jsonable(
        {
            "task": task,
            "policies": [shown_path(p) for p in policies],
            "seeds": list(seeds),
            "tuned_gaits": shown_path(tuned_path),
            "axes": {
                a.name: {"values": list(a.values), "nominal": a.nominal, "training": a.training}
                for a in grid.axes
            },
            "fixed": dict(grid.fixed),
            # only where there are events: the records of grids without them read as before
            **({"events": [dict(c.kwargs) for c in grid.events]} if grid.events else {}),
            **({"cells": list(grid.only)} if grid.only else {}),  # a selection: its cells
            "controllers": controller_table(policies, tuned_path),
        }
    )


def run_benchmark(
    task: str,
    policies: Sequence[Path],
    grid: Grid,
    seeds: Sequence[int],
    record_path: Path,
    pool: Executor | None = None,
    tuned_path: Path = DEFAULT_TUNED_GAITS,
    on_cell: Callable[[Cell], None] | None = None,
    remake: bool = False,
    reuse: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Play every cell of ``grid`` not yet in the record at ``record_path`` (one made with the
    same :func:`settings`; one made with others is :class:`SettingsMismatch`, or with ``remake``
    made again from the start), writing it after each cell; return it. ``on_cell`` is called
    after each cell (a progress bar). ``reuse``: a record whose :func:`reusable` controllers are
    taken from its cells of the same conditions instead of played."""
    wanted = settings(task, policies, grid, seeds, tuned_path)
    names = reusable(wanted, reuse) if reuse is not None else []
    record: dict[str, Any] = {"format": FORMAT, "settings": wanted, "labels": {}, "cells": {}}
    if record_path.is_file():
        previous = read_json(record_path)
        if previous.get("format") == FORMAT and previous.get("settings") == wanted:
            record = previous
        elif not remake:
            raise SettingsMismatch(
                f"{record_path} was made with other settings (task, policies, seeds, grid, tuned "
                "gaits or analytic controllers): give another --json path, or remove it to start "
                "again (--remake)"
            )
    for cell in grid.cells():
        if cell.key not in record["cells"]:
            theirs = (reuse or {}).get("cells", {}).get(cell.key)
            known = {}
            if theirs is not None and theirs["kwargs"] == cell.kwargs:
                known = {name: theirs["controllers"][name] for name in names}
            controllers, labels = run_cell(
                policies, grid.env_kwargs(cell), seeds, pool, tuned_path, known
            )
            record["labels"].update(labels)
            record["cells"][cell.key] = {
                "kwargs": cell.kwargs,
                "held_out": cell.held_out,
                "controllers": controllers,
                **({"reused": list(known)} if known else {}),  # taken from another record
            }
            write_json(record_path, record)
        if on_cell is not None:
            on_cell(cell)
    return record
