"""Run folders: the files a training run writes, and finding the newest model in one.

A run saves its VecNormalize statistics twice: ``vecnormalize.pkl`` (SB3's pickle, which the
RL Zoo and ``VecNormalize.load`` read) and ``vecnormalize.npz`` (the same numbers, pickle-free:
read with ``allow_pickle=False``, it runs no code). Readers here prefer the npz. ``model.zip`` is
unpickled by SB3's loader, so loading a model, or a ``.pkl``, needs ``trust_pickles``
(``--trust-pickles`` on the command lines): :func:`require_trust`.
"""

from __future__ import annotations

import io
import json
import pickle
import zipfile
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import yaml

from acl_env.io import atomic_write

MODEL_FILE = "model.zip"
VECNORMALIZE_FILE = "vecnormalize.pkl"
STATISTICS_SUFFIX = ".npz"  # the pickle-free statistics beside each .pkl (vecnormalize.npz)
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
    would then silently restart from an older checkpoint. The statistics path is the
    pickle-free ``.npz`` when there is one, else the ``.pkl``, and None when the run did not
    normalise (read either with :func:`load_vecnormalize`).
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
    return model, statistics_file(vecnorm)


def statistics_file(pickle_path: str | Path) -> Path | None:
    """The statistics to read for ``pickle_path`` (a ``.pkl``): the ``.npz`` beside it when
    present, else the pickle when present, else None."""
    pickle_path = Path(pickle_path)
    for path in (pickle_path.with_suffix(STATISTICS_SUFFIX), pickle_path):
        if path.is_file():
            return path
    return None


def is_pickle(path: str | Path) -> bool:
    """Does reading this file unpickle it (anything but a ``.npz`` statistics file)?"""
    return Path(path).suffix != STATISTICS_SUFFIX


class UntrustedPickleError(ValueError):
    """A pickle-bearing SB3 file asked to be loaded without ``trust_pickles``."""


def require_trust(path: str | Path, trust_pickles: bool, option: str = "--trust-pickles") -> None:
    """:class:`UntrustedPickleError` unless ``trust_pickles``: ``path`` is a Stable-Baselines3
    model or a ``.pkl``, which SB3 (or pickle) loads by unpickling, which can run any code."""
    if not trust_pickles:
        raise UntrustedPickleError(
            f"{path} is a Stable-Baselines3 folder or file: its model.zip and vecnormalize.pkl "
            f"are pickles, which can run code when loaded; pass {option} only for a folder you "
            "made or trust"
        )


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
    """Save an SB3 model and, when it normalises, its VecNormalize statistics (the ``.pkl`` and
    the pickle-free ``.npz`` beside it, :func:`write_statistics`), each atomically.

    The statistics are written first: a model file never exists without its statistics.
    """
    vec_normalize = model.get_vec_normalize_env()
    if vec_normalize is not None:
        write_statistics(Path(vecnormalize_path).with_suffix(STATISTICS_SUFFIX), vec_normalize)
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


# --- pickle-free VecNormalize statistics ---------------------------------------------------------

# The settings of a VecNormalize saved beside its running statistics.
STATISTICS_SETTINGS = ("norm_obs", "norm_reward", "clip_obs", "clip_reward", "gamma", "epsilon")


def write_statistics(path: str | Path, vec_normalize: Any) -> None:
    """VecNormalize's running statistics (``obs_rms`` and ``ret_rms``: mean, var, count) and
    settings (:data:`STATISTICS_SETTINGS`) as an ``.npz`` of plain arrays, atomically. Only a
    flat (Box) observation's statistics fit; others are left to the pickle."""
    if isinstance(vec_normalize.obs_rms, dict):
        return
    arrays = {
        f"{name}_{field}": np.asarray(getattr(getattr(vec_normalize, name), field), np.float64)
        for name in ("obs_rms", "ret_rms")
        for field in ("mean", "var", "count")
    }
    arrays |= {key: np.asarray(getattr(vec_normalize, key)) for key in STATISTICS_SETTINGS}
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    atomic_write(path, buffer.getvalue())


