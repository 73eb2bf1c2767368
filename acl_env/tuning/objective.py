"""What a trial measures: the study's settings, the open-loop rollouts, and the Optuna objective.

Each trial builds the env with a candidate squeeze and ``gait_kwargs``, plays it open loop (zero
action: one keyframe per step, the gait's own cadence) on a few seeds in each condition, and
scores it by one evaluation metric (mean over the episodes). A gait that falls (or ends by
``roll_limit``) on any seed, whose keyframe table the +-90 deg joint limit clips in more than
``max_clipped`` of its (keyframe, joint) entries (not in a grip study, whose gait is fixed), or
(with ``max_touched_arc_deg``) that touches the pole over more than that arc of some module's
circumference, is disqualified: the trial is
pruned, its reason in the user attribute ``disqualified``. Every trial stores its metrics
(:mod:`acl_env.evaluation`, mean over its episodes) as user attributes.
"""

from __future__ import annotations

import itertools
import math
import os
import socket
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import gymnasium
import optuna

from acl_env import ACL_CLIMB_ID
from acl_env.constants import DEFAULT_STEPS_PER_CYCLE
from acl_env.evaluation import METRICS, mean_ci95, run_episode, zero_policy
from acl_env.tuning.space import (
    DEFAULT_PARAMS,
    ENV_PARAMS,
    GRIP_DEFAULT_PARAMS,
    SEARCH_SPACE,
    ParamRange,
)
from acl_env.tuning.stop import stop_point

DEFAULT_SEEDS = (0, 1, 2)
# What a condition where the gait falls (or rolls past roll_limit) scores under --cvar: worse than
# any gait that holds on (a fall ends the episode at 0.2 m below the start, about -0.1 m per cycle
# at most for a gait that slides down without falling; reward per gait cycle is of that order).
FALL_SCORE = -1.0
# Metrics a study can optimise, with their direction (names as in acl_env.evaluation).
OBJECTIVES = {
    "reward_per_gait_cycle": "maximize",
    "climb_per_gait_cycle_m": "maximize",
    "slip_per_m": "minimize",
    "energy_per_m": "minimize",
}


@dataclass(frozen=True)
class TuneSettings:
    """What defines a study: changing any of these needs a new study name."""

    env_id: str = ACL_CLIMB_ID
    objective: str = "reward_per_gait_cycle"
    reward_weights: dict[str, float] = field(default_factory=dict)
    rolls_per_cycle: int = 1
    seeds: tuple[int, ...] = DEFAULT_SEEDS
    steps_per_cycle: int = DEFAULT_STEPS_PER_CYCLE
    cycles_per_episode: int = 2
    max_clipped: float = 0.1
    max_touched_arc_deg: float | None = None
    space: dict[str, ParamRange] = field(default_factory=lambda: dict(SEARCH_SPACE))
    condition: dict[str, float | list[float]] = field(default_factory=dict)
    grip: bool = False  # search the compliant grip (GRIP_SPACE) on the env's own gait
    # Risk-averse: score the mean of the worst ``cvar`` share of the conditions (CVaR), a fall
    # counting as FALL_SCORE, instead of the mean with falls disqualifying.
    cvar: float | None = None
    # Under ``cvar``: score each condition by the margin over the default gait's score there,
    # on the same seeds (a gait at least as good as the untuned one in every condition scores
    # a CVaR of at least 0).
    against_default: bool = False

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
        if not self.grip:  # nor do those from before --grip
            del out["grip"]
        if self.cvar is None:  # nor those from before --cvar
            del out["cvar"]
        if not self.against_default:  # nor those from before --against-default
            del out["against_default"]
        return out

    @property
    def default_params(self) -> dict[str, float]:
        """The study's trial 0: the untuned gait, or for a grip study the open loop (no gain)."""
        return dict(GRIP_DEFAULT_PARAMS if self.grip else DEFAULT_PARAMS)

    def env_kwargs(self, params: Mapping[str, float]) -> dict[str, Any]:
        """Env arguments that play the gait ``params`` (squeeze and ``gait_kwargs``), or the
        grip ``params`` on the env's own gait."""
        if self.grip:
            return dict(params)
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
        if not self.grip:  # the trial's gait replaces a tuned gait the id plays (ACLClimb-v3)
            kwargs["tuned_gait"] = None
        return [gymnasium.make(self.env_id, **kwargs, **c) for c in self.conditions()]


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
            physics, actuator = env.unwrapped.config.physics, env.unwrapped.config.actuator
            stiffness = actuator.model.stiffness
            where += f" at pole {physics.pole_radius} m, friction {physics.friction}, "
            where += f"{stiffness} {actuator.values[stiffness]}"
        if runs[-1]["falls"] or runs[-1]["rolled"]:
            break
    return episodes, where


def rollout(env: gymnasium.Env, seeds: Sequence[int]) -> list[dict[str, float]]:
    """Per-episode metrics of the open-loop gait (zero action) on ``seeds``, in order, plus
    ``rolled`` (1 if the env's ``roll_limit`` ended the episode); stops after the first fall or
    roll (either disqualifies the gait anyway)."""
    episodes = []
    for seed in seeds:
        episode = run_episode(env, zero_policy(env), seed, stop_point)
        episodes.append({**episode.metrics(), "rolled": float(episode.rolled)})
        if episode.fell or episode.rolled:
            break
    return episodes


