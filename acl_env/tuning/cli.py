"""The command line of the open-loop tuner, ``acl-tune-gait`` (also ``python -m acl_env.tuning``).

Outputs go where they are told, or under ``runs/`` (git-ignored), relative to the working
directory: the study database ``runs/tune_gait.db``, the tuned gait ``runs/tuned_gaits.json``
(format: :mod:`acl_env.tuned_gaits`; the shipped file is written only when given its path) and
the frontier figure ``runs/frontier_{key}.png``::

    acl-tune-gait --n-trials 300                  # rolling ACL, training reward weights
    acl-tune-gait --no-roll --n-trials 300        # non-rolling ACL, key acl_noroll
    acl-tune-gait --n-jobs 2 --storage sqlite:///runs/tune_gait.db   # two worker processes
    acl-tune-gait --storage postgresql://user:pw@host/db   # one worker per machine, one study

The parser and the default paths are in :mod:`acl_env.tuning.arguments`. Every option is checked
before the study starts (:mod:`acl_env.tuning.settings`, :mod:`acl_env.tuning.checks`): a bad one
exits with status 2 and one line naming it, and nothing is written.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import optuna

from acl_env import tuned_gaits
from acl_env.io import atomic_write, console_script, jsonable
from acl_env.tuning.arguments import make_parser
from acl_env.tuning.checks import check_output_file, check_plot, check_storage
from acl_env.tuning.frontier import policy_point, render_frontier
from acl_env.tuning.objective import TuneSettings
from acl_env.tuning.remeasure import tuned_entry, validate
from acl_env.tuning.settings import settings_from_args
from acl_env.tuning.space import UsageError, start_points
from acl_env.tuning.stop import catch_stop_signals, restore_signals
from acl_env.tuning.study import open_storage, prepare_study, run_study, sqlite_path


def main(argv: Sequence[str] | None = None) -> dict[str, Any] | None:
    """Tune, then write the best gait to ``--output`` and the frontier figure; return the entry.

    Every option is checked first: nothing is written (no study database either) unless all pass.
    """
    parser = make_parser()
    args = parser.parse_args(argv)
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    key = args.key or ("acl_noroll" if args.no_roll else "acl")
    study_name = args.study_name or key
    try:
        settings, output, plot, policies, others = _prepare(args, key, study_name)
    except UsageError as exc:
        parser.error(str(exc))
    study = _tune(args, settings, study_name)
    try:
        chosen, validation = validate(
            study, settings, args.validate_top, args.validate_seeds, not args.no_progress_bar
        )
    except RuntimeError as exc:
        print(f"acl-tune-gait: {exc}; nothing written", file=sys.stderr)
        raise SystemExit(1) from None
    entry = tuned_entry(study, settings, chosen, validation)
    image = None
    if plot is not None:  # drawn before anything is written: a failure here writes nothing
        weights = ", ".join(f"{k} {v:g}" for k, v in settings.reward_weights.items())
        seeds = f"{len(settings.seeds)} seed{'s' if len(settings.seeds) != 1 else ''} each"
        if settings.condition:
            seeds += f" in each of {len(settings.conditions())} conditions"
        title = (
            f"{key}: {entry['trials']} {'compliant grips' if settings.grip else 'open-loop gaits'}"
            f" on {settings.env_id}, {seeds}, {settings.steps_per_cycle} steps per gait cycle"
            f"\n{settings.objective} with reward weights {weights}"
        )
        image = render_frontier(
            study, settings, title, chosen, policies, others, plot.suffix.lstrip(".").lower()
        )
    tuned_gaits.write(output, key, entry)
    if plot is not None and image is not None:  # every file first, then the printing
        plot.parent.mkdir(parents=True, exist_ok=True)
        atomic_write(plot, image)
    print(json.dumps(jsonable({key: entry}), indent=2))
    if plot is not None and image is not None:
        print(f"frontier figure: {plot}")
    return entry


def _prepare(
    args: argparse.Namespace, key: str, study_name: str
) -> tuple[TuneSettings, Path, Path | None, list[tuple[str, dict[str, float]]], list[optuna.Study]]:
    """Check every option, then create (or open) the study: the settings, the output file, the
    figure of ``key`` (None: not drawn), the policy points and the other studies drawn. A
    refused option raises :class:`UsageError`, and leaves no new SQLite file behind."""
    settings = settings_from_args(args)
    output = check_output_file(args.output)
    plot = check_plot(args.plot, key)
    check_storage(args.storage)
    policies = _policy_points(args.policy_point)
    others = _other_studies(args.storage, args.also_plot, args.heartbeat)
    database = sqlite_path(args.storage)
    new_file = database is not None and not database.exists()
    try:  # last: it creates the study (and a new SQLite file)
        starts = start_points(args.start_from, settings.space)
        prepare_study(settings, args.storage, study_name, args.heartbeat, starts)
    except UsageError:
        if new_file and database is not None:
            database.unlink(missing_ok=True)
        raise
    return settings, output, plot, policies, others


def _tune(args: argparse.Namespace, settings: TuneSettings, study_name: str) -> optuna.Study:
    """Run the study's trials, SIGTERM handled as Ctrl-C; an interruption exits 130 (the finished
    trials stay in the storage), a failed study 1, nothing written."""
    previous = catch_stop_signals()
    try:
        return run_study(
            settings,
            args.storage,
            study_name,
            args.n_trials,
            args.n_jobs,
            args.sampler_seed,
            progress=not args.no_progress_bar,
            heartbeat=args.heartbeat,
        )
    except KeyboardInterrupt:
        print(
            f"acl-tune-gait: interrupted; the finished trials are in {args.storage}: rerun the "
            "same command to resume (nothing written)",
            file=sys.stderr,
        )
        raise SystemExit(130) from None
    except RuntimeError as exc:
        print(f"acl-tune-gait: {exc}; nothing written", file=sys.stderr)
        raise SystemExit(1) from None
    finally:
        restore_signals(previous)


def _policy_points(given: Sequence[str]) -> list[tuple[str, dict[str, float]]]:
    """``--policy-point EVAL_JSON[:CONTROLLER][=LABEL]`` items as (label, point)."""
    policies = []
    for item in given:
        spec, _, label = item.partition("=")
        path, _, controller = spec.partition(":")
        try:
            point = policy_point(path, controller or "policy")
        except (OSError, KeyError, ValueError, TypeError, OverflowError) as exc:
            raise UsageError("--policy-point", f"cannot read {item}: {exc!r}") from None
        policies.append((label or controller or "policy", point))
    return policies


def _other_studies(storage: str, names: Sequence[str], heartbeat: int) -> list[optuna.Study]:
    """The ``--also-plot`` studies, which must exist in ``storage`` (a new SQLite file holds
    none, and is not created to find out)."""
    if not names:
        return []
    database = sqlite_path(storage)
    if database is not None and not database.exists():
        raise UsageError("--also-plot", f"no study {names[0]!r} in {storage} (no such file)")
    rdb = open_storage(storage, heartbeat)
    others = []
    for name in names:
        try:
            others.append(optuna.load_study(study_name=name, storage=rdb))
        except KeyError:
            raise UsageError("--also-plot", f"no study {name!r} in {storage}") from None
    return others


# The console script (pyproject.toml): main() without its returned document.
run = console_script(main)
