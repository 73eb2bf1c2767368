"""The tuned open-loop gaits: the one home of their numbers, and the one reader and writer of
tuned-gaits files.

The shipped file, ``acl_env/data/tuned_gaits.json`` (package data, reached through
:mod:`importlib.resources`), holds one entry per key: ``"acl"`` (rolling ACL, the shipped ACL
policy's gait), ``"acl_noroll"`` (``rolls_per_cycle`` 0, the registered gait of
``acl_env/ACLClimbNoRollBase-v3``) and ``"acl_noroll_v2"`` (the registered gait of
``acl_env/ACLClimbNoRollBase-v2``). The registrations and the training recipe name an entry by
key (``tuned_gait="acl"``) instead of copying its numbers. The tuner (``acl-tune-gait``) writes
entries of the same format to a file of its own (``runs/tuned_gaits.json`` unless told
otherwise), never to the shipped one unless given its path. Per entry:

- ``env_id``, ``env_kwargs``: ``gymnasium.make(env_id, **env_kwargs)`` plays the tuned gait with a
  zero action (``squeeze`` in m, ``gait_kwargs`` for :class:`acl_env.gait.ACLGait`); an entry
  tuned with ``--grip`` holds the compliant grip instead (``grip_target``, ``grip_gain``,
  ``grip_leak``: :mod:`acl_env.envs.grip`) on its env id's own gait;
- ``objective``, ``reward_weights``: the metric optimised, under those reward weights;
- ``seeds``, ``steps_per_cycle``, ``cycles_per_episode``: each trial's episodes;
- ``condition`` (optional): env arguments every trial played under, such as ``{"friction": 0.5}``;
- ``cvar``, ``against_default`` (optional): a risk-averse study's share of worst conditions, and
  whether each condition scored the margin over the default gait's there;
- ``trials``, ``best_trial``, ``study``: the Optuna study;
- ``metrics``: the tuned gait's metrics (:mod:`acl_env.evaluation`), mean over the seeds;
- ``validation``: the same on new seeds (the best few trials re-measured there; the tuned gait is
  the best of them that neither fell nor rolled);
- ``default_gait_metrics``, ``default_gait_validation``: the untuned default gait, same protocol.

Older files in YAML (``.yml``, ``.yaml``) are read too, with PyYAML (the ``train`` extra).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from acl_env.io import atomic_write, jsonable
from acl_env.shipped import data_path

SHIPPED_FILE = "tuned_gaits.json"
# The env keyword that names a shipped entry; it stands for that entry's squeeze and gait_kwargs.
TUNED_GAIT_KWARG = "tuned_gait"
# What an entry's env_kwargs may hold, and so what tuned_gait=key sets.
GAIT_SHAPE_KWARGS = ("squeeze", "gait_kwargs")
# What an entry tuned with ``acl-tune-gait --grip`` holds instead: the compliant grip's law.
GRIP_KWARGS = ("grip_target", "grip_gain", "grip_leak")


class TunedGaitsError(ValueError):
    """A tuned-gaits file that is not one, or a key it does not hold."""


def shipped_path() -> Path:
    """The shipped tuned-gaits file inside the installed package."""
    return data_path(SHIPPED_FILE)


def read(path: str | Path | None = None) -> dict[str, dict[str, Any]]:
    """The tuned gaits by key: the shipped ones, or those of the file at ``path``.

    :class:`TunedGaitsError` names the file when it is not a tuned-gaits document."""
    path = shipped_path() if path is None else Path(path)
    try:
        text = path.read_text()
        if path.suffix in (".yml", ".yaml"):
            import yaml  # older files only; the train extra has PyYAML

            document = yaml.safe_load(text) or {}
        else:
            document = json.loads(text)
    except (OSError, ValueError) as error:
        raise TunedGaitsError(f"{path}: not a tuned-gaits file ({error})") from None
    except Exception as error:  # yaml.YAMLError, without importing yaml for JSON files
        raise TunedGaitsError(f"{path}: not a tuned-gaits file ({error})") from None
    if not isinstance(document, dict) or not all(isinstance(v, dict) for v in document.values()):
        raise TunedGaitsError(f"{path}: not a tuned-gaits file (expected a mapping of entries)")
    return document


def entry(key: str, path: str | Path | None = None) -> dict[str, Any]:
    """One entry, by key; :class:`TunedGaitsError` names the key and the keys there are."""
    document = read(path)
    if key not in document:
        where = "the shipped tuned gaits" if path is None else str(path)
        raise TunedGaitsError(f"no tuned gait {key!r} in {where} (keys: {', '.join(document)})")
    return document[key]


def gait_shape(key: str, path: str | Path | None = None) -> dict[str, Any]:
    """The env kwargs that make the env play entry ``key``'s gait: its squeeze and gait_kwargs."""
    kwargs = entry(key, path).get("env_kwargs") or {}
    return {k: _copy(v) for k, v in kwargs.items() if k in GAIT_SHAPE_KWARGS}


def grip(key: str, path: str | Path | None = None) -> dict[str, Any]:
    """The env kwargs of entry ``key``'s compliant grip (``acl-tune-gait --grip``): its
    ``grip_target``, ``grip_gain`` and ``grip_leak``."""
    kwargs = entry(key, path).get("env_kwargs") or {}
    return {k: float(v) for k, v in kwargs.items() if k in GRIP_KWARGS}


def resolve(env_kwargs: Mapping[str, Any]) -> dict[str, Any]:
    """``env_kwargs`` with ``tuned_gait=key`` replaced by that shipped entry's squeeze and
    gait_kwargs. Explicit ``squeeze`` or ``gait_kwargs`` beside it are refused by name."""
    kwargs = dict(env_kwargs)
    key = kwargs.pop(TUNED_GAIT_KWARG, None)
    if key is None:
        return kwargs
    if not isinstance(key, str):
        raise TypeError(f"tuned_gait must be the name of a tuned gait, got {key!r}")
    clash = [k for k in GAIT_SHAPE_KWARGS if kwargs.get(k) is not None]
    if clash:
        raise ValueError(f"tuned_gait={key!r} sets {' and '.join(clash)}: give one or the other")
    try:
        shape = gait_shape(key)
    except TunedGaitsError as error:
        raise ValueError(f"tuned_gait: {error}") from None
    return {**kwargs, **shape}


def write(path: str | Path, key: str, new_entry: Mapping[str, Any]) -> None:
    """Replace ``key`` in the JSON file at ``path`` (other entries kept), atomically: a reader
    sees the old file or the new one, and a symbolic link at ``path`` is replaced by the file,
    never written through to its target."""
    path = Path(path)
    document = read(path) if path.is_file() else {}
    document[key] = dict(new_entry)
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(path, json.dumps(jsonable(document), indent=2) + "\n")


def _copy(value: Any) -> Any:
    return {k: _copy(v) for k, v in value.items()} if isinstance(value, dict) else value
