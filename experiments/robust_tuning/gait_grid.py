"""Tuned SEA gaits against the paper's gait, open loop at the same cadence (one keyframe per
step), on every cell of the robust task's condition grid, on the same seeds.

``python experiments/robust_tuning/gait_grid.py [--keys acl_sea_robust ...] [--tuned-gaits PATH]
[--episodes 10] [--workers 2] [--json PATH] [--plot PATH]``

Each gait is an entry of the tuned gaits (``--tuned-gaits``, default the shipped file), played as
the evaluation's ``open_loop_tuned`` controller with that entry; the paper's gait is the
evaluation's ``open_loop_acl``. Per cell and gait the record holds the falls, each metric over the
episodes, and the gait's climb per gait cycle minus the paper's, seed by seed, with its 95 %
interval. The record is written after every cell: run the same command again to go on.
"""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path
from typing import Any

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np
from tqdm import tqdm

from acl_env.benchmark.grid import ROBUST_SEA_GRID
from acl_env.evaluation.baselines import DEFAULT_TUNED_GAITS, Controller, build_controllers
from acl_env.evaluation.runner import make_pool, run_controllers
from acl_env.evaluation.summary import paired_differences, summarize
from acl_env.evaluation.tasks import shown_path
from acl_env.io import console_script, read_json, write_json
from acl_env.scripts import make_parser, seeds, use_agg
from acl_env.shipped import policy_dir
from acl_env.training.policy import read_policy_folder

PAPER = "open_loop_acl"
CLIMB = "climb_per_gait_cycle_m"


def controllers_for(
    condition: dict[str, Any],
    keys: list[str],
    tuned: Path = DEFAULT_TUNED_GAITS,
    grips: bool = False,
) -> list[Controller]:
    """The paper's gait and each tuned entry of ``keys`` (named by its key), open loop under
    ``condition``; with ``grips`` each entry's compliant controller too (``<key>_grip``)."""
    folder = read_policy_folder(policy_dir("acl_climb_sea_ppo"))  # the SEA task's setting
    chosen: list[Controller] = []
    for key in keys:
        built, _ = build_controllers(folder, dict(condition), None, tuned, key)
        by_name = {c.name: c for c in built}
        if not chosen:
            chosen.append(by_name[PAPER])
        chosen.append(replace(by_name["open_loop_tuned"], name=key))
        if grips:
            chosen.append(replace(by_name["compliant_acl"], name=f"{key}_grip"))
    return chosen


def cell_record(episodes: dict[str, list[Any]]) -> dict[str, Any]:
    """Each controller's falls and mean metrics, and each gait's climb minus the paper's."""
    summaries = {name: summarize(eps) for name, eps in episodes.items()}
    out: dict[str, Any] = {}
    for name, summary in summaries.items():
        out[name] = {
            "falls": summary["falls"]["count"],
            **{m: summary[m]["mean"] for m in (CLIMB, "slip_per_m", "energy_per_m")},
            "climb_values": summary[CLIMB]["values"],
        }
        if name != PAPER:
            paired = paired_differences(
                {name: summary, PAPER: summaries[PAPER]}, reference=name, metrics=(CLIMB,)
            )
            out[name]["climb_minus_paper"] = paired[PAPER][CLIMB]
    return out


