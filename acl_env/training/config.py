"""Training configuration: zoo-format YAML configs, their Python-looking strings, env factories.

The configs follow the rl-baselines3-zoo format (one YAML entry per env id, ``policy_kwargs`` and
``normalize`` possibly as Python-looking strings), so the zoo itself can train from the same file.
The zoo ``eval``s those strings; here they are parsed by :func:`parse_python_literal`, which only
accepts literals, ``dict(...)`` calls and ``torch.nn`` / ``torch.optim`` class names.

An experiment's recipe may be a delta over an entry of the shipped recipe
(``acl_env/data/ppo.yml``), as MuJoCo Playground's parameter files are::

    acl_env/ACLClimbNoRollBase-v2:
      base: acl_env/ACLClimbNoRollBase-v3   # an entry of the shipped recipe
      n_timesteps: 1000000             # top-level keys replace the base's
      env_kwargs:                       # merged key by key into the base's env_kwargs:
        squeeze: 0.0157                 # a value replaces the base's value whole,
        domain_randomization: null      # null removes the key

:func:`load_hyperparams` resolves it into a plain, full entry (what a run's ``config.yml`` holds).
"""

from __future__ import annotations

import ast
import importlib
import signal
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

import gymnasium
import yaml

import acl_env  # noqa: F401  (registers the acl_env/* ids)
from acl_env import current_id, shipped, tuned_gaits
from acl_env.io import atomic_write

# Config keys consumed here rather than passed to the SB3 algorithm.
NON_ALGO_KEYS = ("n_envs", "n_timesteps", "normalize", "env_kwargs", "callback")
# The key of a recipe entry that is a delta over an entry of the shipped recipe.
BASE_KEY = "base"


class RecipeError(ValueError):
    """A recipe delta that does not resolve: an unknown base entry, a malformed override."""


# --- parsing -------------------------------------------------------------------------------------


def _resolve_torch_name(dotted: str) -> type:
    """Map ``nn.Tanh``, ``th.nn.ReLU``, ``torch.optim.Adam`` ... to the class, nothing else."""
    import torch

    parts = dotted.split(".")
    if parts[0] in ("th", "torch"):
        parts = parts[1:]
    if len(parts) == 2 and parts[0] in ("nn", "optim"):
        module = torch.nn if parts[0] == "nn" else torch.optim
        value = getattr(module, parts[1], None)
        if isinstance(value, type):
            return value
    raise ValueError(f"unsupported name in config: {dotted!r}")


def _eval_node(node: ast.AST) -> Any:
    """Evaluate a restricted expression tree: literals, containers, dict(...), torch class names."""
    if isinstance(node, ast.Constant):
        return node.value
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
        value = _eval_node(node.operand)
        return -value if isinstance(node.op, ast.USub) else +value
    if isinstance(node, ast.List):
        return [_eval_node(item) for item in node.elts]
    if isinstance(node, ast.Tuple):
        return tuple(_eval_node(item) for item in node.elts)
    if isinstance(node, ast.Dict):
        if any(key is None for key in node.keys):
            raise ValueError("'**' unpacking is not supported in config strings")
        return {_eval_node(k): _eval_node(v) for k, v in zip(node.keys, node.values, strict=True)}
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "dict":
        if node.args or any(kw.arg is None for kw in node.keywords):
            raise ValueError("dict(...) in config strings takes keyword arguments only")
        return {kw.arg: _eval_node(kw.value) for kw in node.keywords}
    if isinstance(node, ast.Attribute | ast.Name):
        return _resolve_torch_name(ast.unparse(node))
    raise ValueError(f"unsupported expression in config: {ast.unparse(node)!r}")


def parse_python_literal(text: str) -> Any:
    """Parse a zoo-style string such as ``"dict(log_std_init=-2, activation_fn=nn.Tanh)"``."""
    return _eval_node(ast.parse(text.strip(), mode="eval").body)


def linear_schedule(initial: float) -> Callable[[float], float]:
    """SB3 schedule decaying linearly from ``initial`` to 0 over training (zoo's ``lin_X``)."""
    from stable_baselines3.common.utils import LinearSchedule

    return LinearSchedule(initial, 0.0, 1.0)


