"""The start of an episode: the snake placed loosely around the pole at the gait's first keyframe,
then ramped into that keyframe's squeeze (the env's reference card, "Starting State")."""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import lru_cache
from typing import Any

import mujoco
import numpy as np

from acl_env.constants import JOINT_LIMIT, SEA_MODULE_RADIUS
from acl_env.gait import Gait
from acl_env.gait.kinematics import clear_placement

START_CLEARANCE = 0.005  # m between shells and pole when the snake is placed
START_HEIGHT = 0.3  # m from the floor to the lowest point of the snake at reset
RAMP_TIME = 0.3  # s to ramp the squeeze in from the placed pose to the first keyframe
SETTLE_TIME = 0.2  # s holding the first keyframe before the episode starts


@lru_cache(maxsize=2)
def _loose_gait(gait_type: type[Gait], items: tuple[tuple[str, Any], ...], radius: float) -> Gait:
    """The gait with its helix loosened to ``radius``. Gaits are immutable, and every reset on one
    pole tries the same radius first (:func:`clear_placement`): kept, it is not made again. Apart
    from the env's :func:`~acl_env.envs.gait_config.cached_gait`, which makes each gait's keyframe
    table: placing the snake needs one keyframe, and two loose gaits are all worth keeping."""
    return gait_type(**dict(items), radius=radius)


def placed_qpos(
    gait_type: type[Gait],
    gait_kwargs: Mapping[str, Any],
    phase: float,
    pole_radius: float,
    yaw: float,
    joint_noise: np.ndarray,
    qpos0: np.ndarray,
) -> np.ndarray:
    """The snake's ``qpos`` at gait ``phase`` (cycles) on a pole of ``pole_radius``: the keyframe
    of ``gait_type(**gait_kwargs)`` (its ``radius`` aside) with the helix loosened
    until every shell clears the pole by ``START_CLEARANCE``, fitted onto that helix (Kabsch),
    ``START_HEIGHT`` above the floor, turned by ``yaw`` (rad) about the pole, with
    ``joint_noise`` (rad) added to the joints and clipped to their limits; ``qpos0``: the model's
    initial ``qpos``."""
    items = tuple(sorted((k, v) for k, v in gait_kwargs.items() if k != "radius"))
    angles, rotation, translation = clear_placement(
        lambda radius: _loose_gait(gait_type, items, radius),
        phase,
        contact_radius=pole_radius + SEA_MODULE_RADIUS,
        clearance=START_CLEARANCE,
        height=START_HEIGHT,
    )
    c, s = math.cos(yaw), math.sin(yaw)
    yaw_rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    qpos = qpos0.copy()
    qpos[:3] = yaw_rot @ translation
    mujoco.mju_mat2Quat(qpos[3:7], (yaw_rot @ rotation).ravel())
    qpos[7 : 7 + len(angles)] = np.clip(angles + joint_noise, -JOINT_LIMIT, JOINT_LIMIT)
    return qpos


def ramp_in(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    start: np.ndarray,
    target: np.ndarray,
    ramp_time: float = RAMP_TIME,
) -> None:
    """Ramp the servo targets from the placed pose ``start`` to the first keyframe ``target`` in
    ``ramp_time`` (``RAMP_TIME``; the SEA's motors need longer, ``actuators.ramp_time``), then
    hold it for ``SETTLE_TIME``.

    Gravity is off while the squeeze ramps in (the loose start pose cannot hold yet, and would
    drop ~10 cm before gripping); it is back on for the hold, so the episode starts from a snake
    that carries its own weight.
    """
    chunks, dt = 10, model.opt.timestep
    per_chunk = max(1, round(ramp_time / dt / chunks))
    gravity = model.opt.gravity.copy()
    model.opt.gravity[:] = 0.0
    for i in range(1, chunks + 1):
        data.ctrl[:] = start + (target - start) * (i / chunks)
        mujoco.mj_step(model, data, nstep=per_chunk)
    model.opt.gravity[:] = gravity
    mujoco.mj_step(model, data, nstep=max(1, round(SETTLE_TIME / dt)))
    mujoco.mj_forward(model, data)


__all__ = ["RAMP_TIME", "SETTLE_TIME", "START_CLEARANCE", "START_HEIGHT", "placed_qpos", "ramp_in"]