def read_statistics(path: str | Path) -> dict[str, np.ndarray]:
    """The arrays of a statistics ``.npz`` (no pickles); ``ValueError`` naming the file when it
    is not one."""
    names = [f"{n}_{f}" for n in ("obs_rms", "ret_rms") for f in ("mean", "var", "count")]
    try:
        with np.load(path, allow_pickle=False) as npz:
            arrays = {key: npz[key] for key in (*names, *STATISTICS_SETTINGS)}
    except (OSError, ValueError, KeyError, zipfile.BadZipFile, EOFError) as error:
        raise ValueError(f"{path} is not VecNormalize statistics ({error})") from None
    return arrays


def read_vecnormalize(path: str | Path, trust_pickles: bool = False) -> Any:
    """VecNormalize statistics without an env: an object with ``obs_rms`` and ``ret_rms`` (each
    ``mean``, ``var``, ``count``) and the settings (:data:`STATISTICS_SETTINGS`), from an ``.npz``
    or, with ``trust_pickles``, a ``.pkl`` (the unpickled ``VecNormalize``). ``ValueError``
    naming the file when it is not such statistics."""
    if is_pickle(path):
        require_trust(path, trust_pickles)
        from stable_baselines3.common.vec_env import VecNormalize

        try:
            stats = pickle.loads(Path(path).read_bytes())
        except Exception as error:  # unpickling garbage raises anything
            raise ValueError(f"{path} is corrupt ({type(error).__name__})") from None
        if not isinstance(stats, VecNormalize):
            raise ValueError(f"{path} holds a {type(stats).__name__}, not VecNormalize")
        return stats
    arrays = read_statistics(path)
    rms = {
        name: SimpleNamespace(
            mean=arrays[f"{name}_mean"],
            var=arrays[f"{name}_var"],
            count=float(arrays[f"{name}_count"]),
        )
        for name in ("obs_rms", "ret_rms")
    }
    return SimpleNamespace(**rms, **{key: arrays[key].item() for key in STATISTICS_SETTINGS})


def load_vecnormalize(path: str | Path, venv: Any, trust_pickles: bool = False) -> Any:
    """A ``VecNormalize`` over ``venv`` with the statistics of ``path``: an ``.npz`` (pickle-free,
    :func:`write_statistics`) or, with ``trust_pickles``, a ``.pkl`` (:func:`require_trust`).
    ``ValueError`` naming the file when it does not load or fit ``venv``."""
    from stable_baselines3.common.vec_env import VecNormalize

    if is_pickle(path):
        require_trust(path, trust_pickles)
        try:
            return VecNormalize.load(str(path), venv)
        except Exception as error:  # unpickling garbage raises anything
            raise ValueError(
                f"{path} is not VecNormalize statistics for this env ({error})"
            ) from None
    saved = read_vecnormalize(path)
    settings = {key: getattr(saved, key) for key in STATISTICS_SETTINGS}
    stats = VecNormalize(venv, **settings)
    for name in ("obs_rms", "ret_rms"):
        rms, source = getattr(stats, name), getattr(saved, name)
        if np.shape(source.mean) != np.shape(rms.mean) or np.shape(source.var) != np.shape(rms.var):
            raise ValueError(
                f"{path}: {name} of shape {np.shape(source.mean)}, this env needs "
                f"{np.shape(rms.mean)}"
            )
        rms.mean, rms.var, rms.count = np.copy(source.mean), np.copy(source.var), source.count
    return stats


SOURCE_SUFFIXES = (".py", ".json", ".yml", ".xml", ".npz")


def code_version() -> dict[str, Any]:
    """What trained a run, so that a retrain can be traced to what changed: ``acl_env``'s
    version and a SHA-256 over its package's source and data files (their paths and bytes,
    in order; the package as installed or checked out), and the versions of the libraries that
    step, learn and count."""
    import hashlib
    import importlib.metadata

    import acl_env

    root = Path(acl_env.__file__).resolve().parent
    digest = hashlib.sha256()
    for path in sorted(p for p in root.rglob("*") if p.suffix in SOURCE_SUFFIXES):
        if "__pycache__" not in path.parts:
            digest.update(path.relative_to(root).as_posix().encode() + b"\0")
            digest.update(path.read_bytes())
    libraries = ("mujoco", "numpy", "torch", "stable_baselines3", "gymnasium")
    return {
        "acl_env": acl_env.__version__,
        "acl_env_sha256": digest.hexdigest(),
        **{name: importlib.metadata.version(name) for name in libraries},
    }