def tally(document: dict[str, Any]) -> dict[str, Any]:
    """Per gait, over the cells: where it falls more often than the paper's gait, where both fall
    in some episode, and over the cells where it held on in every episode, those where it climbs
    at least as far as the paper's gait (mean over seeds), those shorter by the paired interval,
    its worst such cell (the largest shortfall) and the median ratio of the climbs."""
    cells = document["cells"]
    out: dict[str, Any] = {}
    for key in document["keys"]:
        held = {k: c for k, c in cells.items() if not c[key]["falls"]}
        short = {k: c[key]["climb_minus_paper"]["mean"] for k, c in held.items()}
        worst = min(short, key=short.__getitem__)
        ratios = [c[key][CLIMB] / c[PAPER][CLIMB] for c in held.values() if not c[PAPER]["falls"]]
        out[key] = {
            "cells": len(cells),
            "cells_falling_more_than_paper": [
                k for k, c in cells.items() if c[key]["falls"] > c[PAPER]["falls"]
            ],
            "cells_both_fall": [
                k for k, c in cells.items() if c[key]["falls"] and c[PAPER]["falls"]
            ],
            "cells_held": len(held),
            "cells_held_at_least_as_far": sum(v >= 0 for v in short.values()),
            "cells_held_shorter_by_the_interval": [
                k for k, c in held.items() if c[key]["climb_minus_paper"]["ci95"][1] < 0
            ],
            "worst_cell": worst,
            "worst_cell_climb_minus_paper_m": short[worst],
            "median_climb_ratio": float(np.median(ratios)),
            "falls": sum(c[key]["falls"] for c in cells.values()),
            "paper_falls": sum(c[PAPER]["falls"] for c in cells.values()),
        }
    return out


def plot(document: dict[str, Any], path: Path) -> None:
    """Each gait's climb per gait cycle per cell against the paper's, the diagonal marked; a
    cell where either fell in some episode is left out (its count in the legend)."""
    plt = use_agg()
    fig, ax = plt.subplots(figsize=(5.5, 5))
    cells = list(document["cells"].values())
    for key in document["keys"]:
        held = [c for c in cells if not (c[key]["falls"] or c[PAPER]["falls"])]
        ax.scatter(
            [100 * c[PAPER][CLIMB] for c in held],
            [100 * c[key][CLIMB] for c in held],
            s=14,
            label=f"{key} (cells with a fall left out: {len(cells) - len(held)})",
        )
    low, high = min(ax.get_xlim()[0], ax.get_ylim()[0]), max(ax.get_xlim()[1], ax.get_ylim()[1])
    ax.plot([low, high], [low, high], color="grey", lw=0.8, label="as far as the paper's gait")
    ax.set(
        xlabel="paper's gait: climb per gait cycle (cm)",
        ylabel="tuned gait: climb per gait cycle (cm)",
        title="Open loop on the robust grid, same cadence and seeds",
    )
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__, plot=True, seed=0, episodes=10, workers=2, progress=True)
    parser.add_argument("--keys", nargs="+", default=["acl_sea_robust"], help="tuned entries")
    parser.add_argument("--tuned-gaits", type=Path, default=DEFAULT_TUNED_GAITS)
    parser.add_argument("--cells", nargs="+", help="only these cells (default: every cell)")
    args = parser.parse_args(argv)
    played = seeds(args)
    grid = ROBUST_SEA_GRID.select(args.cells) if args.cells else ROBUST_SEA_GRID
    settings = {"keys": args.keys, "seeds": played, "tuned_gaits": shown_path(args.tuned_gaits)}
    document: dict[str, Any] = {**settings, "cells": {}}
    if args.json and Path(args.json).is_file():
        previous = read_json(Path(args.json))
        if all(previous.get(k) == v for k, v in settings.items()):
            document = previous
    pool = make_pool(args.workers)
    try:
        for cell in tqdm(grid.cells(), desc="cells", disable=args.no_progress_bar):
            if cell.key in document["cells"]:
                continue
            controllers = controllers_for(grid.env_kwargs(cell), args.keys, args.tuned_gaits)
            episodes = run_controllers(controllers, played, pool, progress=False)
            document["cells"][cell.key] = {"kwargs": cell.kwargs, **cell_record(episodes)}
            if args.json:
                write_json(Path(args.json), document)
    finally:
        if pool is not None:
            pool.shutdown()
    document["summary"] = tally(document)
    if args.json:
        write_json(Path(args.json), document)
    if args.plot:
        plot(document, Path(args.plot))
    for key, row in document["summary"].items():
        print(f"{key}: {row}")
    return document


if __name__ == "__main__":
    console_script(main)()
