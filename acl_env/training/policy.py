"""A trained policy folder, loaded for evaluation: model, frozen VecNormalize, its env config.

A policy folder is a training run folder or a copy of its final files (``model.zip``,
``vecnormalize.pkl`` and/or ``vecnormalize.npz``, ``config.yml``); see
:mod:`acl_env.training.runs`. Its ``model.zip`` is unpickled by SB3's loader, so
:func:`load_policy` loads it only with ``trust_pickles`` (its statistics come from the
pickle-free ``.npz`` when there is one). A pretrained folder (``policy.json``,
:mod:`acl_env.pretrained`, as shipped) is read and played on numpy instead, no flag needed.
Stable-Baselines3 is imported only when an SB3 policy is loaded. Every problem with a folder
raises ``ValueError`` with a message that names the file and what was expected, so command lines
can refuse it up front.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np

from acl_env import pretrained
from acl_env.pretrained import PretrainedPolicy, SpaceMismatchError
from acl_env.training.config import normalize_kwargs
from acl_env.training.runs import (
    CONFIG_FILE,
    latest_model,
    load_vecnormalize,
    require_trust,
    run_config,
)

Policy = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class PolicyFolder:
    """What a policy folder holds: its env id and config entry, model and statistics paths
    (``vecnormalize``: the pickle-free ``.npz`` when there is one, else the ``.pkl``)."""

    path: Path
    env_id: str
    hyperparams: dict[str, Any]
    model: Path
    vecnormalize: Path | None

    @property
    def env_kwargs(self) -> dict[str, Any]:
        """The training env kwargs of the config (copy)."""
        return dict(self.hyperparams.get("env_kwargs") or {})


def read_policy_folder(path: str | Path) -> PolicyFolder | PretrainedPolicy:
    """Check a policy folder's files and read its config (:func:`read_sb3_folder`), or load a
    pretrained folder (:func:`acl_env.pretrained.load_policy`); ``ValueError`` names what is
    wrong. Both give ``path``, ``env_id``, ``env_kwargs`` and ``hyperparams``."""
    if pretrained.is_pretrained(path):
        return read_pretrained(path)
    return read_sb3_folder(path)


def read_pretrained(path: str | Path) -> PretrainedPolicy:
    """A pretrained policy folder, its env id checked to be registered."""
    policy = pretrained.load_policy(Path(path))
    policy.check_registered()
    return policy


def read_sb3_folder(path: str | Path) -> PolicyFolder:
    """Check an SB3 policy or run folder's files and read its config; ``ValueError`` names what
    is wrong. Reads ``config.yml`` (safe YAML) and file names only: no pickle is loaded."""
    path = Path(path)
    if not path.is_dir():
        raise ValueError(f"{path} is not a folder")
    config = run_config(path)  # ValueError naming the file unless a zoo config of one entry
    if config is None:
        raise ValueError(f"{path} has no {CONFIG_FILE}: it defines the policy's env")
    env_id, hyperparams = config
    if env_id not in gymnasium.registry:
        raise ValueError(
            f"{path / CONFIG_FILE} names env {env_id!r}, which is not registered "
            "(an older version of the env, or a package to pass with --gym-packages)"
        )
    env_kwargs = hyperparams.get("env_kwargs") or {}
    if not isinstance(env_kwargs, dict):
        raise ValueError(f"env_kwargs in {path / CONFIG_FILE} must be a mapping")
    try:
        model, vecnormalize = latest_model(path)
    except FileNotFoundError as error:
        raise ValueError(str(error)) from error
    try:
        normalized = normalize_kwargs(hyperparams) is not None
    except (ValueError, TypeError, SyntaxError) as error:
        raise ValueError(f"normalize in {path / CONFIG_FILE}: {error}") from error
    if normalized and vecnormalize is None:
        raise ValueError(f"{path} was trained with VecNormalize but has no statistics for {model}")
    return PolicyFolder(path, env_id, dict(hyperparams), model, vecnormalize)


def load_policy(
    folder: PolicyFolder | PretrainedPolicy | str | Path,
    env: gymnasium.Env,
    trust_pickles: bool = False,
) -> Policy:
    """Deterministic actions of the folder's newest model for ``env``, observations normalised by
    its VecNormalize statistics frozen (``training=False``, ``norm_reward=False``); a pretrained
    folder's on numpy (the same actions).

    An SB3 folder loads only with ``trust_pickles`` (its ``model.zip`` is unpickled, which can
    run code): else :class:`~acl_env.training.runs.UntrustedPickleError` (a ``ValueError``),
    before any file is opened. ``ValueError`` if a file does not load,
    :class:`SpaceMismatchError` if the model's spaces do not match ``env``'s.
    """
    if not isinstance(folder, PolicyFolder | PretrainedPolicy):
        folder = read_policy_folder(folder)
    if isinstance(folder, PretrainedPolicy):
        folder.check_spaces(env)
        return folder
    require_trust(folder.path, trust_pickles)
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import DummyVecEnv

    torch.set_num_threads(1)  # one small MLP forward per step; threads would fight the workers
    try:
        model = PPO.load(folder.model, device="cpu")
    except Exception as error:  # a zip that is not an SB3 model fails in many ways
        raise ValueError(f"{folder.model} is not a PPO model ({error})") from error
    for name in ("observation_space", "action_space"):
        trained, here = getattr(model, name), getattr(env, name)
        if trained.shape != here.shape:
            raise SpaceMismatchError(
                f"{folder.model} was trained with {name} of shape {trained.shape}, but this env "
                f"has {here.shape} (env kwargs that change the robot or the action do not apply)"
            )
    normalize: Callable[[np.ndarray], np.ndarray] = lambda obs: obs  # noqa: E731
    if folder.vecnormalize is not None:
        stats = load_vecnormalize(folder.vecnormalize, DummyVecEnv([lambda: env]), trust_pickles)
        stats.training, stats.norm_reward = False, False
        normalize = stats.normalize_obs

    def act(obs: np.ndarray) -> np.ndarray:
        action, _ = model.predict(normalize(obs), deterministic=True)
        return action

    return act
