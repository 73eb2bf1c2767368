"""Where a training segment starts (:class:`Start`): the recipe of a new run (:func:`new_start`),
or the run a resume continues (:func:`resumed_start`), its history, newest model and statistics,
and the steps it trains (:func:`resumed_steps`). Every argument and file is checked; nothing is
written.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from acl_env import ACL_CLIMB_SEA_ID
from acl_env.io import read_json
from acl_env.training.arguments import DEFAULT_CONFIG, DEFAULT_SETTINGS, RECIPE_OPTIONS
from acl_env.training.config import RecipeError, load_hyperparams, normalize_kwargs
from acl_env.training.plan_checks import bad_argument, check_saved_model, check_trusted
from acl_env.training.runs import (
    ARGS_FILE,
    CONFIG_FILE,
    SUMMARY_FILE,
    VECNORMALIZE_FILE,
    is_pickle,
    latest_model,
    model_steps,
    run_config,
)


@dataclass
class Start:
    """Where a segment starts: its recipe (and where it was read, for messages) and, for a
    resume, the run it continues, that run's newest model and statistics and its history."""

    env_id: str
    hyperparams: dict[str, Any]
    source: str
    run_dir: Path | None = None
    model_path: Path | None = None
    vecnorm_path: Path | None = None
    history: dict[str, Any] = field(default_factory=dict)
    segment: int = 0


def new_start(args: argparse.Namespace) -> Start:
    """The recipe of a new run: ``--config``'s entry for ``--env`` (or their defaults)."""
    config_path = Path(args.config) if args.config else DEFAULT_CONFIG
    if not config_path.is_file():
        raise bad_argument("--config", f"no such file {str(config_path)!r}")
    env_id = args.env or _only_entry(config_path) or ACL_CLIMB_SEA_ID
    try:
        hyperparams = load_hyperparams(config_path, env_id)
    except KeyError as error:
        raise bad_argument("--env", str(error.args[0])) from None
    except RecipeError as error:
        raise bad_argument("--config", str(error)) from None
    except (yaml.YAMLError, ValueError, TypeError, AttributeError) as error:
        raise bad_argument("--config", f"{config_path} is not a zoo config ({error})") from None
    if args.exp_name and not args.exp_name.replace("-", "").replace("_", "").isalnum():
        raise bad_argument(
            "--exp-name", f"letters, digits, '-' and '_' only, got {args.exp_name!r}"
        )
    return Start(env_id, hyperparams, f"{config_path} entry {env_id}")


def _only_entry(config_path: Path) -> str | None:
    """The env id of a recipe file with one entry (an experiment's ``recipe.yml``), else None."""
    try:
        entries = [k for k in (yaml.safe_load(config_path.read_text()) or {}) if k[:1] != "."]
    except (yaml.YAMLError, OSError, TypeError, AttributeError):
        return None  # reported as a bad --config below
    return entries[0] if len(entries) == 1 else None


def resumed_start(args: argparse.Namespace, settings: dict[str, Any]) -> Start:
    """The run ``--resume`` continues, checked; ``settings`` updated with the run's own."""
    given = [f"--{name.replace('_', '-')}" for name in RECIPE_OPTIONS if getattr(args, name)]
    if given:
        raise bad_argument(
            given[0], "cannot change a resumed run's recipe; start a new run instead"
        )
    run_dir = Path(args.resume)
    if not run_dir.is_dir():
        raise bad_argument("--resume", f"no run folder {str(run_dir)!r}")
    check_trusted("--resume", run_dir, args.trust_pickles)
    env_id, hyperparams = _resumed_config(run_dir)
    record, history = _run_history(run_dir)
    settings.update(
        {
            k: v
            for k, v in (record.get("settings") or record.get("args") or {}).items()
            if k in DEFAULT_SETTINGS and v is not None
        }
    )
    try:
        model_path, vecnorm_path = latest_model(run_dir)
    except (FileNotFoundError, ValueError) as error:
        raise bad_argument("--resume", str(error)) from None
    return Start(
        env_id,
        hyperparams,
        f"{run_dir / CONFIG_FILE}",
        run_dir,
        model_path,
        vecnorm_path,
        history,
        segment=max(len(history.get("segments", [])), 1 if history else 0),
    )


def _resumed_config(run_dir: Path) -> tuple[str, dict[str, Any]]:
    """``(env_id, hyperparams)`` of the run to resume (:func:`runs.run_config`), or refused."""
    try:
        config = run_config(run_dir)
    except ValueError as error:
        raise bad_argument("--resume", str(error)) from None
    if config is None:
        raise bad_argument("--resume", f"{run_dir / CONFIG_FILE} is missing")
    return config


def _run_history(run_dir: Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """``(args.json, summary.json)`` of a run, each ``{}`` when absent."""
    documents = []
    for name in (ARGS_FILE, SUMMARY_FILE):
        path = run_dir / name
        try:
            documents.append(read_json(path) if path.is_file() else {})
        except ValueError as error:
            raise bad_argument("--resume", str(error)) from None
        if not isinstance(documents[-1], dict):
            raise bad_argument("--resume", f"{path} is not a JSON object")
    return documents[0], documents[1]


def resumed_steps(
    args: argparse.Namespace, start: Start, hyperparams: dict[str, Any], total: int
) -> tuple[int, Path | None]:
    """The steps a resume trains (``--n-timesteps``, or the rest of the run's ``total``), its
    saved model checked, and the statistics the trainer reloads (the pickle beside an ``.npz``)."""
    model_path, vecnorm_path = start.model_path, start.vecnorm_path
    assert model_path is not None
    check_saved_model(model_path, vecnorm_path, normalize_kwargs(hyperparams) is not None)
    if vecnorm_path is not None and not is_pickle(vecnorm_path):
        # The trainer reloads the VecNormalize itself from the pickle beside the npz.
        vecnorm_path = vecnorm_path.with_suffix(Path(VECNORMALIZE_FILE).suffix)
        if not vecnorm_path.is_file():
            raise bad_argument("--resume", f"{vecnorm_path} is missing: a resume reloads it")
        check_saved_model(model_path, vecnorm_path, True)
    try:
        trained = model_steps(model_path)
    except ValueError as error:
        raise bad_argument("--resume", str(error)) from None
    if args.n_timesteps is not None:
        return args.n_timesteps, vecnorm_path
    if total - trained <= 0:
        raise bad_argument(
            "--n-timesteps",
            f"the run has trained {trained} of its {total} steps; "
            "pass --n-timesteps N to train N more",
        )
    return total - trained, vecnorm_path
