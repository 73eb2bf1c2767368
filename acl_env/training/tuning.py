"""The open-loop tuner: Optuna searches the ACL gait's parameters for the best open-loop gait.

Each trial builds ``ACLClimb-v1`` (``ACLClimbNoRoll-v3`` with ``--no-roll``: the non-rolling task,
its roll term and ``roll_limit``; ``--env`` names another) with a candidate squeeze and
``gait_kwargs`` (amp_pitch, spatial_freq, amp_radial, radial_freq, pitch of Eq. 1;
``rolls_per_cycle`` 1, or 0 with ``--no-roll``), plays it open loop (zero action: one keyframe per
step, the gait's own cadence) on a few seeds, and scores it by one evaluation metric, by default
the env's reward per gait cycle under the given ``reward_weights`` (default: the training config's
entry for that env id). A gait that falls (or, on the non-rolling task, ends by ``roll_limit``) on
any seed, or whose keyframe table the +-90 deg joint limit clips in more than ``max_clipped`` of
its (keyframe, joint) entries, is disqualified (the trial is pruned, its reason in the user
attribute ``disqualified``); so is, with ``--no-roll``, a gait that touches the pole over more than
90 degrees of some module's circumference (it rolls after all: ``touched_arc_deg``). Episodes are
rolled out and measured by :mod:`acl_env.evaluation` (``run_episode``, ``Episode.metrics``), and
every trial stores those metrics (mean over its seeds) as user attributes.

``--condition friction:0.5`` (also ``pole_radius``, ``kp``) tunes the gait for one fixed condition
other than the env's defaults: every trial and the validation play there. The best gait for a
held-out condition, found this way, is the open loop a policy that never saw it is measured
against at its best (README, non-rolling task). Lists make a grid,
``--condition friction:[0.7,1.2] pole_radius:[0.065,0.09]``: every trial plays every seed in each
of the four, and is scored by the mean over all of them (disqualified by a fall in any): a gait
for a range of conditions rather than one.

With a few seeds per trial the study's best is partly luck, and good gaits sit near a cliff where
the grip gives way; so the ``--validate-top`` best trials (and the default gait) are measured
again on ``--validate-seeds`` new seeds, and the tuned gait is the best of them on those seeds
among the ones that did not fall (nor, with ``--no-roll``, roll) there.

Parallel and resumable as rl_zoo3's ``--optimize --storage``: the study lives in a database
(SQLite file by default, any SQLAlchemy URL Optuna accepts), ``--n-jobs`` worker processes share
it, and so can other processes or machines pointed at the same URL. ``--n-trials`` is the study's
total (finished trials count), so rerunning the same command resumes an interrupted study.

Output, ``train/configs/tuned_gaits.yml`` (read by evaluation), one entry per key ("acl", or
"acl_noroll" with ``--no-roll``)::

    acl:
      env_id: acl_env/ACLClimb-v1     # the env the gait was tuned on (ACLClimbNoRoll-v3, or
                                       # v2 for the studies run before v3, for acl_noroll)
      env_kwargs:                      # pass to gymnasium.make(env_id, **env_kwargs)
        squeeze: 0.004                 # m
        gait_kwargs: {pitch: .., amp_pitch: .., spatial_freq: .., amp_radial: ..,
                      radial_freq: .., rolls_per_cycle: 1}
      objective: reward_per_gait_cycle # the metric maximised (or minimised)
      reward_weights: {climb: 1.0, slip: 2.0}
      seeds: [0, 1, 2]                 # reset seeds of each trial's episodes
      steps_per_cycle: 220
      cycles_per_episode: 2
      trials: 300                      # finished trials (complete + disqualified)
      best_trial: 123                  # the chosen trial (after validation)
      study: acl
      metrics: {climb_per_gait_cycle_m: .., slip_per_m: .., energy_per_m: ..,
                reward_per_gait_cycle: .., falls: 0.0, ...}  # acl_env.evaluation.METRICS of
                                       # the tuned gait, mean over the tuning seeds
      validation:                      # the same on new seeds (absent with --validate-seeds 0)
        seeds: [3, 4, ..., 12]
        fell: false
        candidates: 5                  # best trials re-measured, the tuned gait the best of them
        metrics: {...}                 # mean over the validation seeds
        ci95_half_width: {...}         # Student's t, over the validation seeds
      default_gait_metrics: {...}      # the untuned gait, same protocol (the study's trial 0)
      default_gait_validation: {...}   # and on the validation seeds

    acl-tune-gait --n-trials 300                  # rolling ACL, training reward weights
    acl-tune-gait --no-roll --n-trials 300        # non-rolling ACL, key acl_noroll
    acl-tune-gait --n-jobs 2 --storage sqlite:///runs/tune_gait.db   # two worker processes
"""

from __future__ import annotations

import argparse
import itertools
import math
import multiprocessing
import os
import signal
import socket
import sys
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import optuna
import sqlalchemy.exc
import yaml
from tqdm import tqdm

from acl_env import ACL_CLIMB_ID, ACL_CLIMB_NOROLL_ID, shipped, tuned_gaits
from acl_env.evaluation import METRICS, jsonable, mean_ci95, run_episode, zero_policy
from acl_env.gait.gaits import (
    DEFAULT_AMP_PITCH,
    DEFAULT_PITCH,
    DEFAULT_POLE_RADIUS,
    DEFAULT_SQUEEZE,
    SEA_MODULE_DIAMETER,
    helix_radius,
)
from acl_env.training import cli
from acl_env.training.config import load_hyperparams, parse_kv_pairs