def cvar(scores: Sequence[float], share: float) -> float:
    """The mean of the worst ``share`` of ``scores`` (higher is better): CVaR at level
    ``share``, over at least one score."""
    worst = sorted(scores)[: max(1, math.ceil(share * len(scores) - 1e-9))]
    return sum(worst) / len(worst)


def condition_scores(
    settings: TuneSettings, envs: Sequence[gymnasium.Env], seeds: Sequence[int]
) -> tuple[list[float], list[dict[str, float]], int]:
    """Each condition's (env's) score: the mean of the objective over ``seeds``, or
    :data:`FALL_SCORE` if the gait fell or rolled there; with every episode and how many
    conditions the gait fell in. Every condition is played."""
    scores, episodes, fallen = [], [], 0
    for env in envs:
        runs = rollout(env, seeds)
        episodes += runs
        if runs[-1]["falls"] or runs[-1]["rolled"]:
            scores.append(FALL_SCORE)
            fallen += 1
            continue
        score = mean_ci95(r[settings.objective] for r in runs)["mean"]
        scores.append(FALL_SCORE if math.isnan(score) else score)
    return scores, episodes, fallen


_DEFAULT_SCORES: dict[tuple[str, tuple[int, ...]], list[float]] = {}


def default_scores(settings: TuneSettings, seeds: Sequence[int]) -> list[float]:
    """The default gait's :func:`condition_scores` on ``seeds`` (played once per process)."""
    key = (repr(settings), tuple(seeds))
    if key not in _DEFAULT_SCORES:
        envs = settings.make_envs(settings.default_params)
        try:
            _DEFAULT_SCORES[key] = condition_scores(settings, envs, seeds)[0]
        finally:
            for env in envs:
                env.close()
    return _DEFAULT_SCORES[key]


def margins(settings: TuneSettings, scores: Sequence[float], seeds: Sequence[int]) -> list[float]:
    """``scores`` as scored under ``--cvar``: each condition's own, or with
    ``against_default`` its margin over the default gait's there (:func:`default_scores`; 0
    where the default gait falls, so a gait that falls there too scores :data:`FALL_SCORE`)."""
    if not settings.against_default:
        return list(scores)
    # Where the default gait falls it climbs nothing: a gait that falls there too scores a fall.
    reference = [0.0 if d == FALL_SCORE else d for d in default_scores(settings, seeds)]
    return [s - d for s, d in zip(scores, reference, strict=True)]


def risk_averse_value(
    trial: optuna.Trial, settings: TuneSettings, envs: Sequence[gymnasium.Env]
) -> float:
    """A trial's value under ``--cvar``: the :func:`cvar` of its :func:`condition_scores` (or
    of their :func:`margins` over the default gait's). The scores (and margins), the conditions
    fallen in and the metrics' means over all episodes are the trial's user attributes."""
    scores, episodes, fallen = condition_scores(settings, envs, settings.seeds)
    for name in METRICS:
        trial.set_user_attr(name, mean_ci95(e[name] for e in episodes)["mean"])
    trial.set_user_attr("seeds_run", len(episodes))
    trial.set_user_attr("condition_scores", scores)
    trial.set_user_attr("conditions_fallen", fallen)
    scored = margins(settings, scores, settings.seeds)
    if settings.against_default:
        trial.set_user_attr("condition_margins", scored)
    return cvar(scored, settings.cvar or 1.0)


def suggest_params(trial: optuna.Trial, space: Mapping[str, ParamRange]) -> dict[str, float]:
    """The trial's gait parameters from the search space."""
    params: dict[str, float] = {}
    for name, r in space.items():
        if r.integer:
            params[name] = trial.suggest_int(name, int(r.low), int(r.high))
        else:
            params[name] = trial.suggest_float(name, r.low, r.high)
    return params


def make_objective(settings: TuneSettings, heartbeat: int = 0) -> Callable[[optuna.Trial], float]:
    """Optuna objective: the mean of ``settings.objective`` over the seeds (and conditions),
    falls disqualifying; with ``settings.cvar``, :func:`risk_averse_value`. A trial records its
    worker (``host:pid``) and, if its storage beats (:mod:`~acl_env.tuning.study`), the
    ``heartbeat`` interval: other workers wait for it."""

    def objective(trial: optuna.Trial) -> float:
        if heartbeat:
            trial.set_user_attr("heartbeat", heartbeat)
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
            # With --grip the gait is held fixed, the same in every trial: its clipping is no
            # reason to prefer one grip over another.
            if not settings.grip and saturation.sample_fraction > settings.max_clipped:
                trial.set_user_attr("disqualified", "saturated")
                raise optuna.TrialPruned(f"joint limit clips {saturation.sample_fraction:.0%}")
            if settings.cvar is not None:
                return risk_averse_value(trial, settings, envs)
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
