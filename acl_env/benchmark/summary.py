"""What a benchmark record says over its cells and training seeds: each controller's grid-wide
figures, the policies' interquartile mean and bootstrap interval over seeds, and their
probability of improvement over the best analytic controller of each cell."""

from __future__ import annotations

from typing import Any

import numpy as np

from acl_env.evaluation.baselines import POLICY_PREFIX
from acl_env.evaluation.statistics import bootstrap_interval, iqm, mean_probability_of_improvement

# Each score and whether more is better.
SCORES = {
    "success_rate": True,
    "climb_per_gait_cycle_m": True,
    "slip_per_m": False,
    "energy_per_m": False,
}


def cell_matrix(record: dict[str, Any], controller: str, score: str, cells: list[str]) -> list:
    """``controller``'s ``score`` in each of ``cells`` (NaN where it is undefined)."""
    values = []
    for key in cells:
        result = record["cells"][key]["controllers"][controller]
        value = result[score] if score == "success_rate" else result[score]["mean"]
        values.append(np.nan if value is None else float(value))
    return values


def controllers_of(record: dict[str, Any]) -> tuple[list[str], list[str]]:
    """The record's policies (``policy:<name>``) and analytic controllers, in record order."""
    first = next(iter(record["cells"].values()))["controllers"]
    policies = [n for n in first if n.startswith(POLICY_PREFIX)]
    return policies, [n for n in first if not n.startswith(POLICY_PREFIX)]


def summarize_benchmark(record: dict[str, Any], held_out_only: bool = False) -> dict[str, Any]:
    """Per score, over the cells where every controller's value is defined: each analytic
    controller's mean; the policies' grid means, their IQM over seeds with its bootstrap 95 %
    interval; the best analytic controller per cell, and the probability that a policy seed
    beats it, averaged over cells, with its interval. ``held_out_only``: only the cells outside
    the training ranges."""
    cells = [k for k, c in record["cells"].items() if c["held_out"] or not held_out_only]
    policies, analytic = controllers_of(record)
    out: dict[str, Any] = {"cells": len(cells), "policies": policies, "scores": {}}
    for score, higher in SCORES.items():
        table = {name: np.array(cell_matrix(record, name, score, cells)) for name in analytic}
        matrix = np.array([cell_matrix(record, p, score, cells) for p in policies])
        # Slip and energy per metre are undefined where a controller did not climb: every mean
        # is over the cells where every controller's is defined, so that none looks better for
        # the cells it failed in (success rates are defined everywhere).
        stacked = np.array([*table.values(), *matrix])
        common = np.all(np.isfinite(stacked), axis=0)
        entry: dict[str, Any] = {
            "cells": int(common.sum()),
            "analytic": {name: float(np.mean(v[common])) for name, v in table.items()},
        }
        if policies:
            analytic_table = np.array(list(table.values()))
            best = analytic_table.max(0) if higher else analytic_table.min(0)
            usable = common
            grid_means = matrix[:, common].mean(axis=1)
            low, high = bootstrap_interval(grid_means)
            entry["policies"] = {
                "per_seed": dict(zip(policies, grid_means.tolist(), strict=True)),
                "iqm": float(iqm(grid_means)),
                "ci95": [low, high],
            }
            entry["best_analytic_mean"] = float(np.mean(best[common]))
            entry["probability_of_improvement"] = {
                **mean_probability_of_improvement(matrix[:, usable], best[usable], higher),
                "cells": int(usable.sum()),
            }
        out["scores"][score] = entry
    return out


# A cell is held in "most episodes" below this share of falls, and "reliably" at this success.
MOSTLY = 0.5
RELIABLE = 0.95


def limits(record: dict[str, Any]) -> dict[str, Any]:
    """Where each policy's limits lie against the analytic controllers, cell by cell (every
    controller on the same seeds): the cells where it falls more often than the analytic
    controller that falls least; over the held-out cells where some analytic controller
    succeeds reliably (:data:`RELIABLE`), those where the policy does too; and over the cells
    where every analytic controller falls in most episodes, those where the policy succeeds in
    at least half (:data:`MOSTLY`)."""
    policies, analytic = controllers_of(record)
    out: dict[str, Any] = {}
    for policy in policies:
        falls_more, reliable, reliable_held, hard, hard_held = [], [], [], [], []
        for key, cell in record["cells"].items():
            results = cell["controllers"]
            mine = results[policy]
            if mine["falls"] > min(results[name]["falls"] for name in analytic):
                falls_more.append(key)
            best = max(results[name]["success_rate"] for name in analytic)
            if cell["held_out"] and best >= RELIABLE:
                reliable.append(key)
                if mine["success_rate"] >= RELIABLE:
                    reliable_held.append(key)
            if all(results[n]["falls"] > MOSTLY * results[n]["episodes"] for n in analytic):
                hard.append(key)
                if mine["success_rate"] >= MOSTLY:
                    hard_held.append(key)
        out[policy] = {
            "cells_falling_more_than_best_analytic": falls_more,
            "held_out_reliable_cells": len(reliable),
            "held_out_reliable_cells_held": len(reliable_held),
            "cells_every_analytic_loses": hard,
            "cells_every_analytic_loses_held": hard_held,
        }
    return out


def ratios_where_held(
    record: dict[str, Any], policies: list[str], controller: str, scores: tuple[str, ...]
) -> dict[str, Any]:
    """Per score, the median over cells of the policies' mean over ``controller``'s cell mean,
    and in how many cells it is above 1, over the cells where neither a policy nor ``controller``
    falls in any episode (a fall's climb is negative: no ratio)."""
    held = [
        cell["controllers"]
        for cell in record["cells"].values()
        if all(cell["controllers"][name]["falls"] == 0 for name in [*policies, controller])
    ]
    out: dict[str, Any] = {}
    for score in scores:
        values = [
            np.mean([results[p][score]["mean"] for p in policies])
            / results[controller][score]["mean"]
            for results in held
            if all(results[name][score]["mean"] is not None for name in [*policies, controller])
        ]
        out[score] = {
            "median": float(np.median(values)),
            "higher": int(sum(v > 1.0 for v in values)),
            "cells": len(values),
        }
    return out