DEFAULT_CONFIG = shipped.recipe_path()
DEFAULT_OUTPUT = Path("runs/tuned_gaits.json")
DEFAULT_STORAGE = Path("runs/tune_gait.db")
DEFAULT_PLOT = "runs/frontier_{key}.png"
DEFAULT_SEEDS = (0, 1, 2)

# Metrics a study can optimise, with their direction (names as in acl_env.evaluation).
OBJECTIVES = {
    "reward_per_gait_cycle": "maximize",
    "climb_per_gait_cycle_m": "maximize",
    "slip_per_m": "minimize",
    "energy_per_m": "minimize",
}
ENV_PARAMS = ("squeeze",)  # searched parameters that are env arguments; the rest are gait_kwargs
# Env arguments --condition may fix for a whole study (the physical conditions of the held-out
# evaluation); the env checks their values.
CONDITIONS = ("pole_radius", "friction", "kp")


@dataclass(frozen=True)
class ParamRange:
    """A searched parameter's bounds; ``integer`` ones are suggested as whole numbers."""

    low: float
    high: float
    integer: bool = False


# Default search space. The hard limits of the gait (checked by check_space, the gait raises
# otherwise) are A_p, A_r >= 0, A_r below the helix radius, pitch >= one module diameter and, for
# this tuner, whole wave numbers; inside them the ranges are chosen as follows (the clipping
# shares are those of 400 random gaits of this space with Omega, k_r up to 4: half of them clip
# more than 10 % of their joint angles and are disqualified without a rollout):
# - squeeze -0.4 to 1.6 cm: from a loose helix (-0.4 cm climbs 0.141 m/cycle at default waves, the
#   grip giving way) to twice the default 0.8 cm (1.2 cm costs 1549 J/m against 1176: the energy
#   grows with the squeeze; issue 9's figures, v0 physics). The helix radius 10.04 cm - squeeze
#   stays far above A_r. The tuned non-rolling gait sits at 1.57 cm; with its waves, 1.9 cm scores
#   less (and clips 13 %) and 2.3 cm rolls (3 seeds, v1), and a 140-trial study with squeeze up
#   to 3 cm found nothing better (best reward 0.0006 against 0.0212).
# - amp_pitch 0-5 cm: 0 is the rolling helix; the best non-rolling gaits measured so far use 3-4
#   cm (clipping 4-8 % of their joint angles); above 3.6 cm three gaits in four clip over 10 %.
# - spatial_freq, radial_freq 1-3, whole numbers: a whole number of waves per turn repeats the
#   wave on every turn, so adjacent turns stay exactly one pitch apart (z(t + 2 pi) - z(t) =
#   pitch) and the pitch bound below keeps them from colliding all along the body. Omega >= 1:
#   the wave's direction sets the direction of travel (Omega = -2 slides down). At 4 waves per
#   turn 70 % of the gaits clip over 10 % (21-34 % at 1-2).
# - amp_radial 0-2.5 cm: 0 is the paper's Eq. 2; at 2 cm with A_p 4 cm the non-rolling gait
#   already falls.
# - pitch 7-16 cm: at least 7 cm leaves 2 cm between turns of the 5.08 cm modules (the gait
#   refuses less than one module diameter); at 16 cm the 1.34 m body still makes two turns.
SEARCH_SPACE: dict[str, ParamRange] = {
    "squeeze": ParamRange(-0.004, 0.016),
    "amp_pitch": ParamRange(0.0, 0.05),
    "spatial_freq": ParamRange(1, 3, integer=True),
    "amp_radial": ParamRange(0.0, 0.025),
    "radial_freq": ParamRange(1, 3, integer=True),
    "pitch": ParamRange(0.07, 0.16),
}
# The untuned gait (the env's and ACLGait's defaults): trial 0 of every new study.
DEFAULT_PARAMS: dict[str, float] = {
    "squeeze": DEFAULT_SQUEEZE,
    "amp_pitch": DEFAULT_AMP_PITCH,
    "spatial_freq": 2,
    "amp_radial": 0.0,
    "radial_freq": 2,
    "pitch": DEFAULT_PITCH,
}


class UsageError(ValueError):
    """Bad command-line input: reported as one line naming the argument, exit status 2."""

    def __init__(self, argument: str, message: str) -> None:
        super().__init__(f"argument {argument}: {message}")


@dataclass(frozen=True)
class TuneSettings:
    """What defines a study: changing any of these needs a new study name."""

    env_id: str = ACL_CLIMB_ID
    objective: str = "reward_per_gait_cycle"
    reward_weights: dict[str, float] = field(default_factory=dict)
    rolls_per_cycle: int = 1
    seeds: tuple[int, ...] = DEFAULT_SEEDS
    steps_per_cycle: int = 220
    cycles_per_episode: int = 2
    max_clipped: float = 0.1
    max_touched_arc_deg: float | None = None
    space: dict[str, ParamRange] = field(default_factory=lambda: dict(SEARCH_SPACE))
    condition: dict[str, float | list[float]] = field(default_factory=dict)

    @property
    def direction(self) -> str:
        return OBJECTIVES[self.objective]

    def as_attrs(self) -> dict[str, Any]:
        """JSON-friendly form stored in the study's user attributes."""
        out = asdict(self)
        out["seeds"] = list(self.seeds)
        out["space"] = {k: [v.low, v.high, v.integer] for k, v in self.space.items()}
        if not self.condition:  # studies from before --condition resume unchanged
            del out["condition"]
        return out

    def env_kwargs(self, params: Mapping[str, float]) -> dict[str, Any]:
        """Env arguments that play the gait ``params`` (squeeze and ``gait_kwargs``)."""
        gait = {k: v for k, v in params.items() if k not in ENV_PARAMS}
        gait["rolls_per_cycle"] = self.rolls_per_cycle
        env = {k: v for k, v in params.items() if k in ENV_PARAMS}
        return {**env, "gait_kwargs": gait}

    def protocol_kwargs(self) -> dict[str, Any]:
        """Env arguments of the evaluation protocol (the same for every trial)."""
        return {
            "steps_per_cycle": self.steps_per_cycle,
            "cycles_per_episode": self.cycles_per_episode,
            "reward_weights": dict(self.reward_weights),
        }

    def conditions(self) -> list[dict[str, float]]:
        """The conditions every trial plays: the grid of ``condition``'s values (one condition
        when each name has one value; the env's defaults when there is none)."""
        names = list(self.condition)
        values = [v if isinstance(v, list) else [v] for v in self.condition.values()]
        return [dict(zip(names, combo, strict=True)) for combo in itertools.product(*values)]

    def make_envs(self, params: Mapping[str, float]) -> list[gymnasium.Env]:
        """One env per condition playing the gait ``params`` under the protocol."""
        kwargs = {**self.protocol_kwargs(), **self.env_kwargs(params)}
        return [gymnasium.make(self.env_id, **kwargs, **c) for c in self.conditions()]


