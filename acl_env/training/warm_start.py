"""Warm start: a new run's policy begins as a trained one, on an action space that may be larger.

A curriculum in one step: train the joint residual first, then add gait-modulation (or cadence)
actions and keep learning. ``acl-train --init-from POLICY_DIR`` builds the new run's model from its
own config, then copies from the trained policy

- every network weight whose name and shape agree (the shared layers of actor and critic, the
  value head): the architecture must match, which :func:`check_compatible` enforces;
- the action head's rows and the action log-std of each action the two envs share, matched by
  name (``ACLClimbEnv.action_names``: ``joint_3``, ``squeeze_section_1``, ``cadence``);
- the observation and return normalisation statistics (VecNormalize), so the copied layers see
  the inputs they were trained on.

The new env may also observe more than the trained one (the compliant grip's state,
``envs/observations.py`` names every entry): the input layers' columns and the statistics of the
observations the two share are copied by name, a new observation's columns are zero (the policy
first ignores it) and its statistics start at mean 0, variance 1. Every observation the trained
policy saw must still be there.

A new action's row and bias are zero: its mean starts at 0, which is the base gait unchanged (a
zero modulation or residual is bit-identical to the env without it), so the warm-started policy
first acts exactly as the trained one. Its log-std stays the config's ``log_std_init``: the new
actions explore at the rate the config chose, the copied ones at the rate they had learned.
The optimiser starts afresh.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

ACTION_HEAD = ("action_net.weight", "action_net.bias")
LOG_STD = "log_std"


@dataclass(frozen=True)
class TrainedStart:
    """A trained policy checked against the new run (by ``acl-train``'s plan): its model file,
    network weights, VecNormalize statistics (None without normalisation), the ``(new,
    trained)`` indices of the actions the two envs share and of the observations (the trained
    env's, all of them)."""

    model: Path
    state: dict[str, Any]
    normalization: Any
    shared: list[tuple[int, int]]
    observed: list[tuple[int, int]] | None = None  # None: the same observations


def action_map(source: Sequence[str], target: Sequence[str]) -> list[tuple[int, int]]:
    """``(target index, source index)`` of every action name the two lists share."""
    index = {name: i for i, name in enumerate(source)}
    return [(i, index[name]) for i, name in enumerate(target) if name in index]


def observation_map(source: Sequence[str], target: Sequence[str]) -> list[tuple[int, int]]:
    """``(target index, source index)`` of every observation of ``source`` (the trained env's);
    ``ValueError`` naming those the new env lacks."""
    missing = [name for name in source if name not in target]
    if missing:
        raise ValueError(
            f"the new env does not observe {', '.join(missing[:4])}"
            f"{' ...' if len(missing) > 4 else ''}, which the trained policy observes"
        )
    return action_map(source, target)


def _input_layer(a: tuple[int, ...], b: tuple[int, ...], observed: list | None) -> bool:
    """Whether tensors of shapes ``a`` (trained) and ``b`` (new) are an input layer's weights
    that differ only in the observations (``observed``: the map; None, the same ones)."""
    return (
        observed is not None
        and len(a) == len(b) == 2
        and a[0] == b[0]
        and a[1] == len(observed)
        and b[1] >= a[1]
    )


def check_compatible(
    source_state: dict[str, Any],
    target_state: dict[str, Any],
    shared: list[tuple[int, int]],
    observed: list[tuple[int, int]] | None = None,
) -> None:
    """``ValueError`` unless the two policies differ only in their action entries, and in the
    input layers' columns of observations the new env adds (``observed``).

    Every other tensor but the action head and log-std must have the same name and shape in
    both, and the actions must share at least one entry (else nothing trained would carry over).
    """
    if not shared:
        raise ValueError("the trained policy and the new env share no action")
    for name in sorted(set(source_state) | set(target_state)):
        if name in ACTION_HEAD or name == LOG_STD:
            continue
        if name not in source_state or name not in target_state:
            raise ValueError(
                f"network tensor {name!r} is in only one of the policies: "
                "the new run's policy_kwargs must build the same network"
            )
        a, b = tuple(source_state[name].shape), tuple(target_state[name].shape)
        if a != b and not _input_layer(a, b, observed):
            raise ValueError(
                f"network tensor {name!r} has shape {a} in the trained policy and {b} in the new "
                "one: the new run's policy_kwargs must build the same network"
            )
    a, b = source_state[LOG_STD].dim(), target_state[LOG_STD].dim()
    if a != b:
        raise ValueError(
            "one policy uses gSDE and the other does not (use_sde): their exploration "
            "parameters cannot be copied"
        )


def transfer(
    source_state: dict[str, Any],
    target_state: dict[str, Any],
    shared: list[tuple[int, int]],
    observed: list[tuple[int, int]] | None = None,
) -> dict[str, Any]:
    """The target's state dict with the source's weights copied in (see the module docstring).

    The action head's rows are indexed by action; ``log_std`` is ``(n_actions,)``, or
    ``(latent, n_actions)`` with gSDE, whose last axis is the action; an input layer's columns
    by observation (``observed``).
    """
    check_compatible(source_state, target_state, shared, observed)
    state = {name: tensor.clone() for name, tensor in target_state.items()}
    for name, tensor in source_state.items():
        if name in ACTION_HEAD or name == LOG_STD:
            continue
        if tensor.shape == state[name].shape:
            state[name] = tensor.clone()
        else:  # an input layer: the shared observations' columns, zero for new ones
            columns = [t for t, _ in observed or []]
            state[name].zero_()
            state[name][:, columns] = tensor[:, [s for _, s in observed or []]]
    target_rows = [t for t, _ in shared]
    source_rows = [s for _, s in shared]
    for name in ACTION_HEAD:
        state[name].zero_()
        state[name][target_rows] = source_state[name][source_rows]
    state[LOG_STD][..., target_rows] = source_state[LOG_STD][..., source_rows]
    return state


def copy_normalization(
    source: Any, target: Any, observed: list[tuple[int, int]] | None = None
) -> None:
    """Copy VecNormalize running statistics (observations, returns) from ``source`` to
    ``target``, the observations by ``observed`` (new ones at mean 0, variance 1); ``ValueError``
    if the observation shapes differ without such a map."""
    if observed is None and source.obs_rms.mean.shape != target.obs_rms.mean.shape:
        raise ValueError(
            f"the trained policy saw observations of shape {source.obs_rms.mean.shape}, "
            f"the new env makes {target.obs_rms.mean.shape}"
        )
    for name in ("obs_rms", "ret_rms"):
        src, dst = getattr(source, name), getattr(target, name)
        if name == "obs_rms" and observed is not None:
            mean, var = np.zeros_like(dst.mean), np.ones_like(dst.var)
            new, old = [t for t, _ in observed], [s for _, s in observed]
            mean[new], var[new] = src.mean[old], src.var[old]
            dst.mean, dst.var, dst.count = mean, var, src.count
        else:
            dst.mean, dst.var, dst.count = np.copy(src.mean), np.copy(src.var), src.count
