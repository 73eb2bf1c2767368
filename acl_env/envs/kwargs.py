"""Checks of env keyword arguments before any work, for every command that builds envs from a
config or a command line (evaluation, training, tuning): names against the env's signature,
values against its annotations, then the env's own validation. Numpy and Gymnasium only.
"""

from __future__ import annotations

import collections.abc
import inspect
import types
import typing
import warnings
from collections.abc import Callable, Mapping
from typing import Any

import gymnasium
from gymnasium.envs.registration import load_env_creator

from acl_env.validation import shown


class ConfigError(ValueError):
    """A configuration value that the trainer refuses; the message names it."""


def env_creator(env_id: str) -> Callable[..., gymnasium.Env]:
    """The registered entry point of ``env_id``; an unknown id lists the ``acl_env`` ones."""
    try:
        spec = gymnasium.spec(env_id)
    except gymnasium.error.Error:
        known = sorted(k for k in gymnasium.registry if k.startswith("acl_env/"))
        raise ConfigError(f"unknown env id {env_id!r} (registered: {', '.join(known)})") from None
    if callable(spec.entry_point):  # a renamed id (acl_env.renamed.RenamedId): the env's class
        return getattr(spec.entry_point, "target", spec.entry_point)
    return load_env_creator(spec.entry_point)


def _type_name(hint: Any) -> str:
    if isinstance(hint, type):
        return hint.__name__
    return str(hint).replace("typing.", "").replace("collections.abc.", "")


def _matches(value: Any, hint: Any) -> bool:
    """Whether ``value`` fits the annotation ``hint`` (the shapes used by env signatures)."""
    if hint is Any:
        return True
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (typing.Union, types.UnionType):
        return any(_matches(value, arg) for arg in args)
    if hint is type(None):
        return value is None
    if hint is bool:
        return isinstance(value, bool)
    if hint is int:
        return isinstance(value, int) and not isinstance(value, bool)
    if hint is float:
        return isinstance(value, int | float) and not isinstance(value, bool)
    if hint is str:
        return isinstance(value, str)
    if origin is tuple:
        if not isinstance(value, list | tuple):
            return False
        if len(args) == 2 and args[1] is Ellipsis:
            return all(_matches(item, args[0]) for item in value)
        return len(value) == len(args) and all(map(_matches, value, args))
    if origin in (list, collections.abc.Sequence):
        return isinstance(value, list | tuple) and all(_matches(v, args[0]) for v in value)
    if origin in (dict, collections.abc.Mapping):
        return isinstance(value, Mapping) and all(
            _matches(k, args[0]) and _matches(v, args[1]) for k, v in value.items()
        )
    return True  # an annotation this check does not model: the constructor decides


def make_quietly(env_id: str, **env_kwargs: Any) -> gymnasium.Env:
    """``gymnasium.make`` without gymnasium's note that ``env_id`` has a newer version: for the
    ids the library spells itself (the evaluation's controllers: a benchmark task as its base id
    and kwargs, the base gaits), where the note is about that spelling, not an id the user chose."""
    from acl_env import current_id  # a task's old id: made under its current name

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", ".*is out of date", DeprecationWarning)
        return gymnasium.make(current_id(env_id), **env_kwargs)


def check_env_kwargs(
    env_id: str, env_kwargs: Mapping[str, Any], quiet: bool = False
) -> gymnasium.Env:
    """Check ``env_kwargs`` against the env's signature (names, annotated types), then build one
    env with them so its own validation runs; return that env (the caller closes it). ``quiet``:
    an id the library spelled, built by :func:`make_quietly`."""
    creator = env_creator(env_id)
    signature = inspect.signature(creator)
    params = [p for p in signature.parameters if p != "self"]
    unknown = sorted(set(env_kwargs) - set(params))
    if unknown:
        raise ConfigError(f"unknown env kwargs {unknown} for {env_id} (accepted: {params})")
    try:
        hints = typing.get_type_hints(creator.__init__ if inspect.isclass(creator) else creator)
    except Exception:  # unresolvable annotations: leave the types to the constructor
        hints = {}
    for key, value in env_kwargs.items():
        hint = hints.get(key)
        if hint is not None and not _matches(value, hint):
            raise ConfigError(
                f"env kwarg {key} must be {_type_name(hint)}, got {shown(value)} "
                f"({type(value).__name__})"
            )
    spec_kwargs = dict(gymnasium.spec(env_id).kwargs)
    try:
        make = make_quietly if quiet else gymnasium.make
        return make(env_id, **{**spec_kwargs, **env_kwargs})
    except (TypeError, ValueError) as error:
        message = str(error).split(" was raised from the environment creator")[0]
        raise ConfigError(f"env kwargs refused by {env_id}: {message}") from None
