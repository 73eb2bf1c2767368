"""Pretrained policies on numpy alone, from pickle-free files: no torch, SB3 or PyYAML.

A pretrained policy folder holds two files (format ``acl_env.policy/1``):

* ``policy.npz``: the actor as float32 arrays: ``hidden_<i>_weight`` / ``hidden_<i>_bias`` of each
  hidden layer in order, ``action_weight`` / ``action_bias`` of the action head, ``log_std``; and,
  when the policy normalises its observations, VecNormalize's statistics ``obs_mean``,
  ``obs_var`` (float64, as VecNormalize keeps them), ``clip_obs`` and ``epsilon``;
* ``policy.json``: the metadata: ``format``, ``name``, ``env_id``, ``env_kwargs`` (the training
  env's, as trained), ``activation``, ``net_arch``, the spaces' shapes and the action bounds,
  ``training`` (the recipe entry, steps, wall time, command, the ``--resume`` commands that
  continued the run if any, commit) and ``evaluation`` (a summary of the published record).

The deterministic action is SB3's ``PPO.predict(VecNormalize.normalize_obs(obs),
deterministic=True)``: the observation normalised in float64 and rounded to float32, the MLP in
float32, the action head's mean clipped to the action bounds. ``acl_env.evaluation.export`` writes
such a folder from an SB3 run folder.
"""

from __future__ import annotations

import itertools
import json
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, Protocol

import gymnasium
import numpy as np

from acl_env import shipped

FORMAT = "acl_env.policy/1"
METADATA_FILE = "policy.json"
WEIGHTS_FILE = "policy.npz"
ACTIVATIONS: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "tanh": np.tanh,
    "relu": lambda x: np.maximum(x, np.float32(0.0)),
}
NORMALIZATION_KEYS = ("obs_mean", "obs_var", "clip_obs", "epsilon")


class SpaceMismatchError(ValueError):
    """The policy was trained on an env with other observation or action shapes."""


class PolicySource(Protocol):
    """What evaluation needs to know of a policy folder, pretrained or an SB3 run folder."""

    @property
    def path(self) -> Path: ...

    @property
    def env_id(self) -> str: ...

    @property
    def env_kwargs(self) -> dict[str, Any]: ...

    @property
    def hyperparams(self) -> dict[str, Any]: ...


def list_policies() -> list[str]:
    """The names of the shipped pretrained policies (for :func:`load_policy`)."""
    return shipped.list_policies()


def is_pretrained(path: str | Path) -> bool:
    """Is ``path`` a pretrained policy folder (it has ``policy.json``)?"""
    return (Path(path) / METADATA_FILE).is_file()


