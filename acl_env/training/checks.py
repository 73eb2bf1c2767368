"""Checks of a training configuration before any work: env kwargs and PPO hyperparameters.

Every check raises :class:`ConfigError` with a one-line message that names the offending key and
what is accepted, so a command line can refuse the run before it spawns a worker or writes a file.
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable, Mapping
from typing import Any

from acl_env.envs.kwargs import ConfigError, check_env_kwargs, env_creator
from acl_env.training.config import NON_ALGO_KEYS, import_dotted, parse_python_literal

__all__ = ["TRAINER_SET", "ConfigError", "check_env_kwargs", "check_hyperparams", "env_creator"]

# Arguments of PPO.__init__ that the trainer sets itself, never the config.
TRAINER_SET = ("self", "env", "tensorboard_log", "verbose", "seed", "device", "_init_setup_model")


# --- hyperparameters -----------------------------------------------------------------------------


# The largest count a config may give (n_timesteps, n_steps, ...), and the largest rollout
# (n_steps x n_envs, the buffer PPO allocates up front): beyond any use, short of a hang or an
# out-of-memory crash after the setup.
MAX_COUNT = 10**12
MAX_ROLLOUT = 10**7


def _finite(value: Any) -> bool:
    """A real number (not a bool) that is finite as a float (a 400-digit integer is not)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    try:
        return math.isfinite(float(value))
    except OverflowError:
        return False


def _positive_int(value: Any) -> bool:
    return _finite(value) and value == int(value) and 1 <= value <= MAX_COUNT


def _number(value: Any, low: float, high: float, low_open: bool = False) -> bool:
    if not _finite(value):
        return False
    return (value > low if low_open else value >= low) and value <= high


def _schedule(value: Any) -> bool:
    """A positive number or the zoo's ``lin_<positive number>``."""
    if isinstance(value, str) and value.startswith("lin_"):
        try:
            return _number(float(value.removeprefix("lin_")), 0.0, math.inf, low_open=True)
        except ValueError:
            return False
    return _number(value, 0.0, math.inf, low_open=True)


def _bool(value: Any) -> bool:
    return isinstance(value, bool)


def _parsed(value: Any) -> Any:
    """A zoo string parsed by :func:`parse_python_literal` (None if it does not parse); any
    other value as it is."""
    if not isinstance(value, str):
        return value
    try:
        return parse_python_literal(value)
    except (ValueError, SyntaxError):
        return None


def _normalize(value: Any) -> bool:
    """``normalize``: a bool, a dict of VecNormalize arguments, or such a dict as a string."""
    value = _parsed(value)
    if isinstance(value, bool):
        return True
    allowed = {"norm_obs", "norm_reward", "clip_obs", "clip_reward", "gamma", "epsilon"}
    return isinstance(value, dict) and set(value) <= allowed


def _policy_kwargs(value: Any) -> bool:
    return isinstance(_parsed(value), dict)


def _callback(value: Any) -> bool:
    """``callback``: an allowed class (:data:`~acl_env.training.config.ALLOWED_CLASSES`) as a
    dotted path, a ``{path: kwargs}`` mapping, or a list of those; nothing else is imported."""
    items = value if isinstance(value, list) else [value]
    for item in items:
        name = next(iter(item)) if isinstance(item, dict) and len(item) == 1 else item
        if isinstance(item, dict) and not isinstance(item.get(name), dict | None):
            return False
        try:
            import_dotted(name, "callback")
        except ValueError:
            return False
    return True