# --- validation -----------------------------------------------------------------------------------


def check_space(space: Mapping[str, ParamRange], pole_radius: float = DEFAULT_POLE_RADIUS) -> None:
    """Raise :class:`UsageError` (``--space``) if a range leaves the gait's validity."""
    for name, r in space.items():
        if name not in SEARCH_SPACE:
            raise UsageError("--space", f"unknown parameter {name!r}; known: {list(SEARCH_SPACE)}")
        if not (math.isfinite(r.low) and math.isfinite(r.high)) or r.low > r.high:
            raise UsageError("--space", f"{name} needs finite low <= high, got {r.low}:{r.high}")
        if r.integer and (r.low != round(r.low) or r.high != round(r.high)):
            raise UsageError(
                "--space",
                f"{name} takes whole numbers (a whole number of waves per turn keeps adjacent "
                f"turns one pitch apart), got {r.low}:{r.high}",
            )
    for name in ("amp_pitch", "amp_radial"):
        if space[name].low < 0.0:
            raise UsageError("--space", f"{name} must be >= 0, got low {space[name].low}")
    if space["pitch"].low < SEA_MODULE_DIAMETER:
        raise UsageError(
            "--space",
            f"pitch must be at least one module diameter ({SEA_MODULE_DIAMETER} m) so that "
            f"adjacent turns do not collide, got low {space['pitch'].low}",
        )
    radius = helix_radius(pole_radius, space["squeeze"].high)
    if space["amp_radial"].high >= radius:
        raise UsageError(
            "--space",
            f"amp_radial must stay below the helix radius ({radius:.4f} m at squeeze "
            f"{space['squeeze'].high}), got high {space['amp_radial'].high}",
        )


def parse_space(
    items: Sequence[str], pole_radius: float = DEFAULT_POLE_RADIUS
) -> dict[str, ParamRange]:
    """``NAME:LOW:HIGH`` overrides of :data:`SEARCH_SPACE`, checked against the gait's validity
    on a pole of ``pole_radius``."""
    space = dict(SEARCH_SPACE)
    for item in items:
        parts = item.split(":")
        if len(parts) != 3:
            raise UsageError("--space", f"expected NAME:LOW:HIGH, got {item!r}")
        name, low, high = parts
        if name not in SEARCH_SPACE:
            raise UsageError("--space", f"unknown parameter {name!r}; known: {list(SEARCH_SPACE)}")
        try:
            bounds = float(low), float(high)
        except ValueError:
            raise UsageError("--space", f"{name} bounds must be numbers, got {item!r}") from None
        space[name] = ParamRange(*bounds, integer=SEARCH_SPACE[name].integer)
    check_space(space, pole_radius)
    return space


def parse_condition(items: Sequence[str]) -> dict[str, float | list[float]]:
    """``--condition NAME:VALUE ...`` as ``{name: value}``, names from :data:`CONDITIONS`; a
    value may be a list (``friction:[0.7,1.2]``): the study then plays the grid of them all."""
    try:
        condition = parse_kv_pairs(items)
    except ValueError as exc:
        raise UsageError("--condition", str(exc)) from None
    for name, value in condition.items():
        if name not in CONDITIONS:
            raise UsageError("--condition", f"unknown {name!r}; known: {list(CONDITIONS)}")
        values = list(value) if isinstance(value, list | tuple) else [value]
        if not values or any(isinstance(v, bool) or not isinstance(v, int | float) for v in values):
            raise UsageError("--condition", f"{name} takes a number or a list, got {value!r}")
        if len(set(values)) != len(values):
            raise UsageError("--condition", f"{name} repeats a value: {value!r}")
        condition[name] = [float(v) for v in values] if len(values) > 1 else float(values[0])
    return condition


def storage_url(storage: str) -> str:
    """An Optuna storage URL: a plain path becomes an SQLite file URL."""
    return storage if "://" in storage else f"sqlite:///{storage}"