class PretrainedPolicy:
    """A policy read from a pretrained folder: SB3's ``predict`` on numpy.

    ``env_id`` and ``env_kwargs`` name the env it was trained on (``gym.make(env_id,
    **env_kwargs)``; ``domain_randomization`` among them is a training choice), ``metadata`` is
    ``policy.json``. ``rng`` draws the stochastic actions (``deterministic=False``).
    """

    def __init__(self, path: Path, metadata: dict[str, Any], arrays: dict[str, np.ndarray]):
        self.path = path
        self.metadata = metadata
        self.name: str = metadata["name"]
        self._env_id: str = metadata["env_id"]
        self.activation = ACTIVATIONS[metadata["activation"]]
        self.observation_shape = tuple(metadata["observation_shape"])
        self.action_shape = tuple(metadata["action_shape"])
        self.action_low = np.asarray(metadata["action_low"], dtype=np.float32)
        self.action_high = np.asarray(metadata["action_high"], dtype=np.float32)
        # The entries' names (acl_env.envs.observations); empty in exports that predate them.
        self.observation_names = tuple(metadata.get("observation_names") or ())
        self.action_names = tuple(metadata.get("action_names") or ())
        hidden = len(metadata["net_arch"])
        f32 = {k: v.astype(np.float32) for k, v in arrays.items() if k not in NORMALIZATION_KEYS}
        self.layers = [(f32[f"hidden_{i}_weight"], f32[f"hidden_{i}_bias"]) for i in range(hidden)]
        self.action_head = (f32["action_weight"], f32["action_bias"])
        self.log_std = f32["log_std"]
        self.normalization = None  # VecNormalize's statistics, float64 as it keeps them
        if "obs_mean" in arrays:
            self.normalization = {k: arrays[k].astype(np.float64) for k in NORMALIZATION_KEYS}
        self.rng = np.random.default_rng()

    def __repr__(self) -> str:
        return f"PretrainedPolicy({self.name!r}, env_id={self.env_id!r}, path={str(self.path)!r})"

    @property
    def env_id(self) -> str:
        """The registered env id the policy was trained on."""
        return self._env_id

    @property
    def env_kwargs(self) -> dict[str, Any]:
        """The training env's kwargs (a deep copy)."""
        return json.loads(json.dumps(self.metadata["env_kwargs"]))

    @property
    def hyperparams(self) -> dict[str, Any]:
        """The training recipe's entry, as the run folder's ``config.yml`` held it (a copy; its
        ``env_kwargs`` spell the task on the id it was trained on, which may be the base id of
        :attr:`env_id`)."""
        training = self.metadata.get("training") or {}
        return json.loads(json.dumps(training.get("hyperparams") or {}))

    def normalize(self, obs: np.ndarray) -> np.ndarray:
        """The observation as the network sees it: VecNormalize's (float64), as float32."""
        if self.normalization is None:
            return np.asarray(obs).astype(np.float32)
        n = self.normalization
        clip = float(n["clip_obs"])
        scaled = (np.asarray(obs) - n["obs_mean"]) / np.sqrt(n["obs_var"] + float(n["epsilon"]))
        return np.clip(scaled, -clip, clip).astype(np.float32)

    def mean_action(self, obs: np.ndarray) -> np.ndarray:
        """The action head's output for normalised float32 observations (unclipped)."""
        x = obs
        for weight, bias in self.layers:
            x = self.activation(x @ weight.T + bias)
        weight, bias = self.action_head
        return x @ weight.T + bias

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, None]:
        """``(action, None)`` as SB3's ``predict``, for one observation or a batch of them."""
        obs = np.asarray(observation)
        single = obs.shape == self.observation_shape
        if not single and obs.shape[1:] != self.observation_shape:
            raise ValueError(
                f"{self.name}: observation of shape {obs.shape}, expected {self.observation_shape}"
                f" or a batch of them"
            )
        batch = self.normalize(obs.reshape(-1, *self.observation_shape))
        actions = self.mean_action(batch.reshape(len(batch), -1))
        if not deterministic:
            noise = self.rng.standard_normal(actions.shape).astype(np.float32)
            actions = actions + np.exp(self.log_std) * noise
        actions = actions.reshape(-1, *self.action_shape)
        actions = np.clip(
            actions,
            self.action_low.reshape(self.action_shape),
            self.action_high.reshape(self.action_shape),
        )
        return (actions[0] if single else actions), None

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        """The deterministic action for ``obs``."""
        return self.predict(obs, deterministic=True)[0]

    def check_registered(self) -> None:
        """``ValueError`` naming ``policy.json`` unless its env id is registered."""
        if self.env_id not in gymnasium.registry:
            raise ValueError(
                f"{self.path / METADATA_FILE} names env {self.env_id!r}, which is not registered "
                "(an older version of the env, or a package to import first: --gym-packages)"
            )

    def check_spaces(self, env: Any) -> None:
        """:class:`SpaceMismatchError` unless ``env``'s spaces have the trained shapes."""
        for name, trained in (
            ("observation_space", self.observation_shape),
            ("action_space", self.action_shape),
        ):
            here = getattr(env, name).shape
            if tuple(here) != trained:
                raise SpaceMismatchError(
                    f"{self.path / METADATA_FILE}: {self.name} was trained with {name} of shape "
                    f"{trained}, but this env has {here} (env kwargs that change the robot or the "
                    "action do not apply)"
                )
        self._check_names(env)

    def _check_names(self, env: Any) -> None:
        """Spaces of the trained shapes must also hold the trained entries, in order (the env's
        layouts, ``acl_env.envs.observations``, against the names exported with the policy)."""
        if getattr(env.unwrapped, "config", None) is None or not self.observation_names:
            return
        from acl_env.envs.observations import env_observation_names

        here = env_observation_names(env.unwrapped)
        for i, (mine, theirs) in enumerate(zip(self.observation_names, here, strict=True)):
            if mine != theirs:
                raise SpaceMismatchError(
                    f"{self.path / METADATA_FILE}: {self.name} observes {mine!r} at entry {i}, "
                    f"this env {theirs!r}"
                )