# --- configs -------------------------------------------------------------------------------------


def load_hyperparams(path: str | Path, env_id: str) -> dict[str, Any]:
    """A copy of the zoo-format YAML's entry for ``env_id``; an entry with a ``base`` (a delta
    over the shipped recipe, see the module docstring) is resolved into a full one.

    ``KeyError`` naming the entries when ``env_id`` has none, :class:`RecipeError` when a delta
    does not resolve."""
    with open(path) as f:
        configs = yaml.safe_load(f)
    # A task's old id and its current one name the same entry (acl_env.RENAMED_IDS).
    key = next((k for k in configs if current_id(k) == current_id(env_id)), None)
    if key is None:
        known = ", ".join(k for k in configs if not k.startswith("."))
        raise KeyError(f"no entry for {env_id!r} in {path} (entries: {known})")
    entry = dict(configs[key])
    if BASE_KEY in entry:
        return resolve_delta(entry, f"{path} entry {env_id}")
    return entry


def resolve_delta(delta: Mapping[str, Any], source: str = "recipe") -> dict[str, Any]:
    """The full entry a recipe delta stands for: its ``base``, an entry of the shipped recipe,
    with the delta's top-level keys replacing the base's and its ``env_kwargs`` merged key by
    key (a value replaces the base's whole, ``None`` removes the key)."""
    overrides = dict(delta)
    base = overrides.pop(BASE_KEY)
    base = current_id(base) if isinstance(base, str) else base
    recipe = shipped.recipe_path()
    with open(recipe) as f:
        entries = {k: v for k, v in yaml.safe_load(f).items() if not k.startswith(".")}
    if not isinstance(base, str) or base not in entries:
        raise RecipeError(
            f"{source}: base {base!r} is not an entry of the shipped recipe {recipe} "
            f"(entries: {', '.join(entries)})"
        )
    if BASE_KEY in entries[base]:
        raise RecipeError(f"{source}: base {base!r} is itself a delta")
    resolved = dict(entries[base])
    env_kwargs = overrides.pop("env_kwargs", None) or {}
    if not isinstance(env_kwargs, Mapping):
        raise RecipeError(f"{source}: env_kwargs must be a mapping, got {env_kwargs!r}")
    resolved.update(overrides)
    resolved["env_kwargs"] = merge_env_kwargs(
        resolved.get("env_kwargs") or {}, env_kwargs, none_removes=True
    )
    return resolved


def merge_env_kwargs(
    base: Mapping[str, Any], overrides: Mapping[str, Any], none_removes: bool = False
) -> dict[str, Any]:
    """``base`` env kwargs with ``overrides`` merged key by key (with ``none_removes``, a None
    override removes the key). Overriding ``squeeze`` or ``gait_kwargs`` of a base that names a
    tuned gait by key (``tuned_gait``) changes that gait: its numbers are written out first
    (:func:`acl_env.tuned_gaits.resolve`), unless the overrides name a tuned gait themselves."""
    shape = set(tuned_gaits.GAIT_SHAPE_KWARGS) & set(overrides)
    if shape and tuned_gaits.TUNED_GAIT_KWARG not in overrides:
        base = tuned_gaits.resolve(base)
    merged = {**base, **overrides}
    return {k: v for k, v in merged.items() if not (none_removes and v is None)}


def save_hyperparams(path: str | Path, env_id: str, hyperparams: dict[str, Any]) -> None:
    """Write ``{env_id: hyperparams}`` in the same zoo format, so it can be trained from again
    (atomically: a reader sees the old file or the new one)."""
    atomic_write(path, yaml.safe_dump({env_id: hyperparams}, sort_keys=False))


def normalize_kwargs(hyperparams: dict[str, Any]) -> dict[str, Any] | None:
    """VecNormalize keyword arguments from ``normalize`` (bool, dict or string), or None."""
    value = hyperparams.get("normalize", False)
    if isinstance(value, str):
        value = parse_python_literal(value)
    if value is False or value is None:
        return None
    kwargs = {} if value is True else dict(value)
    if "gamma" in hyperparams:  # as the zoo does: discount the reward normaliser like the agent
        kwargs.setdefault("gamma", float(hyperparams["gamma"]))
    return kwargs


