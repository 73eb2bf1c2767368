"""The command line of the open-loop tuner, ``acl-tune-gait`` (also ``python -m acl_env.tuning``).

Outputs go where they are told, or under ``runs/`` (git-ignored), relative to the working
directory: the study database ``runs/tune_gait.db``, the tuned gait ``runs/tuned_gaits.json``
(format: :mod:`acl_env.tuned_gaits`; the shipped file is written only when given its path) and
the frontier figure ``runs/frontier_{key}.png``::

    acl-tune-gait --n-trials 300                  # rolling ACL, training reward weights
    acl-tune-gait --no-roll --n-trials 300        # non-rolling ACL, key acl_noroll
    acl-tune-gait --n-jobs 2 --storage sqlite:///runs/tune_gait.db   # two worker processes
    acl-tune-gait --storage postgresql://user:pw@host/db   # one worker per machine, one study

Every option is checked before the study starts (:mod:`acl_env.tuning.checks`): a bad one exits
with status 2 and one line naming it, and nothing is written.
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
from acl_env.cli import ArgumentParser, pairs_to_dict, reward_weight
from acl_env.constants import DEFAULT_STEPS_PER_CYCLE
from acl_env.envs.config import CYCLES_PER_EPISODE_RANGE
from acl_env.envs.gait_config import STEPS_PER_CYCLE_RANGE
from acl_env.gait.gaits import DEFAULT_POLE_RADIUS
from acl_env.io import atomic_write, console_script, jsonable
from acl_env.training.config import load_hyperparams
from acl_env.tuning.checks import (
    SAMPLER_SEED_RANGE,
    SEED_RANGE,
    check_output_file,
    check_plot,
    check_recipe,
    check_storage,
    finite_float,
    int_in,
)
from acl_env.tuning.frontier import policy_point, render_frontier
from acl_env.tuning.objective import DEFAULT_SEEDS, OBJECTIVES, TuneSettings
from acl_env.tuning.remeasure import tuned_entry, validate
from acl_env.tuning.space import (
    CONDITIONS,
    GRIP_SPACE,
    UsageError,
    parse_condition,
    parse_space,
    start_points,
)
from acl_env.tuning.stop import catch_stop_signals, restore_signals
from acl_env.tuning.study import (
    DEFAULT_HEARTBEAT,
    open_storage,
    prepare_study,
    run_study,
    sqlite_path,
)

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
        type=reward_weight,
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
        type=int_in(1, 10**6),
        default=300,
        help="the study's total trials: a rerun, or another process, runs only what is missing",
    )
    parser.add_argument("--n-jobs", type=int_in(1, 1024), default=1, help="worker processes")
    parser.add_argument(
        "--storage",
        default=str(DEFAULT_STORAGE),
        help="SQLite file or Optuna storage URL (postgresql://user:password@host/db: workers on "
        "several machines share one study)",
    )
    parser.add_argument(
        "--heartbeat",
        type=int_in(0, 3600),
        default=DEFAULT_HEARTBEAT,
        metavar="SECONDS",
        help="each running trial records a heartbeat this often; one silent for 4 heartbeats "
        "(its worker killed) is marked failed and run again by another worker (0: off)",
    )
    parser.add_argument("--study-name", default=None, help="default: the key")
    parser.add_argument("--key", default=None, help="entry in --output (acl / acl_noroll)")
    parser.add_argument("--seeds", type=int_in(*SEED_RANGE), nargs="+", default=list(DEFAULT_SEEDS))
    parser.add_argument(
        "--steps-per-cycle", type=int_in(*STEPS_PER_CYCLE_RANGE), default=DEFAULT_STEPS_PER_CYCLE
    )
    parser.add_argument(
        "--cycles",
        type=int_in(*CYCLES_PER_EPISODE_RANGE),
        default=2,
        help="gait cycles per episode",
    )
    parser.add_argument(
        "--max-clipped",
        type=finite_float,
        default=0.1,
        help="largest share of the keyframe table's joint angles the +-90 deg limit may clip",
    )
    parser.add_argument(
        "--max-arc",
        type=finite_float,
        default=None,
        help="disqualify gaits whose largest touched arc (deg) exceeds this on any seed "
        "(default: 90 with --no-roll, so the tuned gait truly does not roll; none otherwise)",
    )
    parser.add_argument(
        "--validate-seeds",
        type=int_in(0, 1000),
        default=10,
        help="new seeds on which the best trials are re-measured before one is picked (0: none)",
    )
    parser.add_argument(
        "--validate-top",
        type=int_in(1, 1000),
        default=5,
        help="how many of the best trials to re-measure",
    )
    parser.add_argument(
        "--space", nargs="*", default=[], metavar="NAME:LOW:HIGH", help="search range overrides"
    )
    parser.add_argument(
        "--output",
        default=str(DEFAULT_OUTPUT),
        help="tuned-gaits JSON file (the key's entry replaced, atomically; a symbolic link there "
        "is replaced, never written through)",
    )
    parser.add_argument(
        "--plot", default=DEFAULT_PLOT, help="frontier figure, {key} the key ('' for none)"
    )
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
    parser.add_argument(
        "--start-from",
        nargs="+",
        default=[],
        metavar="KEY",
        help="shipped tuned gaits a new study tries first (e.g. a gait tuned on other physics)",
    )
    parser.add_argument(
        "--grip",
        action="store_true",
        help="tune the compliant grip (grip_target, grip_gain, grip_leak) on the gait the SEA "
        "env id plays, instead of the gait (trial 0: no gain, the open loop)",
    )
    parser.add_argument("--sampler-seed", type=int_in(*SAMPLER_SEED_RANGE), default=None)
    parser.add_argument("--no-progress-bar", action="store_true")
    return parser


def settings_from_args(args: argparse.Namespace) -> TuneSettings:
    """Validated settings; bad input raises :class:`UsageError` naming the argument."""
    max_arc = _checked_limits(args)
    env_id = args.env or (ACL_CLIMB_NOROLL_ID if args.no_roll else ACL_CLIMB_ID)
    if env_id not in gymnasium.registry or not env_id.startswith("acl_env/"):
        known = [k for k in gymnasium.registry if k.startswith("acl_env/")]
        raise UsageError("--env", f"unknown env {env_id!r}; known: {known}")
    weights = _reward_weights(args, env_id)
    _check_env(env_id, "--reward-weights", reward_weights=weights)
    _check_env(env_id, "--steps-per-cycle", steps_per_cycle=args.steps_per_cycle)
    _check_env(env_id, "--cycles", cycles_per_episode=args.cycles)
    condition = parse_condition(args.condition)
    space = _search_space(args, env_id, condition)
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
        grip=args.grip,
    )
    for values in settings.conditions():  # the env checks the condition's values
        _check_env(env_id, "--condition", **values)
    return settings


def _checked_limits(args: argparse.Namespace) -> float | None:
    """Check the objective, ``--max-clipped``, ``--max-arc`` and ``--seeds``; return the largest
    touched arc allowed (``--max-arc``, 90 degrees with ``--no-roll``, else None)."""
    if args.objective not in OBJECTIVES:
        raise UsageError("--objective", f"unknown {args.objective!r}; known: {list(OBJECTIVES)}")
    if not 0.0 <= args.max_clipped <= 1.0:
        raise UsageError("--max-clipped", f"must be in [0, 1], got {args.max_clipped}")
    max_arc = args.max_arc if args.max_arc is not None else (90.0 if args.no_roll else None)
    if max_arc is not None and not 0.0 < max_arc <= 360.0:
        raise UsageError("--max-arc", f"must be in (0, 360] degrees, got {max_arc}")
    if len(set(args.seeds)) != len(args.seeds):
        raise UsageError("--seeds", f"repeated seeds {args.seeds}")
    return max_arc


def _reward_weights(args: argparse.Namespace, env_id: str) -> dict[str, Any]:
    """``--reward-weights``, else the reward the recipe (``--config``'s entry) trains on."""
    if args.reward_weights is not None:
        try:
            return pairs_to_dict("--reward-weights", args.reward_weights)
        except argparse.ArgumentTypeError as exc:
            raise UsageError("--reward-weights", str(exc).split(": ", 1)[1]) from None
    try:
        hyperparams = load_hyperparams(args.config, env_id)
    except (OSError, KeyError, ValueError, TypeError, AttributeError, yaml.YAMLError) as exc:
        message = str(exc).splitlines()[0]
        where = "" if args.config in message else f"{args.config} entry {env_id}: "
        raise UsageError("--config", f"{where}{message}") from None
    if not isinstance(hyperparams, dict):
        raise UsageError("--config", f"{args.config} entry {env_id} is not a mapping")
    check_recipe(hyperparams, env_id, f"{args.config} entry {env_id}")
    # The entry's reward, else the one the env registers (a benchmark id's entry holds
    # only its domain randomisation): the reward the recipe trains on.
    registered = (gymnasium.spec(env_id).kwargs or {}).get("reward_weights") or {}
    entry = (hyperparams.get("env_kwargs") or {}).get("reward_weights")
    return dict(entry if entry is not None else registered)


def _search_space(
    args: argparse.Namespace, env_id: str, condition: dict[str, Any]
) -> dict[str, Any]:
    """``--space`` over the gait's parameters, or with ``--grip`` the grip's (the env's gait
    held fixed)."""
    radii = condition.get("pole_radius", DEFAULT_POLE_RADIUS)
    # the thinnest pole leaves the least helix radius for the radial wave
    space = parse_space(args.space, min(radii) if isinstance(radii, list) else radii)
    if args.grip:
        for option, given in (("--space", args.space), ("--start-from", args.start_from)):
            if given:
                raise UsageError(option, "searches the gait; --grip holds the env's gait fixed")
        _check_env(env_id, "--grip", grip_target=0.0)  # the SEA, and a gait to adapt
        space = dict(GRIP_SPACE)
    return space


def _check_env(env_id: str, option: str, **kwargs: Any) -> None:
    """Build the env with ``kwargs`` once, so that its own checks refuse them naming ``option``."""
    try:
        gymnasium.make(env_id, **kwargs).close()
    except (ValueError, TypeError, OverflowError) as exc:
        message = str(exc).split(" was raised from the environment creator")[0]
        raise UsageError(option, message) from None


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
        chosen, validation = validate(study, settings, args.validate_top, args.validate_seeds)
    except RuntimeError as exc:
        print(f"acl-tune-gait: {exc}; nothing written", file=sys.stderr)
        raise SystemExit(1) from None
    entry = tuned_entry(study, settings, chosen, validation)
    image = None
    if plot is not None:  # drawn before anything is written: a failure here writes nothing
        weights = ", ".join(f"{k} {v:g}" for k, v in settings.reward_weights.items())
        title = (
            f"{key}: {entry['trials']} {'compliant grips' if settings.grip else 'open-loop gaits'}"
            f" on {settings.env_id}, {len(settings.seeds)}"
            f" seeds each, {settings.steps_per_cycle} steps per gait cycle"
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
