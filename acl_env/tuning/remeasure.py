"""Re-measuring the best trials on new seeds, and the tuned-gaits entry of the chosen one.

With a few seeds per trial the study's best is partly luck, and good gaits sit near a cliff where
the grip gives way; so the best few trials (and the default gait) are measured again on new seeds,
and the tuned gait is the best of them on those seeds among the ones that did not fall (nor roll,
nor touch the pole over ``max_touched_arc_deg``) there. The entry's format is documented in
:mod:`acl_env.tuned_gaits`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import optuna
from tqdm import tqdm

from acl_env.evaluation import METRICS, mean_ci95
from acl_env.io import jsonable
from acl_env.tuning.objective import TuneSettings, condition_scores, cvar, margins, rollout_all
from acl_env.tuning.study import FINISHED


def validation_seeds(settings: TuneSettings, n_seeds: int) -> list[int]:
    """Seeds after the largest tuning seed: episodes the search never saw."""
    return [max(settings.seeds) + 1 + i for i in range(n_seeds)]


def validate(
    study: optuna.Study,
    settings: TuneSettings,
    top_k: int,
    n_seeds: int,
    progress: bool = True,
) -> tuple[optuna.trial.FrozenTrial, dict[int, dict[str, Any]]]:
    """Re-measure the ``top_k`` best trials (and the default gait) on ``n_seeds`` new seeds and
    pick the best on those seeds among the ones that neither fell nor rolled there (a progress
    bar unless ``progress`` is False).

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
    measured = [*candidates, *default]
    for trial in tqdm(measured, desc="validation", unit="gait", leave=False, disable=not progress):
        key = f"validation_{trial.number}"
        stored = study.user_attrs.get(key)
        if stored is None or stored["seeds"] != seeds:
            stored = _measure(settings, trial, seeds)
            study.set_user_attr(key, jsonable(stored))
        results[trial.number] = {**stored, "candidate": trial in candidates}

    def holds(trial: optuna.trial.FrozenTrial) -> bool:
        result = results[trial.number]
        if settings.cvar is not None:  # its falls are in its score
            return True
        arc_limit = settings.max_touched_arc_deg
        return not (result["fell"] or result.get("rolled")) and (
            arc_limit is None or result["max_touched_arc_deg"] <= arc_limit
        )

    def validated_value(trial: optuna.trial.FrozenTrial) -> float:
        result = results[trial.number]
        value = (
            result["cvar"] if settings.cvar is not None else result["metrics"][settings.objective]
        )
        return -math.inf if value is None or math.isnan(value) else sign * value

    holding = [t for t in candidates if holds(t)]
    chosen = max(holding, key=validated_value) if holding else best
    return chosen, results


def _measure(
    settings: TuneSettings, trial: optuna.trial.FrozenTrial, seeds: list[int]
) -> dict[str, Any]:
    """``trial``'s gait played on ``seeds`` in every condition: its metrics' means and 95 %
    half-widths, whether it fell or rolled, its largest touched arc; under ``--cvar`` also each
    condition's score and their CVaR."""
    envs = settings.make_envs({k: trial.params[k] for k in settings.space})
    if settings.cvar is None:
        episodes, _ = rollout_all(envs, seeds)
    else:  # risk-averse: every condition played, falls scored, not disqualifying
        scores, episodes, _ = condition_scores(settings, envs, seeds)
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
    if settings.cvar is not None:
        scored = margins(settings, scores, seeds)
        stored["cvar"] = cvar(scored, settings.cvar)
        stored["condition_scores"] = scores
        if settings.against_default:
            stored["condition_margins"] = scored
    return stored


def tuned_entry(
    study: optuna.Study,
    settings: TuneSettings,
    chosen: optuna.trial.FrozenTrial,
    validation: Mapping[int, dict[str, Any]],
) -> dict[str, Any]:
    """The tuned-gaits entry for the chosen trial (format: :mod:`acl_env.tuned_gaits`)."""
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
        **({"cvar": settings.cvar} if settings.cvar is not None else {}),
        **({"against_default": True} if settings.against_default else {}),
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
