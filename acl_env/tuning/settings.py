"""The tuner's settings from its parsed command line (:func:`settings_from_args`): every option
checked, the env built once per option so that its own checks name the option refused."""

from __future__ import annotations

import argparse
from typing import Any

import gymnasium
import yaml

from acl_env import ACL_CLIMB_ID, ACL_CLIMB_NOROLL_ID
from acl_env.cli import pairs_to_dict
from acl_env.gait.gaits import DEFAULT_POLE_RADIUS
from acl_env.training.config import load_hyperparams
from acl_env.tuning.checks import check_recipe
from acl_env.tuning.objective import OBJECTIVES, TuneSettings
from acl_env.tuning.space import GRIP_SPACE, UsageError, parse_condition, parse_space


def settings_from_args(args: argparse.Namespace) -> TuneSettings:
    """Validated settings; bad input raises :class:`UsageError` naming the argument."""
    max_arc = _checked_limits(args)
    env_id = args.env or (ACL_CLIMB_NOROLL_ID if args.no_roll else ACL_CLIMB_ID)
    if env_id not in gymnasium.registry or not env_id.startswith("acl_env/"):
        known = [k for k in gymnasium.registry if k.startswith("acl_env/")]
        raise UsageError("--env", f"unknown env {env_id!r}; known: {known}")
    weights = _reward_weights(args, env_id)
    _check_env(env_id, "--reward-weights", reward_weights=weights)
    _check_env(env_id, "--steps-per-cycle", steps_per_cycle=args.steps_per_cycle)
    _check_env(env_id, "--cycles", cycles_per_episode=args.cycles)
    condition = parse_condition(args.condition)
    space = _search_space(args, env_id, condition)
    settings = TuneSettings(
        env_id=env_id,
        objective=args.objective,
        reward_weights=weights,
        rolls_per_cycle=0 if args.no_roll else 1,
        seeds=tuple(args.seeds),
        steps_per_cycle=args.steps_per_cycle,
        cycles_per_episode=args.cycles,
        max_clipped=args.max_clipped,
        max_touched_arc_deg=max_arc,
        space=space,
        condition=condition,
        grip=args.grip,
        cvar=_checked_cvar(args),
        against_default=_checked_against_default(args),
    )
    for values in settings.conditions():  # the env checks the condition's values
        _check_env(env_id, "--condition", **values)
    return settings


def _checked_cvar(args: argparse.Namespace) -> float | None:
    """``--cvar``: a share in (0, 1], for an objective the study maximises."""
    share = getattr(args, "cvar", None)
    if share is None:
        return None
    if not 0.0 < share <= 1.0:
        raise UsageError("--cvar", f"must be in (0, 1], got {share}")
    if OBJECTIVES[args.objective] != "maximize":
        raise UsageError("--cvar", f"needs a maximised --objective, got {args.objective!r}")
    return float(share)


def _checked_against_default(args: argparse.Namespace) -> bool:
    """``--against-default``: it scores the margins of ``--cvar``'s conditions, so it needs it
    (in a ``--grip`` study the default is no gain: the margins are the grip's gain)."""
    if not getattr(args, "against_default", False):
        return False
    if getattr(args, "cvar", None) is None:
        raise UsageError("--against-default", "needs --cvar (it scores the conditions' margins)")
    return True


def _checked_limits(args: argparse.Namespace) -> float | None:
    """Check the objective, ``--max-clipped``, ``--max-arc`` and ``--seeds``; return the largest
    touched arc allowed (``--max-arc``, 90 degrees with ``--no-roll``, else None)."""
    if args.objective not in OBJECTIVES:
        raise UsageError("--objective", f"unknown {args.objective!r}; known: {list(OBJECTIVES)}")
    if not 0.0 <= args.max_clipped <= 1.0:
        raise UsageError("--max-clipped", f"must be in [0, 1], got {args.max_clipped}")
    max_arc = args.max_arc if args.max_arc is not None else (90.0 if args.no_roll else None)
    if max_arc is not None and not 0.0 < max_arc <= 360.0:
        raise UsageError("--max-arc", f"must be in (0, 360] degrees, got {max_arc}")
    if len(set(args.seeds)) != len(args.seeds):
        raise UsageError("--seeds", f"repeated seeds {args.seeds}")
    return max_arc


def _reward_weights(args: argparse.Namespace, env_id: str) -> dict[str, Any]:
    """``--reward-weights``, else the reward the recipe (``--config``'s entry) trains on."""
    if args.reward_weights is not None:
        try:
            return pairs_to_dict("--reward-weights", args.reward_weights)
        except argparse.ArgumentTypeError as exc:
            raise UsageError("--reward-weights", str(exc).split(": ", 1)[1]) from None
    try:
        hyperparams = load_hyperparams(args.config, env_id)
    except (OSError, KeyError, ValueError, TypeError, AttributeError, yaml.YAMLError) as exc:
        message = str(exc).splitlines()[0]
        where = "" if args.config in message else f"{args.config} entry {env_id}: "
        raise UsageError("--config", f"{where}{message}") from None
    if not isinstance(hyperparams, dict):
        raise UsageError("--config", f"{args.config} entry {env_id} is not a mapping")
    check_recipe(hyperparams, env_id, f"{args.config} entry {env_id}")
    # The entry's reward, else the one the env registers (a benchmark id's entry holds
    # only its domain randomisation): the reward the recipe trains on.
    registered = (gymnasium.spec(env_id).kwargs or {}).get("reward_weights") or {}
    entry = (hyperparams.get("env_kwargs") or {}).get("reward_weights")
    return dict(entry if entry is not None else registered)


def _search_space(
    args: argparse.Namespace, env_id: str, condition: dict[str, Any]
) -> dict[str, Any]:
    """``--space`` over the gait's parameters, or with ``--grip`` the grip's (the env's gait
    held fixed)."""
    radii = condition.get("pole_radius", DEFAULT_POLE_RADIUS)
    # the thinnest pole leaves the least helix radius for the radial wave
    space = parse_space(args.space, min(radii) if isinstance(radii, list) else radii)
    if args.grip:
        for option, given in (("--space", args.space), ("--start-from", args.start_from)):
            if given:
                raise UsageError(option, "searches the gait; --grip holds the env's gait fixed")
        _check_env(env_id, "--grip", grip_target=0.0)  # the SEA, and a gait to adapt
        space = dict(GRIP_SPACE)
    return space


def _check_env(env_id: str, option: str, **kwargs: Any) -> None:
    """Build the env with ``kwargs`` once, so that its own checks refuse them naming ``option``."""
    try:
        gymnasium.make(env_id, **kwargs).close()
    except (ValueError, TypeError, OverflowError) as exc:
        message = str(exc).split(" was raised from the environment creator")[0]
        raise UsageError(option, message) from None
