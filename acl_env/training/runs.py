"""Run folders: the files a training run writes, and finding the newest model in one."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

MODEL_FILE = "model.zip"
VECNORMALIZE_FILE = "vecnormalize.pkl"
CONFIG_FILE = "config.yml"
ARGS_FILE = "args.json"
SUMMARY_FILE = "summary.json"
CHECKPOINT_DIR = "checkpoints"
CHECKPOINT_PREFIX = "model"


# --- run folders ---------------------------------------------------------------------------------


def latest_model(run_dir: str | Path) -> tuple[Path, Path | None]:
    """The newest ``(model.zip, vecnormalize.pkl)`` pair in a run folder or a policy folder.

    Candidates are the final/interrupted ``model.zip`` and the checkpoints; the most recently
    written wins. The VecNormalize path is None when the run did not normalise.
    """
    run_dir = Path(run_dir)
    pairs = [(run_dir / MODEL_FILE, run_dir / VECNORMALIZE_FILE)]
    for model in (run_dir / CHECKPOINT_DIR).glob(f"{CHECKPOINT_PREFIX}_*_steps.zip"):
        steps = model.stem.removeprefix(f"{CHECKPOINT_PREFIX}_")
        pairs.append((model, model.with_name(f"{CHECKPOINT_PREFIX}_vecnormalize_{steps}.pkl")))
    pairs = [pair for pair in pairs if pair[0].is_file()]
    if not pairs:
        raise FileNotFoundError(f"no {MODEL_FILE} or checkpoint in {run_dir}")
    model, vecnorm = max(pairs, key=lambda pair: pair[0].stat().st_mtime_ns)
    return model, vecnorm if vecnorm.is_file() else None


def run_config(run_dir: str | Path) -> tuple[str, dict[str, Any]] | None:
    """``(env_id, hyperparams)`` from a run folder's ``config.yml``, or None if it has none."""
    path = Path(run_dir) / CONFIG_FILE
    if not path.is_file():
        return None
    with open(path) as f:
        configs = yaml.safe_load(f)
    ((env_id, hyperparams),) = configs.items()
    return env_id, dict(hyperparams)