def read_metadata(folder: Path) -> dict[str, Any]:
    """``policy.json`` of ``folder``, checked; ``ValueError`` naming the file and what is wrong."""
    path = folder / METADATA_FILE
    try:
        metadata = json.loads(path.read_text())
    except FileNotFoundError:
        raise ValueError(f"{folder} has no {METADATA_FILE}: not a pretrained policy") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise ValueError(f"{path} is not JSON ({error})") from None
    if not isinstance(metadata, dict):
        raise ValueError(f"{path} must hold a JSON object")
    if metadata.get("format") != FORMAT:
        raise ValueError(
            f"{path} has format {metadata.get('format')!r}; this acl_env reads {FORMAT!r}"
        )
    expected: dict[str, type | tuple[type, ...]] = {
        "name": str,
        "env_id": str,
        "env_kwargs": dict,
        "activation": str,
        "net_arch": list,
        "observation_shape": list,
        "action_shape": list,
        "action_low": list,
        "action_high": list,
    }
    for key, kind in expected.items():
        if not isinstance(metadata.get(key), kind):
            raise ValueError(f"{path}: {key!r} missing or not a {getattr(kind, '__name__', kind)}")
    if metadata["activation"] not in ACTIVATIONS:
        raise ValueError(
            f"{path}: activation {metadata['activation']!r} is not one of {sorted(ACTIVATIONS)}"
        )
    sizes = [*metadata["net_arch"], *metadata["observation_shape"], *metadata["action_shape"]]
    if not all(isinstance(n, int) and n > 0 for n in sizes):
        raise ValueError(f"{path}: net_arch and the shapes must be positive integers")
    size = int(np.prod(metadata["action_shape"]))
    for key in ("action_low", "action_high"):
        if len(metadata[key]) != size or not all(isinstance(v, int | float) for v in metadata[key]):
            raise ValueError(f"{path}: {key!r} must be {size} numbers")
    return metadata


def read_arrays(folder: Path, metadata: dict[str, Any]) -> dict[str, np.ndarray]:
    """``policy.npz`` of ``folder`` (no pickles), its shapes checked against ``metadata``;
    ``ValueError`` naming the file and what is wrong."""
    path = folder / WEIGHTS_FILE
    try:
        with np.load(path, allow_pickle=False) as npz:
            arrays = {key: npz[key] for key in npz.files}
    except FileNotFoundError:
        raise ValueError(f"{folder} has no {WEIGHTS_FILE}: the policy's weights") from None
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as error:
        raise ValueError(f"{path} is not a numpy .npz of arrays ({error})") from None
    obs_size = int(np.prod(metadata["observation_shape"]))
    widths = [obs_size, *metadata["net_arch"]]
    shapes: dict[str, tuple[int, ...]] = {}
    for i, (n_in, n_out) in enumerate(itertools.pairwise(widths)):
        shapes |= {f"hidden_{i}_weight": (n_out, n_in), f"hidden_{i}_bias": (n_out,)}
    n_actions = int(np.prod(metadata["action_shape"]))
    shapes |= {
        "action_weight": (n_actions, widths[-1]),
        "action_bias": (n_actions,),
        "log_std": (n_actions,),
    }
    if any(key in arrays for key in NORMALIZATION_KEYS):
        shapes |= {"obs_mean": (obs_size,), "obs_var": (obs_size,), "clip_obs": (), "epsilon": ()}
    for key, shape in shapes.items():
        if key not in arrays:
            raise ValueError(f"{path} has no array {key!r}")
        if arrays[key].shape != shape or not np.issubdtype(arrays[key].dtype, np.floating):
            raise ValueError(
                f"{path}: {key!r} is {arrays[key].dtype} {arrays[key].shape}, expected floats "
                f"of shape {shape}"
            )
        if not np.all(np.isfinite(arrays[key])):
            raise ValueError(f"{path}: {key!r} has non-finite values")
    return {key: arrays[key] for key in shapes}


def resolve(name_or_path: str | Path) -> Path:
    """The folder of a shipped policy's name, or ``name_or_path`` as a folder."""
    if isinstance(name_or_path, str) and name_or_path in shipped.list_policies():
        return shipped.policy_dir(name_or_path)
    path = Path(name_or_path)
    if not path.is_dir():
        raise ValueError(
            f"{name_or_path} is neither a shipped policy ({', '.join(shipped.list_policies())}) "
            "nor a folder"
        )
    return path


def load_policy(name_or_path: str | Path) -> PretrainedPolicy:
    """A shipped policy by name (:func:`list_policies`), or a pretrained policy folder.

    ``ValueError`` naming the file when one is missing, malformed or of another format.
    """
    folder = resolve(name_or_path)
    metadata = read_metadata(folder)
    return PretrainedPolicy(folder, metadata, read_arrays(folder, metadata))