def open_storage(storage: str) -> optuna.storages.RDBStorage:
    """The study database (created if missing); unreadable storage raises :class:`UsageError`.

    The heartbeat marks trials of a killed process as failed, so a rerun redoes them; the SQLite
    timeout lets several processes wait for each other's writes.
    """
    url = storage_url(storage)
    if url.startswith("sqlite:///"):
        path = Path(url.removeprefix("sqlite:///"))
        if path.is_dir():
            raise UsageError("--storage", f"{path} is a folder, not a database file")
        if not path.parent.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
    for attempt in range(_CREATE_ATTEMPTS):
        try:
            with warnings.catch_warnings():  # heartbeat_interval: experimental since Optuna 2.9
                warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
                return optuna.storages.RDBStorage(
                    url,
                    engine_kwargs={"connect_args": {"timeout": 60}}
                    if url.startswith("sqlite")
                    else {},
                    heartbeat_interval=30,
                    grace_period=120,
                )
        except Exception as exc:  # SQLAlchemy raises many types: all mean "cannot use it"
            if _lost_creation_race(exc) and attempt + 1 < _CREATE_ATTEMPTS:
                time.sleep(0.2 * (attempt + 1))  # another process is creating the tables
                continue
            raise UsageError(
                "--storage", f"cannot open {storage!r}: {exc}".splitlines()[0]
            ) from None
    raise AssertionError("unreachable")


_CREATE_ATTEMPTS = 8


def _lost_creation_race(exc: Exception) -> bool:
    """Whether ``exc`` is another process creating the same new database's tables at once.

    Two workers started together on a new SQLite file both try to create Optuna's schema; the
    loser sees a duplicate table or version row. Once the winner is done, opening succeeds.
    """
    text = str(exc)
    return isinstance(exc, sqlalchemy.exc.IntegrityError | sqlalchemy.exc.OperationalError) and (
        "already exists" in text or "UNIQUE constraint failed: alembic_version" in text
    )


# --- the objective --------------------------------------------------------------------------------


def rollout_all(
    envs: Sequence[gymnasium.Env], seeds: Sequence[int]
) -> tuple[list[dict[str, float]], str]:
    """:func:`rollout` in each env (condition) in turn, stopping after the first fall or roll;
    with where the last episode ran (``seed 3``, or ``seed 3 at friction 0.7`` on a grid)."""
    episodes: list[dict[str, float]] = []
    where = ""
    for env in envs:
        runs = rollout(env, seeds)
        episodes += runs
        where = f"seed {seeds[len(runs) - 1]}"
        if len(envs) > 1:
            u = env.unwrapped
            where += f" at pole {u.pole_radius} m, friction {u.friction}, kp {u.kp}"
        if runs[-1]["falls"] or runs[-1]["rolled"]:
            break
    return episodes, where


def rollout(env: gymnasium.Env, seeds: Sequence[int]) -> list[dict[str, float]]:
    """Per-episode metrics of the open-loop gait (zero action) on ``seeds``, in order, plus
    ``rolled`` (1 if the env's ``roll_limit`` ended the episode); stops after the first fall or
    roll (either disqualifies the gait anyway)."""
    episodes = []
    for seed in seeds:
        episode = run_episode(env, zero_policy(env), seed, _stop_point)
        episodes.append({**episode.metrics(), "rolled": float(episode.rolled)})
        if episode.fell or episode.rolled:
            break
    return episodes


def suggest_params(trial: optuna.Trial, space: Mapping[str, ParamRange]) -> dict[str, float]:
    """The trial's gait parameters from the search space."""
    params: dict[str, float] = {}
    for name, r in space.items():
        if r.integer:
            params[name] = trial.suggest_int(name, int(r.low), int(r.high))
        else:
            params[name] = trial.suggest_float(name, r.low, r.high)
    return params


def make_objective(settings: TuneSettings) -> Callable[[optuna.Trial], float]:
    """Optuna objective: the mean of ``settings.objective`` over the seeds (and conditions),
    falls disqualifying."""

    def objective(trial: optuna.Trial) -> float:
        trial.set_user_attr("worker", f"{socket.gethostname()}:{os.getpid()}")
        params = suggest_params(trial, settings.space)
        envs = settings.make_envs(params)
        try:
            # The most clipped table over the conditions (a thinner pole clips more).
            saturation = max(
                (env.unwrapped.gait.saturation for env in envs), key=lambda s: s.sample_fraction
            )
            trial.set_user_attr("clipped_fraction", saturation.sample_fraction)
            trial.set_user_attr("clipped_max_rad", saturation.max_excess)
            if saturation.sample_fraction > settings.max_clipped:
                trial.set_user_attr("disqualified", "saturated")
                raise optuna.TrialPruned(f"joint limit clips {saturation.sample_fraction:.0%}")
            episodes, where = rollout_all(envs, settings.seeds)
        finally:
            for env in envs:
                env.close()
        metrics = {m: mean_ci95(e[m] for e in episodes)["mean"] for m in METRICS}
        for name, value in metrics.items():
            trial.set_user_attr(name, value)
        trial.set_user_attr("seeds_run", len(episodes))
        if metrics["falls"] > 0.0:
            trial.set_user_attr("disqualified", "fell")
            raise optuna.TrialPruned(f"fell on {where}")
        if any(e["rolled"] for e in episodes):
            trial.set_user_attr("disqualified", "rolled")
            raise optuna.TrialPruned(f"rolled past roll_limit on {where}")
        arc = max(e["touched_arc_deg"] for e in episodes)
        trial.set_user_attr("max_touched_arc_deg", arc)
        if settings.max_touched_arc_deg is not None and arc > settings.max_touched_arc_deg:
            trial.set_user_attr("disqualified", "touched arc")
            raise optuna.TrialPruned(f"a module's skin touched the pole over {arc:.0f} deg")
        value = metrics[settings.objective]
        if math.isnan(value):
            trial.set_user_attr("disqualified", "no climb")
            raise optuna.TrialPruned("no climb: the metric per metre is undefined")
        return value

    return objective


