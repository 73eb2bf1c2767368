"""The open-loop controllers of the protocol: the gait with a zero residual, at its own cadence or
at a constant one."""

from __future__ import annotations

from collections.abc import Sequence

import gymnasium
import numpy as np

from acl_env.evaluation.protocol import Policy


def zero_policy(env: gymnasium.Env) -> Policy:
    """The open-loop gait: a zero residual (and, with the cadence option, the gait's cadence)."""
    zero = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)
    return lambda obs: zero


def cadence_action(phase_rate: float, phase_rate_range: Sequence[float]) -> float:
    """The cadence action that plays ``phase_rate`` keyframes per step (the env's mapping
    ``1 + a (high - 1)`` for ``a >= 0``, ``1 + a (1 - low)`` below, inverted)."""
    low, high = phase_rate_range
    if not low <= phase_rate <= high:
        raise ValueError(f"phase_rate {phase_rate} is outside phase_rate_range {phase_rate_range}")
    if phase_rate >= 1.0:
        return (phase_rate - 1.0) / (high - 1.0) if high > 1.0 else 0.0
    return (phase_rate - 1.0) / (1.0 - low)


def constant_cadence_policy(env: gymnasium.Env, phase_rate: float) -> Policy:
    """The open-loop gait (zero residual) played at ``phase_rate`` keyframes per step; the env
    must have the cadence option (``phase_rate_range``)."""
    config = getattr(env.unwrapped, "config", None)  # an ACLClimbEnv's (envs/config.py)
    rate_range = None if config is None else config.gait.phase_rate_range
    if rate_range is None:
        raise ValueError("a constant cadence needs an env with phase_rate_range set")
    action = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)
    action[-1] = cadence_action(phase_rate, rate_range)
    return lambda obs: action
