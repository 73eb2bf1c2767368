"""Run folders: the files a training run writes, and finding the newest model in one."""

from __future__ import annotations

import io
import json
import pickle
import zipfile
from pathlib import Path
from typing import Any

import yaml

# The one JSON writer and reader are acl_env.io's, re-exported here for the commands.
from acl_env.io import atomic_write as atomic_write
from acl_env.io import read_json as read_json
from acl_env.io import write_json as write_json

MODEL_FILE = "model.zip"
VECNORMALIZE_FILE = "vecnormalize.pkl"
CONFIG_FILE = "config.yml"
ARGS_FILE = "args.json"
SUMMARY_FILE = "summary.json"
CHECKPOINT_DIR = "checkpoints"
CHECKPOINT_PREFIX = "model"


# --- run folders ---------------------------------------------------------------------------------


def model_steps(model: Path) -> int:
    """Env steps a saved SB3 model had trained: a checkpoint's from its file name, any other
    zip's from its ``data`` record (``num_timesteps``); ``ValueError`` naming the file when it
    has neither."""
    prefix = f"{CHECKPOINT_PREFIX}_"
    if model.parent.name == CHECKPOINT_DIR and model.stem.startswith(prefix):
        steps = model.stem.removeprefix(prefix).removesuffix("_steps")
        if steps.isdigit():
            return int(steps)
    try:
        with zipfile.ZipFile(model) as archive:
            return int(json.loads(archive.read("data"))["num_timesteps"])
    except (zipfile.BadZipFile, KeyError, ValueError, TypeError) as error:
        raise ValueError(f"{model}: not an SB3 model with a step count ({error})") from None


def latest_model(run_dir: str | Path) -> tuple[Path, Path | None]:
    """The ``(model.zip, vecnormalize.pkl)`` pair that trained furthest in a run or policy folder.

    Candidates are the final/interrupted ``model.zip`` and the checkpoints, ranked by the env
    steps they had trained (:func:`model_steps`), ``model.zip`` winning a tie. Not by file times:
    a copied folder (``cp -r``, a checkout, an archive) gives every file a new one, and a resume
    would then silently restart from an older checkpoint. The VecNormalize path is None when the
    run did not normalise.
    """
    run_dir = Path(run_dir)
    pairs = [(run_dir / MODEL_FILE, run_dir / VECNORMALIZE_FILE)]
    for model in (run_dir / CHECKPOINT_DIR).glob(f"{CHECKPOINT_PREFIX}_*_steps.zip"):
        steps = model.stem.removeprefix(f"{CHECKPOINT_PREFIX}_")
        pairs.append((model, model.with_name(f"{CHECKPOINT_PREFIX}_vecnormalize_{steps}.pkl")))
    pairs = [pair for pair in pairs if pair[0].is_file()]
    if not pairs:
        raise FileNotFoundError(f"no {MODEL_FILE} or checkpoint in {run_dir}")
    # max keeps the first of equals: model.zip, listed first, wins a tie.
    model, vecnorm = max(pairs, key=lambda pair: model_steps(pair[0]))
    return model, vecnorm if vecnorm.is_file() else None


def run_config(run_dir: str | Path) -> tuple[str, dict[str, Any]] | None:
    """``(env_id, hyperparams)`` from a run folder's ``config.yml`` (a zoo config with one env
    entry), or None if it has none; ``ValueError`` naming the file when it is not such a config."""
    path = Path(run_dir) / CONFIG_FILE
    if not path.is_file():
        return None
    try:
        document = yaml.safe_load(path.read_text())
    except yaml.YAMLError as error:
        raise ValueError(f"{path} is not YAML ({str(error).splitlines()[0]})") from None
    if not (
        isinstance(document, dict)
        and len(document) == 1
        and isinstance(next(iter(document.values())), dict)
    ):
        raise ValueError(f"{path} is not a zoo config with one env entry (empty or corrupt)")
    ((env_id, hyperparams),) = document.items()
    return str(env_id), dict(hyperparams)


def save_model(model: Any, model_path: str | Path, vecnormalize_path: str | Path) -> None:
    """Save an SB3 model and, when it normalises, its VecNormalize statistics, each atomically.

    The statistics are written first: a model file never exists without its statistics.
    """
    vec_normalize = model.get_vec_normalize_env()
    if vec_normalize is not None:
        atomic_write(vecnormalize_path, pickle.dumps(vec_normalize))  # as VecNormalize.save does
    buffer = io.BytesIO()
    model.save(buffer)
    atomic_write(model_path, buffer.getvalue())


def checkpoint_paths(run_dir: str | Path, steps: int) -> tuple[Path, Path]:
    """``(model, vecnormalize)`` paths of the checkpoint at ``steps`` (rl-zoo / SB3 names)."""
    folder = Path(run_dir) / CHECKPOINT_DIR
    return (
        folder / f"{CHECKPOINT_PREFIX}_{steps}_steps.zip",
        folder / f"{CHECKPOINT_PREFIX}_vecnormalize_{steps}_steps.pkl",
    )