def _policy(value: Any) -> bool:
    """``policy``: an SB3 alias (``MlpPolicy``), or the dotted path of an allowed
    ``ActorCriticPolicy`` subclass (SB3's, :mod:`acl_env.training.networks`)."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.policies import ActorCriticPolicy

    if isinstance(value, str) and value in PPO.policy_aliases:
        return True
    try:
        cls = import_dotted(value, "policy")
    except ValueError:
        return False
    return issubclass(cls, ActorCriticPolicy)


# key -> (check, what is accepted)
HYPERPARAM_CHECKS: dict[str, tuple[Callable[[Any], bool], str]] = {
    "n_envs": (lambda v: _positive_int(v) and v <= 1024, "an integer in [1, 1024]"),
    "n_timesteps": (_positive_int, f"an integer in [1, {MAX_COUNT:.0e}]"),
    "n_steps": (_positive_int, f"an integer in [1, {MAX_COUNT:.0e}]"),
    "batch_size": (lambda v: _positive_int(v) and v >= 2, f"an integer in [2, {MAX_COUNT:.0e}]"),
    "n_epochs": (_positive_int, f"an integer in [1, {MAX_COUNT:.0e}]"),
    "learning_rate": (_schedule, "a positive number or 'lin_<number>'"),
    "clip_range": (_schedule, "a positive number or 'lin_<number>'"),
    "clip_range_vf": (lambda v: v is None or _schedule(v), "None or a positive number"),
    "gamma": (lambda v: _number(v, 0.0, 1.0, low_open=True), "a number in (0, 1]"),
    "gae_lambda": (lambda v: _number(v, 0.0, 1.0), "a number in [0, 1]"),
    "ent_coef": (lambda v: _number(v, 0.0, math.inf), "a number >= 0"),
    "vf_coef": (lambda v: _number(v, 0.0, math.inf), "a number >= 0"),
    "max_grad_norm": (lambda v: _number(v, 0.0, math.inf, low_open=True), "a number > 0"),
    "target_kl": (lambda v: v is None or _number(v, 0.0, math.inf, True), "None or a number > 0"),
    "normalize_advantage": (_bool, "True or False"),
    "use_sde": (_bool, "True or False"),
    "sde_sample_freq": (lambda v: _positive_int(v) or v == -1, "-1 or an integer >= 1"),
    "stats_window_size": (_positive_int, f"an integer in [1, {MAX_COUNT:.0e}]"),
    "policy": (
        _policy,
        "an SB3 alias (MlpPolicy) or the dotted path of an ActorCriticPolicy subclass of "
        "stable_baselines3 or acl_env.training.networks",
    ),
    "policy_kwargs": (_policy_kwargs, "a dict or a dict(...) string"),
    "normalize": (_normalize, "a bool or a dict of VecNormalize arguments"),
    "env_kwargs": (lambda v: v is None or isinstance(v, dict), "a mapping"),
    "callback": (
        _callback,
        "the dotted path of a callback class of acl_env.training.callbacks or "
        "stable_baselines3.common.callbacks (or {path: kwargs}), or a list of them",
    ),
}


def check_hyperparams(hyperparams: Mapping[str, Any], source: str = "hyperparameter") -> None:
    """Names from PPO's signature and the zoo keys the trainer reads; values typed and in range.

    ``source`` prefixes the message (``--hyperparams``, or the config file and entry).
    """
    from stable_baselines3 import PPO

    accepted = [
        *(p for p in inspect.signature(PPO.__init__).parameters if p not in TRAINER_SET),
        *NON_ALGO_KEYS,
    ]
    unknown = sorted(set(hyperparams) - set(accepted))
    if unknown:
        raise ConfigError(f"{source}: unknown names {unknown} (accepted: {sorted(accepted)})")
    if "n_timesteps" not in hyperparams:
        raise ConfigError(f"{source}: n_timesteps is missing")
    for key, value in hyperparams.items():
        check, accepted_text = HYPERPARAM_CHECKS.get(key, (lambda v: True, ""))
        if not check(value):
            raise ConfigError(f"{source}: {key} must be {accepted_text}, got {value!r}")
    n_rollout = int(hyperparams.get("n_steps", 2048)) * int(hyperparams.get("n_envs", 1))
    if not 2 <= n_rollout <= MAX_ROLLOUT:
        raise ConfigError(
            f"{source}: n_steps x n_envs must be in [2, {MAX_ROLLOUT:.0e}], got {n_rollout}"
        )
