"""The command line of the open-loop tuner, ``acl-tune-gait`` (also ``python -m acl_env.tuning``).

Outputs go where they are told, or under ``runs/`` (git-ignored), relative to the working
directory: the study database ``runs/tune_gait.db``, the tuned gait ``runs/tuned_gaits.json``
(format: :mod:`acl_env.tuned_gaits`; the shipped file is written only when given its path) and
the frontier figure ``runs/frontier_{key}.png``::

    acl-tune-gait --n-trials 300                  # rolling ACL, training reward weights
    acl-tune-gait --no-roll --n-trials 300        # non-rolling ACL, key acl_noroll
    acl-tune-gait --n-jobs 2 --storage sqlite:///runs/tune_gait.db   # two worker processes
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import gymnasium
import optuna
import yaml

from acl_env import ACL_CLIMB_ID, ACL_CLIMB_NOROLL_ID, shipped, tuned_gaits
from acl_env.gait.gaits import DEFAULT_POLE_RADIUS
from acl_env.io import jsonable
from acl_env.training.cli import ArgumentParser, int_at_least, script
from acl_env.training.config import load_hyperparams
from acl_env.tuning.frontier import plot_frontier, policy_point
from acl_env.tuning.objective import DEFAULT_SEEDS, OBJECTIVES, TuneSettings
from acl_env.tuning.space import CONDITIONS, UsageError, parse_condition, parse_pairs, parse_space
from acl_env.tuning.stop import catch_stop_signals, restore_signals
from acl_env.tuning.study import open_storage, prepare_study, run_study
from acl_env.tuning.validation import tuned_entry, validate

DEFAULT_CONFIG = shipped.recipe_path()
DEFAULT_OUTPUT = Path("runs/tuned_gaits.json")
DEFAULT_STORAGE = Path("runs/tune_gait.db")
DEFAULT_PLOT = "runs/frontier_{key}.png"


def make_parser() -> ArgumentParser:
    """Command line (relative paths from the working directory; outputs under ``runs/``)."""
    parser = ArgumentParser(
        prog="acl-tune-gait",
        description="Tune the open-loop ACL gait with Optuna (parallel, resumable).",
    )
    positive = int_at_least(1)
    parser.add_argument("--no-roll", action="store_true", help="rolls_per_cycle=0 (key acl_noroll)")
    parser.add_argument(
        "--env",
        default=None,
        help=f"env every trial plays (default: {ACL_CLIMB_ID}, or {ACL_CLIMB_NOROLL_ID} with "
        f"--no-roll; a trial sets the whole gait, so another version of the task plays the same "
        f"trials: name the one a stored study was run on to resume or redraw it)",
    )
    parser.add_argument(
        "--objective",
        default="reward_per_gait_cycle",
        help=f"evaluation metric to optimise, one of {list(OBJECTIVES)}",
    )
    parser.add_argument(
        "--reward-weights",
        nargs="*",
        default=None,
        metavar="TERM:WEIGHT",
        help="env reward weights (default: the --config entry's for the env)",
    )
    parser.add_argument(
        "--condition",
        nargs="*",
        default=[],
        metavar="NAME:VALUE",
        help=f"play every trial under this condition instead of the env's default, NAME one of "
        f"{list(CONDITIONS)} (e.g. friction:0.5)",
    )
    parser.add_argument(
        "--config",
        default=str(DEFAULT_CONFIG),
        help="training recipe (zoo YAML; default: the shipped one)",
    )
    parser.add_argument(
        "--n-trials",
        type=positive,
        default=300,
        help="the study's total trials: a rerun, or another process, runs only what is missing",
    )
    parser.add_argument("--n-jobs", type=positive, default=1, help="worker processes")
    parser.add_argument(
        "--storage", default=str(DEFAULT_STORAGE), help="SQLite file or Optuna storage URL"
    )
    parser.add_argument("--study-name", default=None, help="default: the key")
    parser.add_argument("--key", default=None, help="entry in --output (acl / acl_noroll)")
    parser.add_argument("--seeds", type=int, nargs="+", default=list(DEFAULT_SEEDS))
    parser.add_argument("--steps-per-cycle", type=int_at_least(2), default=220)
    parser.add_argument("--cycles", type=positive, default=2, help="gait cycles per episode")
    parser.add_argument(
        "--max-clipped",
        type=float,
        default=0.1,
        help="largest share of the keyframe table's joint angles the +-90 deg limit may clip",
    )
    parser.add_argument(
        "--max-arc",
        type=float,
        default=None,
        help="disqualify gaits whose largest touched arc (deg) exceeds this on any seed "
        "(default: 90 with --no-roll, so the tuned gait truly does not roll; none otherwise)",
    )
    parser.add_argument(
        "--validate-seeds",
        type=int_at_least(0),
        default=10,
        help="new seeds on which the best trials are re-measured before one is picked (0: none)",
    )
    parser.add_argument(
        "--validate-top", type=positive, default=5, help="how many of the best trials to re-measure"
    )
    parser.add_argument(
        "--space", nargs="*", default=[], metavar="NAME:LOW:HIGH", help="search range overrides"
    )
    parser.add_argument(
        "--output",
        default=str(DEFAULT_OUTPUT),
        help="tuned-gaits JSON file (the key's entry replaced)",
    )
    parser.add_argument("--plot", default=DEFAULT_PLOT, help="frontier figure ('' for none)")
    parser.add_argument(
        "--policy-point",
        action="append",
        default=[],
        metavar="EVAL_JSON[:CONTROLLER][=LABEL]",
        help="mark a controller of an evaluation JSON on the figure (default controller: policy; "
        "may repeat)",
    )
    parser.add_argument(
        "--also-plot",
        nargs="*",
        default=[],
        metavar="STUDY",
        help="other studies in --storage whose gaits join the frontier figure",
    )
    parser.add_argument("--sampler-seed", type=int, default=None)
    parser.add_argument("--no-progress-bar", action="store_true")
    return parser


def settings_from_args(args: argparse.Namespace) -> TuneSettings:
    """Validated settings; bad input raises :class:`UsageError` naming the argument."""
    if args.objective not in OBJECTIVES:
        raise UsageError("--objective", f"unknown {args.objective!r}; known: {list(OBJECTIVES)}")
    if not 0.0 <= args.max_clipped <= 1.0:
        raise UsageError("--max-clipped", f"must be in [0, 1], got {args.max_clipped}")
    max_arc = args.max_arc if args.max_arc is not None else (90.0 if args.no_roll else None)
    if max_arc is not None and not 0.0 < max_arc <= 360.0:
        raise UsageError("--max-arc", f"must be in (0, 360] degrees, got {max_arc}")
    if len(set(args.seeds)) != len(args.seeds):
        raise UsageError("--seeds", f"repeated seeds {args.seeds}")
    env_id = args.env or (ACL_CLIMB_NOROLL_ID if args.no_roll else ACL_CLIMB_ID)
    if env_id not in gymnasium.registry or not env_id.startswith("acl_env/"):
        known = [k for k in gymnasium.registry if k.startswith("acl_env/")]
        raise UsageError("--env", f"unknown env {env_id!r}; known: {known}")
    if args.reward_weights is None:
        try:
            hyperparams = load_hyperparams(args.config, env_id)
        except (OSError, KeyError, ValueError, yaml.YAMLError) as exc:
            raise UsageError("--config", str(exc).splitlines()[0]) from None
        weights = dict((hyperparams.get("env_kwargs") or {}).get("reward_weights") or {})
    else:
        weights = parse_pairs(args.reward_weights, "--reward-weights")
    try:  # the env checks the weights' names and values
        gymnasium.make(env_id, steps_per_cycle=args.steps_per_cycle, reward_weights=weights).close()
    except (ValueError, TypeError) as exc:
        raise UsageError("--reward-weights", str(exc)) from None
    condition = parse_condition(args.condition)
    radii = condition.get("pole_radius", DEFAULT_POLE_RADIUS)
    # the thinnest pole leaves the least helix radius for the radial wave
    space = parse_space(args.space, min(radii) if isinstance(radii, list) else radii)
    settings = TuneSettings(
        env_id=env_id,
        objective=args.objective,
        reward_weights=weights,
        rolls_per_cycle=0 if args.no_roll else 1,
        seeds=tuple(args.seeds),
        steps_per_cycle=args.steps_per_cycle,
        cycles_per_episode=args.cycles,
        max_clipped=args.max_clipped,
        max_touched_arc_deg=max_arc,
        space=space,
        condition=condition,
    )
    for values in settings.conditions():  # the env checks the condition's values
        try:
            gymnasium.make(env_id, **values).close()
        except (ValueError, TypeError) as exc:
            raise UsageError("--condition", str(exc)) from None
    return settings


def main(argv: Sequence[str] | None = None) -> dict[str, Any] | None:
    """Tune, then write the best gait to ``--output`` and the frontier figure; return the entry."""
    parser = make_parser()
    args = parser.parse_args(argv)
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    key = args.key or ("acl_noroll" if args.no_roll else "acl")
    study_name = args.study_name or key
    try:
        settings = settings_from_args(args)
        policies = []
        for given in args.policy_point:
            spec, _, label = given.partition("=")
            path, _, controller = spec.partition(":")
            try:
                point = policy_point(path, controller or "policy")
            except (OSError, KeyError, ValueError, TypeError) as exc:
                raise UsageError("--policy-point", f"cannot read {given}: {exc!r}") from None
            policies.append((label or controller or "policy", point))
        prepare_study(settings, args.storage, study_name)  # bad storage fails before any trial
        others = []
        for name in args.also_plot:
            try:
                others.append(
                    optuna.load_study(study_name=name, storage=open_storage(args.storage))
                )
            except KeyError:
                raise UsageError("--also-plot", f"no study {name!r} in {args.storage}") from None
    except UsageError as exc:
        parser.error(str(exc))
    previous = catch_stop_signals()
    try:
        study = run_study(
            settings,
            args.storage,
            study_name,
            args.n_trials,
            args.n_jobs,
            args.sampler_seed,
            progress=not args.no_progress_bar,
        )
    except KeyboardInterrupt:
        print(
            f"acl-tune-gait: interrupted; the finished trials are in {args.storage}: rerun the "
            "same command to resume (nothing written)",
            file=sys.stderr,
        )
        raise SystemExit(130) from None
    finally:
        restore_signals(previous)
    try:
        chosen, validation = validate(study, settings, args.validate_top, args.validate_seeds)
    except RuntimeError as exc:
        print(f"acl-tune-gait: {exc}; nothing written", file=sys.stderr)
        raise SystemExit(1) from None
    entry = tuned_entry(study, settings, chosen, validation)
    tuned_gaits.write(args.output, key, entry)
    print(json.dumps(jsonable({key: entry}), indent=2))
    if args.plot:
        plot = args.plot.format(key=key)
        weights = ", ".join(f"{k} {v:g}" for k, v in settings.reward_weights.items())
        title = (
            f"{key}: {entry['trials']} open-loop gaits on {settings.env_id}, {len(settings.seeds)}"
            f" seeds each, {settings.steps_per_cycle} steps per gait cycle"
            f"\n{settings.objective} with reward weights {weights}"
        )
        plot_frontier(study, settings, plot, title, chosen, policies, others)
        print(f"frontier figure: {plot}")
    return entry


# The console script (pyproject.toml): main() without its returned document.
run = script(main)