# What a config's ``callback:`` and ``policy:`` may name, an allow-list (a config is data; a class
# it names is built with the arguments it gives): per key, the modules (and their submodules) a
# dotted path may lie in, checked before anything is imported, and the base class it must have.
ALLOWED_CLASSES: dict[str, tuple[tuple[str, ...], str]] = {
    "callback": (
        ("acl_env.training.callbacks", "stable_baselines3.common.callbacks"),
        "stable_baselines3.common.callbacks.BaseCallback",
    ),
    "policy": (
        ("acl_env.training.networks", "stable_baselines3"),
        "stable_baselines3.common.policies.BasePolicy",
    ),
}


def import_dotted(name: str, key: str = "callback") -> Any:
    """The class a dotted path (``package.module.Class``) in a config's ``key`` (``callback`` or
    ``policy``) names, if :data:`ALLOWED_CLASSES` allows it; ``ValueError`` saying why not. A
    module outside the allow-list is never imported."""
    modules, base_path = ALLOWED_CLASSES[key]
    module, _, attr = name.rpartition(".") if isinstance(name, str) else ("", "", "")
    if not module:
        raise ValueError(f"not a dotted path: {name!r}")
    if not any(module == m or module.startswith(f"{m}.") for m in modules):
        raise ValueError(
            f"{name!r} is not allowed for {key}: only classes of {' or '.join(modules)}"
        )
    try:
        value = getattr(importlib.import_module(module), attr)
    except (ImportError, AttributeError) as error:
        raise ValueError(f"cannot import {name!r}: {error}") from error
    base_module, _, base_name = base_path.rpartition(".")
    base = getattr(importlib.import_module(base_module), base_name)
    if not (isinstance(value, type) and issubclass(value, base)):
        raise ValueError(f"{name!r} is not a {base_name} class, as {key} needs")
    return value


def algo_kwargs(hyperparams: dict[str, Any]) -> dict[str, Any]:
    """Keyword arguments for the SB3 algorithm: strings parsed, ``lin_X`` made schedules, a
    dotted ``policy`` path imported (SB3's own aliases such as ``MlpPolicy`` stay strings)."""
    kwargs = {k: v for k, v in hyperparams.items() if k not in NON_ALGO_KEYS}
    if isinstance(kwargs.get("policy"), str) and "." in kwargs["policy"]:
        kwargs["policy"] = import_dotted(kwargs["policy"], "policy")
    if isinstance(kwargs.get("policy_kwargs"), str):
        kwargs["policy_kwargs"] = parse_python_literal(kwargs["policy_kwargs"])
    for key in ("learning_rate", "clip_range", "clip_range_vf"):
        value = kwargs.get(key)
        if isinstance(value, str):
            if not value.startswith("lin_"):
                raise ValueError(f"{key} must be a number or 'lin_<value>', got {value!r}")
            kwargs[key] = linear_schedule(float(value.removeprefix("lin_")))
    return kwargs


# --- environments --------------------------------------------------------------------------------


def import_gym_packages(packages: Iterable[str] | None) -> None:
    """Import extra modules that register environments (the zoo's ``--gym-packages``)."""
    for name in packages or ():
        importlib.import_module(name)


def make_env(env_id: str, env_kwargs: dict[str, Any] | None = None, **extra: Any) -> gymnasium.Env:
    """``gymnasium.make`` with the config's ``env_kwargs`` (copied, so callers keep theirs)."""
    return gymnasium.make(env_id, **{**(env_kwargs or {}), **extra})


def make_worker_env(env_id: str, **env_kwargs: Any) -> gymnasium.Env:
    """Env factory for subprocess workers: Ctrl-C and SIGTERM (to the whole process group) go to
    the trainer only, which saves and then closes the workers (orphans exit on a closed pipe)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    return make_env(env_id, env_kwargs)
