"""``acl-benchmark``: policies and every analytic controller of their task on the task's
condition grid (:mod:`acl_env.benchmark.grid`), on the same seeds, with a record that resumes.

Every argument is checked before the first episode (a bad one: exit 2, one line naming it). The
record is rewritten after each cell: run the same command again to go on after an interruption.
The heat maps (``--plots``) and the summary over training seeds are made from the record.
"""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import argparse
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tqdm import tqdm

from acl_env import cli, current_id, shipped
from acl_env.benchmark.figures import TITLES, plot_heat_maps, plot_profiles
from acl_env.benchmark.grid import Grid, grid_for
from acl_env.benchmark.run import SettingsMismatch, run_benchmark
from acl_env.benchmark.summary import limits, summarize_benchmark
from acl_env.evaluation.baselines import read_policy
from acl_env.evaluation.cli import policy_folder
from acl_env.evaluation.runner import PolicySetError, make_pool
from acl_env.evaluation.statistics import MIN_SEEDS
from acl_env.io import atomic_output, console_script, jsonable, read_json, write_json

DEFAULT_EPISODES = 10


def make_parser() -> cli.ArgumentParser:
    """The command line of ``acl-benchmark``."""
    parser = cli.ArgumentParser(
        prog="acl-benchmark",
        description="Play policies and their task's analytic controllers on the task's "
        "condition grid, on the same seeds.",
    )
    parser.add_argument(
        "--policy",
        nargs="+",
        type=policy_folder,
        default=[shipped.policy_dir()],
        help="shipped policies or exported policy folders of one task, e.g. the training seeds "
        f"of one recipe (default {shipped.DEFAULT_POLICY})",
    )
    cli.add_episodes(
        parser, DEFAULT_EPISODES, f"episodes per cell and controller (default {DEFAULT_EPISODES})"
    )
    cli.add_seed(parser, 0, "episode i resets with seed + i in every cell")
    parser.add_argument(
        "--json",
        type=cli.output_file(".json"),
        required=True,
        help="the record (.json); an unfinished one made with the same settings is resumed",
    )
    parser.add_argument(
        "--plots",
        type=cli.output_file(".png", ".pdf", ".svg"),
        help="figures: FILE's stem + _<score> for each score's heat maps, + _profiles for the "
        "performance profiles",
    )
    parser.add_argument(
        "--cells",
        nargs="+",
        metavar="KEY",
        help="play only these cells, named as the record names them: nominal, friction=0.4, "
        "friction=0.4,pole_radius=0.12, friction_step=0.5 (default: every cell)",
    )
    parser.add_argument(
        "--remake",
        action="store_true",
        help="a record at --json made with other settings (another version's controllers, "
        "grid or policies) is made again from the start, instead of refused",
    )
    parser.add_argument(
        "--reuse",
        type=record_file,
        metavar="RECORD",
        help="an acl-benchmark record on the same seeds (another recipe's, an ablation arm's, "
        "another task's on the same grid): the analytic controllers it played alike (the same "
        "env and arguments, privileged_obs and obs_history aside; not those at the policies' "
        "cadence) are taken from its cells instead of played again; each such cell says so "
        "under 'reused'",
    )
    cli.add_workers(parser, 2, "processes running episodes (default 2)")
    parser.add_argument("--no-progress-bar", action="store_true")
    return parser


def record_file(text: str) -> dict[str, Any]:
    """An existing record's contents (``--reuse``)."""
    try:
        return read_json(Path(text))
    except (OSError, ValueError) as error:
        raise argparse.ArgumentTypeError(f"cannot read {text} as a record: {error}") from None


def plot_paths(plots: Path) -> dict[str, Path]:
    """The heat maps' files: ``plots``'s stem with each score's name appended."""
    return {score: plots.with_name(f"{plots.stem}_{score}{plots.suffix}") for score in TITLES}


def main(argv: Sequence[str] | None = None) -> dict[str, Any]:
    """Run (or resume) the benchmark, write the record and heat maps, print the summary."""
    parser = make_parser()
    args = parser.parse_args(argv)
    try:
        folders = [read_policy(path) for path in args.policy]
    except ValueError as error:
        parser.error(f"argument --policy: {error}")
    tasks = {current_id(folder.env_id) for folder in folders}
    if len(tasks) > 1:
        parser.error(f"argument --policy: the policies are of several tasks: {sorted(tasks)}")
    (task,) = tasks
    try:
        grid = grid_for(task)
    except KeyError as error:
        parser.error(f"argument --policy: {error.args[0]}")
    if args.cells:
        try:
            grid = grid.select(args.cells)
        except ValueError as error:
            parser.error(f"argument --cells: {error}")
    if args.json.is_file():
        try:
            read_json(args.json)
        except ValueError as error:
            parser.error(f"argument --json: {error}")
    seeds = [args.seed + i for i in range(args.episodes)]
    cells = grid.cells()
    try:
        record = _play(args, task, grid, seeds)
    except SettingsMismatch as error:
        parser.error(f"argument --json: {error}")
    except PolicySetError as error:
        parser.error(f"argument --policy: {error}")
    summary = summarize_benchmark(record)
    record["summary"] = {
        "all": summary,
        "held_out": summarize_benchmark(record, True),
        "limits": limits(record),
    }
    write_json(args.json, record)
    if args.plots:
        labels = record.get("labels", {})
        for score, path in plot_paths(args.plots).items():
            with atomic_output(path) as tmp:
                plot_heat_maps(record, score, tmp, labels)
        profiles = args.plots.with_name(f"{args.plots.stem}_profiles{args.plots.suffix}")
        with atomic_output(profiles) as tmp:
            plot_profiles(record, tmp, labels)
    print(f"{task}: {len(cells)} cells, {len(seeds)} episodes each, {len(args.policy)} policies")
    if 1 < len(args.policy) < MIN_SEEDS:
        print(f"fewer than {MIN_SEEDS} seeds: the intervals over seeds are too narrow to trust")
    print(json.dumps(jsonable(record["summary"]["all"]["scores"]), indent=1))
    print_limits(record["summary"]["limits"], len(cells))
    return record


def _play(args: argparse.Namespace, task: str, grid: Grid, seeds: list[int]) -> dict[str, Any]:
    """The cells still to play, in ``args.workers`` processes, behind a progress bar."""
    pool = make_pool(args.workers)
    bar = tqdm(total=len(grid.cells()), desc="cells", unit="cell", disable=args.no_progress_bar)
    try:
        return run_benchmark(
            task,
            args.policy,
            grid,
            seeds,
            args.json,
            pool,
            on_cell=lambda _: bar.update(),
            remake=args.remake,
            reuse=args.reuse,
        )
    finally:
        bar.close()
        if pool is not None:
            pool.shutdown()


def print_limits(found: dict[str, Any], cells: int) -> None:
    """One line per policy of :func:`~acl_env.benchmark.summary.limits`' counts."""
    for policy, where in found.items():
        print(
            f"{policy}: falls more often than the best analytic controller in "
            f"{len(where['cells_falling_more_than_best_analytic'])} of {cells} cells; "
            f"succeeds reliably in {where['held_out_reliable_cells_held']} of the "
            f"{where['held_out_reliable_cells']} held-out cells where an analytic controller does; "
            f"holds on in {len(where['cells_every_analytic_loses_held'])} of the "
            f"{len(where['cells_every_analytic_loses'])} cells where every analytic controller "
            "falls in most episodes"
        )


run = console_script(main)

if __name__ == "__main__":
    run()