# --- running the study ----------------------------------------------------------------------------

FINISHED = (optuna.trial.TrialState.COMPLETE, optuna.trial.TrialState.PRUNED)


def _counted(study: optuna.Study) -> int:
    """Trials that count toward ``--n-trials``: finished, or running in some process."""
    states = (*FINISHED, optuna.trial.TrialState.RUNNING)
    return len(study.get_trials(deepcopy=False, states=states))


def _sampler(seed: int | None) -> optuna.samplers.TPESampler:
    # constant_liar: workers sharing a study do not all sample next to the same running trial.
    return optuna.samplers.TPESampler(
        n_startup_trials=10, multivariate=True, constant_liar=True, seed=seed
    )


def run_worker(
    settings: TuneSettings,
    storage: str,
    study_name: str,
    quota: int,
    n_trials: int,
    seed: int | None = None,
    callbacks: Sequence[Callable[[optuna.Study, optuna.trial.FrozenTrial], None]] = (),
) -> None:
    """Run up to ``quota`` trials, stopping early once the study holds ``n_trials``."""
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = optuna.load_study(
        study_name=study_name, storage=open_storage(storage), sampler=_sampler(seed)
    )
    objective = make_objective(settings)
    for _ in range(quota):
        _stop_point()
        if _counted(study) >= n_trials:
            break
        study.optimize(objective, n_trials=1, callbacks=list(callbacks))


def _worker_process(*args: Any, **kwargs: Any) -> None:
    """:func:`run_worker` in a spawned process: Ctrl-C (sent to the whole process group) or the
    parent's SIGTERM ends it quietly at the next safe point; Optuna has marked its running trial
    failed, and a rerun redoes it."""
    _catch_stop_signals()
    try:
        run_worker(*args, **kwargs)
    except KeyboardInterrupt:
        pass


# Ctrl-C and SIGTERM are taken only at safe points (:func:`_stop_point`): between env steps of a
# trial, which Optuna then records as failed (a rerun redoes it), or between trials. Raised
# anywhere else, the interrupt could land while a trial's result is being written, leaving it
# RUNNING in the storage (a rerun would count it as another process's and skip it until the
# heartbeat's grace period fails it) or a half-written transaction.
_stop_requested = False


def _request_stop(signum: int, frame: Any) -> None:
    global _stop_requested
    _stop_requested = True


def _catch_stop_signals() -> dict[int, Any]:
    """Route SIGINT and SIGTERM to the stop request; return the previous handlers."""
    global _stop_requested
    _stop_requested = False
    return {sig: signal.signal(sig, _request_stop) for sig in (signal.SIGINT, signal.SIGTERM)}


def _stop_point(*_: Any) -> None:
    """Raise ``KeyboardInterrupt`` here if a stop was requested (also a run_episode callback)."""
    if _stop_requested:
        raise KeyboardInterrupt


def prepare_study(
    settings: TuneSettings, storage: str, study_name: str
) -> tuple[optuna.Study, optuna.storages.RDBStorage]:
    """Create or resume the study; a study run with other settings raises :class:`UsageError`."""
    rdb = open_storage(storage)
    try:
        study = optuna.create_study(
            study_name=study_name,
            storage=rdb,
            direction=settings.direction,
            load_if_exists=True,
        )
    except Exception as exc:
        raise UsageError("--storage", f"cannot use {storage!r}: {exc}".splitlines()[0]) from None
    attrs = settings.as_attrs()
    stored = study.user_attrs.get("settings")
    if stored is None:
        study.set_user_attr("settings", attrs)
        if all(
            settings.space[k].low <= v <= settings.space[k].high for k, v in DEFAULT_PARAMS.items()
        ):
            study.enqueue_trial(DEFAULT_PARAMS, user_attrs={"default_gait": True})
    elif stored != attrs:
        changed = sorted(k for k in attrs if stored.get(k) != attrs[k])
        raise UsageError(
            "--study-name",
            f"study {study_name!r} in {storage} was run with other settings ({', '.join(changed)}"
            "); rerun with the same settings to resume, or name a new study",
        )
    return study, rdb


def run_study(
    settings: TuneSettings,
    storage: str,
    study_name: str,
    n_trials: int,
    n_jobs: int = 1,
    seed: int | None = None,
    progress: bool = True,
) -> optuna.Study:
    """Run the study until it holds ``n_trials`` finished trials, on ``n_jobs`` processes.

    Ctrl-C (or SIGTERM, with :func:`main`'s handler) stops the workers and raises
    ``KeyboardInterrupt``; the finished trials stay in the study for a rerun to resume from.
    """
    study, _ = prepare_study(settings, storage, study_name)
    with warnings.catch_warnings():  # experimental since Optuna 2.9, still there in 4.x
        warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
        optuna.storages.fail_stale_trials(study)
    done = _counted(study)
    bar = tqdm(total=n_trials, initial=done, desc=study_name, unit="trial", disable=not progress)
    seed_base = None if seed is None else seed + 1000 * done

    def update(study: optuna.Study, trial: optuna.trial.FrozenTrial) -> None:
        bar.update()
        bar.set_postfix_str(_best_text(study))

    workers: list[multiprocessing.process.BaseProcess] = []
    try:
        # Enqueued trials (the default gait) run here first: two processes popping the same
        # waiting trial from SQLite can both run it, and the second fails to record it.
        waiting = len(study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.WAITING,)))
        if waiting and done < n_trials:
            run_worker(settings, storage, study_name, waiting, n_trials, seed_base, [update])
        remaining = max(0, n_trials - _counted(study))
        if remaining and n_jobs == 1:
            run_worker(settings, storage, study_name, remaining, n_trials, seed_base, [update])
        elif remaining:
            context = multiprocessing.get_context("spawn")
            quotas = [remaining // n_jobs + (i < remaining % n_jobs) for i in range(n_jobs)]
            workers = [
                context.Process(
                    target=_worker_process,
                    args=(settings, storage, study_name, quota, n_trials),
                    kwargs={"seed": None if seed_base is None else seed_base + 1 + i},
                )
                for i, quota in enumerate(quotas)
                if quota
            ]
            for worker in workers:
                worker.start()
            while any(worker.is_alive() for worker in workers):
                time.sleep(1.0)
                _stop_point()
                finished = len(study.get_trials(deepcopy=False, states=FINISHED))
                bar.update(max(0, finished - bar.n))
                bar.set_postfix_str(_best_text(study))
            failed = [w.exitcode for w in workers if w.exitcode]
            if failed:
                raise RuntimeError(f"tuning workers exited with status {failed}")
    except KeyboardInterrupt:
        for worker in workers:
            worker.terminate()  # SIGTERM: it stops at its next safe point, its trial failed
        for worker in workers:
            worker.join(timeout=60.0)
            if worker.is_alive():  # stuck: its trial stays RUNNING until the heartbeat fails it
                worker.kill()
        raise
    finally:
        bar.close()
    return study


def _best_text(study: optuna.Study) -> str:
    try:
        return f"best {study.best_value:.4g} (trial {study.best_trial.number})"
    except ValueError:
        return "no qualified trial yet"


# --- outputs --------------------------------------------------------------------------------------


def validation_seeds(settings: TuneSettings, n_seeds: int) -> list[int]:
    """Seeds after the largest tuning seed: episodes the search never saw."""
    return [max(settings.seeds) + 1 + i for i in range(n_seeds)]


def validate(
    study: optuna.Study, settings: TuneSettings, top_k: int, n_seeds: int
) -> tuple[optuna.trial.FrozenTrial, dict[int, dict[str, Any]]]:
    """Re-measure the ``top_k`` best trials (and the default gait) on ``n_seeds`` new seeds and
    pick the best on those seeds among the ones that neither fell nor rolled there.

    With a few seeds per trial the study's best is partly luck (and may sit next to a cliff); the
    pick is the gait that holds up on episodes the search never saw. Results are cached in the
    study's user attributes (``validation_<trial>``), so a rerun does not repeat them. Without
    validation (``n_seeds`` 0) the pick is the study's best trial.
    """
    try:
        best = study.best_trial
    except ValueError:
        raise RuntimeError(f"study {study.study_name!r} has no qualified trial yet") from None
    if n_seeds == 0:
        return best, {}
    seeds = validation_seeds(settings, n_seeds)
    sign = 1.0 if settings.direction == "maximize" else -1.0
    complete = study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
    ranked = sorted(complete, key=lambda t: -sign * t.value)
    candidates = ranked[:top_k]
    default = [t for t in complete if t.user_attrs.get("default_gait") and t not in candidates]
    results: dict[int, dict[str, Any]] = {}
    for trial in tqdm([*candidates, *default], desc="validation", unit="gait", leave=False):
        key = f"validation_{trial.number}"
        stored = study.user_attrs.get(key)
        if stored is None or stored["seeds"] != seeds:
            envs = settings.make_envs({k: trial.params[k] for k in settings.space})
            episodes, _ = rollout_all(envs, seeds)
            for env in envs:
                env.close()
            summaries = {m: mean_ci95(e[m] for e in episodes) for m in METRICS}
            stored = {
                "seeds": seeds,
                "episodes": len(episodes),
                "fell": any(e["falls"] for e in episodes),
                "rolled": any(e["rolled"] for e in episodes),
                "max_touched_arc_deg": max(e["touched_arc_deg"] for e in episodes),
                "metrics": {m: summary["mean"] for m, summary in summaries.items()},
                "ci95_half_width": {m: summary["half_width"] for m, summary in summaries.items()},
            }
            study.set_user_attr(key, jsonable(stored))
        results[trial.number] = {**stored, "candidate": trial in candidates}

    def holds(trial: optuna.trial.FrozenTrial) -> bool:
        result = results[trial.number]
        arc_limit = settings.max_touched_arc_deg
        return not (result["fell"] or result.get("rolled")) and (
            arc_limit is None or result["max_touched_arc_deg"] <= arc_limit
        )

    def validated_value(trial: optuna.trial.FrozenTrial) -> float:
        value = results[trial.number]["metrics"][settings.objective]
        return -math.inf if value is None or math.isnan(value) else sign * value

    holding = [t for t in candidates if holds(t)]
    chosen = max(holding, key=validated_value) if holding else best
    return chosen, results


def tuned_entry(
    study: optuna.Study,
    settings: TuneSettings,
    chosen: optuna.trial.FrozenTrial,
    validation: Mapping[int, dict[str, Any]],
) -> dict[str, Any]:
    """The YAML entry for the chosen trial (see the module docstring for the format)."""
    finished = study.get_trials(deepcopy=False, states=FINISHED)
    default = next((t for t in finished if t.user_attrs.get("default_gait")), None)
    params = {k: chosen.params[k] for k in settings.space}
    entry: dict[str, Any] = {
        "env_id": settings.env_id,
        "env_kwargs": settings.env_kwargs(params),
        "objective": settings.objective,
        "reward_weights": dict(settings.reward_weights),
        "seeds": list(settings.seeds),
        "steps_per_cycle": settings.steps_per_cycle,
        "cycles_per_episode": settings.cycles_per_episode,
        **({"condition": dict(settings.condition)} if settings.condition else {}),
        "trials": len(finished),
        "best_trial": chosen.number,
        "study": study.study_name,
        "metrics": {m: chosen.user_attrs.get(m) for m in METRICS},
    }
    if chosen.number in validation:
        candidates = sum(result["candidate"] for result in validation.values())
        entry["validation"] = _validation_entry(validation[chosen.number], candidates)
    if default is not None:
        entry["default_gait_metrics"] = {m: default.user_attrs.get(m) for m in METRICS}
        if "disqualified" in default.user_attrs:
            entry["default_gait_disqualified"] = default.user_attrs["disqualified"]
        if default.number in validation:
            entry["default_gait_validation"] = _validation_entry(validation[default.number])
    return entry


def _validation_entry(result: dict[str, Any], candidates: int | None = None) -> dict[str, Any]:
    out = {
        "seeds": result["seeds"],
        "fell": result["fell"],
        "rolled": result.get("rolled", False),
        "metrics": result["metrics"],
        "ci95_half_width": result["ci95_half_width"],
    }
    if candidates is not None:
        out["candidates"] = candidates
    return out


def write_tuned_gaits(path: str | Path, key: str, entry: dict[str, Any]) -> None:
    """Replace ``key`` in the tuned-gaits file at ``path`` (:func:`acl_env.tuned_gaits.write`)."""
    tuned_gaits.write(path, key, entry)


def read_tuned_gaits(path: str | Path = DEFAULT_OUTPUT) -> dict[str, dict[str, Any]]:
    """The tuned gaits by key (:func:`acl_env.tuned_gaits.read`)."""
    return tuned_gaits.read(path)


POINT_METRICS = ("energy_per_m", "climb_per_gait_cycle_m", "slip_per_m")
# The frontier figure's panels: y metric, axis label, whether more is better (x: energy, less).
FRONTIER_PANELS = (
    ("climb_per_gait_cycle_m", "climb per gait cycle (m)", True),
    ("slip_per_m", "slip per metre climbed", False),
)


def policy_point(path: str | Path, controller: str = "policy") -> dict[str, float]:
    """Energy, climb and slip means (:data:`POINT_METRICS`) of one controller of an evaluation
    JSON; a metric the JSON lacks is NaN (not drawn)."""
    import json

    summary = json.loads(Path(path).read_text())["controllers"][controller]
    point = {m: float(summary[m]["mean"]) if m in summary else math.nan for m in POINT_METRICS}
    if not math.isfinite(point["energy_per_m"]):
        raise KeyError(f"{controller} has no energy_per_m")
    return point


def pareto_front(points: np.ndarray, maximize: bool = True) -> np.ndarray:
    """Points ``(energy, y)`` that no other point beats on both (less energy, more ``y``, or less
    with ``maximize=False``), sorted by energy."""
    sign = 1.0 if maximize else -1.0
    order = np.argsort(points[:, 0], kind="stable")
    front, best = [], -np.inf
    for i in order:
        if sign * points[i, 1] > best:
            front.append(i)
            best = sign * points[i, 1]
    return points[front]


def plot_frontier(
    study: optuna.Study,
    settings: TuneSettings,
    path: str | Path,
    title: str,
    chosen: optuna.trial.FrozenTrial | None = None,
    policies: Sequence[tuple[str, Mapping[str, float]]] = (),
    others: Sequence[optuna.Study] = (),
) -> None:
    """Every trial's climb per gait cycle (left) and slip per metre (right) against its energy
    per metre: the open-loop frontiers, with labelled policy points
    (:func:`policy_point`) where a learned controller lands.

    ``others``: studies (of other objectives or ranges) whose qualified gaits join the frontier,
    drawn in grey.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    trials = study.get_trials(deepcopy=False, states=FINISHED)
    complete = [t for t in trials if t.state == optuna.trial.TrialState.COMPLETE]
    measured_out = [
        t for t in trials if t.user_attrs.get("disqualified") in ("fell", "rolled", "touched arc")
    ]
    extra_trials = [
        t
        for other in others
        for t in other.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
    ]
    default = next((t for t in complete if t.user_attrs.get("default_gait")), None)
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), constrained_layout=True)
    colours = ("tab:orange", "tab:pink", "tab:cyan", "tab:brown")
    for ax, (metric, label, maximize) in zip(axes, FRONTIER_PANELS, strict=True):

        def point(t: optuna.trial.FrozenTrial, metric: str = metric) -> tuple[float, float]:
            return t.user_attrs.get("energy_per_m", math.nan), t.user_attrs.get(metric, math.nan)

        def finite(ts: list[optuna.trial.FrozenTrial]) -> np.ndarray:
            pts = np.array([point(t) for t in ts], dtype=float).reshape(-1, 2)
            return pts[np.all(np.isfinite(pts), axis=1) & (pts[:, 0] > 0)]

        ok = finite(complete)
        values = [t.value for t in complete if np.all(np.isfinite(point(t))) and point(t)[0] > 0]
        if len(ok):
            # Colours span the better 90 % of the gaits: one bad outlier would wash out the rest.
            low, high = np.percentile(values, [10.0, 100.0])
            if settings.direction == "minimize":
                low, high = np.percentile(values, [0.0, 90.0])
            sc = ax.scatter(
                ok[:, 0], ok[:, 1], c=values, s=14, cmap="viridis", vmin=low, vmax=high, zorder=2
            )
            if ax is axes[-1]:
                extend = "min" if settings.direction == "maximize" else "max"
                fig.colorbar(sc, ax=ax, label=settings.objective, extend=extend)
        extra = finite(extra_trials)
        if len(extra):
            names = ", ".join(other.study_name for other in others)
            ax.scatter(
                extra[:, 0],
                extra[:, 1],
                s=14,
                facecolors="none",
                edgecolors="0.55",
                lw=0.7,
                label=f"studies {names}",
                zorder=1,
            )
        if len(ok) or len(extra):
            front = pareto_front(np.vstack([ok, extra]), maximize)
            ax.step(front[:, 0], front[:, 1], where="post", color="0.3", lw=1, label="frontier")
        out = finite(measured_out)
        if len(out):
            label_out = "disqualified: fell or rolled"
            ax.scatter(out[:, 0], out[:, 1], marker="x", s=14, color="0.6", label=label_out)
        if default is not None:
            ax.scatter(*point(default), marker="s", s=60, color="k", label="default gait", zorder=3)
        if chosen is not None:
            ax.scatter(*point(chosen), marker="*", s=200, color="tab:red", label="tuned", zorder=4)
        marked = [point(t) for t in (default, chosen) if t is not None]
        for (name, values_), colour in zip(policies, itertools.cycle(colours)):
            xy = (values_["energy_per_m"], values_[metric])
            if all(math.isfinite(v) for v in xy):
                ax.scatter(*xy, marker="^", s=90, color=colour, label=name, zorder=5)
                marked.append(xy)
        # Axes around the better gaits (the frontier's side): far-off bad gaits only squash them.
        shown = np.vstack([ok, extra, out, np.array(marked, dtype=float).reshape(-1, 2)])
        shown = shown[np.all(np.isfinite(shown), axis=1) & (shown[:, 0] > 0)]
        beyond = 0
        if len(ok) >= 10:
            x_hi = max([np.percentile(ok[:, 0], 90) * 1.3, *(1.1 * m[0] for m in marked)])
            if maximize:
                y_lo = min([np.percentile(ok[:, 1], 10), *(m[1] for m in marked)])
                y_hi = shown[:, 1].max()
                beyond = int(np.sum((shown[:, 0] > x_hi) | (shown[:, 1] < y_lo)))
            else:
                y_hi = max([np.percentile(ok[:, 1], 90), *(m[1] for m in marked)])
                y_lo = shown[:, 1].min()
                beyond = int(np.sum((shown[:, 0] > x_hi) | (shown[:, 1] > y_hi)))
            pad = 0.05 * (y_hi - y_lo)
            ax.set_xlim(shown[:, 0].min() / 1.1, x_hi)
            ax.set_ylim(y_lo - pad, y_hi + pad)
        hidden = len(trials) - len(ok) - len(out)
        clip = f"{settings.max_clipped:.0%}"
        note = f"not shown: {hidden} gaits that did not climb\nor clipped over {clip} of the joints"
        if beyond:
            note += f";\n{beyond} beyond the axes"
        ax.plot([], [], " ", label=note)  # in the legend, which finds a place clear of the points
        lo, hi = ax.get_xlim()
        if hi / lo > 10.0:  # a log axis only where the energies span more than a decade
            ax.set_xscale("log")
            ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax.set_xlabel("energy per metre climbed (J/m)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7, loc="best")
    fig.suptitle(title, fontsize=9)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


# --- command line ---------------------------------------------------------------------------------


def make_parser() -> cli.ArgumentParser:
    """Command line (paths relative to the repository root, where it is meant to run)."""
    parser = cli.ArgumentParser(
        prog="acl-tune-gait",
        description="Tune the open-loop ACL gait with Optuna (parallel, resumable).",
    )
    positive = cli.int_at_least(1)
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
        help="env reward weights (default: the training config's)",
    )
    parser.add_argument(
        "--condition",
        nargs="*",
        default=[],
        metavar="NAME:VALUE",
        help=f"play every trial under this condition instead of the env's default, NAME one of "
        f"{list(CONDITIONS)} (e.g. friction:0.5)",
    )
    parser.add_argument("--config", default=str(DEFAULT_CONFIG), help="training config (zoo YAML)")
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
    parser.add_argument("--steps-per-cycle", type=cli.int_at_least(2), default=220)
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
        type=cli.int_at_least(0),
        default=10,
        help="new seeds on which the best trials are re-measured before one is picked (0: none)",
    )
    parser.add_argument(
        "--validate-top", type=positive, default=5, help="how many of the best trials to re-measure"
    )
    parser.add_argument(
        "--space", nargs="*", default=[], metavar="NAME:LOW:HIGH", help="search range overrides"
    )
    parser.add_argument("--output", default=str(DEFAULT_OUTPUT), help="tuned gaits YAML")
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
        except (OSError, KeyError, yaml.YAMLError) as exc:
            raise UsageError("--config", str(exc).splitlines()[0]) from None
        weights = dict((hyperparams.get("env_kwargs") or {}).get("reward_weights") or {})
    else:
        try:
            weights = parse_kv_pairs(args.reward_weights)
        except ValueError as exc:
            raise UsageError("--reward-weights", str(exc)) from None
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
    previous = _catch_stop_signals()
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
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    try:
        chosen, validation = validate(study, settings, args.validate_top, args.validate_seeds)
    except RuntimeError as exc:
        print(f"acl-tune-gait: {exc}; nothing written", file=sys.stderr)
        raise SystemExit(1) from None
    entry = tuned_entry(study, settings, chosen, validation)
    write_tuned_gaits(args.output, key, entry)
    print(dump_yaml({key: entry}), end="")
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
run = cli.script(main)


if __name__ == "__main__":
    main()
