"""Domain randomisation of the climbing scene: the ranges, their validation, and one draw applied.

At every reset the env draws ``pole_radius``, ``friction``, ``mass_scale`` and the actuator
model's randomised options (the servo's ``kp``; the SEA's ``spring_stiffness``,
``motor_speed_limit`` and ``control_latency``: each model declares its own, with its defaults,
in :mod:`acl_env.actuators`) uniformly from their ``(low, high)`` ranges (the others keep the
env's nominal values), writes them into the compiled model, and scales the Gaussian sensor noise
of the observation.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from acl_env.actuators import DEFAULT_MODEL, ActuatorModel, actuator_model
from acl_env.constants import POLE_GEOM, link_name
from acl_env.model import snake_geom_ids
from acl_env.validation import check_finite, check_mapping, check_range, check_sequence, shown

# What domain_randomization=True draws on every actuator model; the model adds its own ranges.
SCENE_RANDOMIZATION: dict[str, Any] = {
    "pole_radius": (0.065, 0.09),
    "friction": (0.7, 1.2),
    "mass_scale": (0.9, 1.1),
    "sensor_noise": 0.01,
}
# Widest accepted (low, high) of the scene's ranges; the env passes its own argument bounds as
# well, and each actuator model its options'.
SCENE_BOUNDS: dict[str, tuple[float, float]] = {
    "pole_radius": (0.0, math.inf),
    "friction": (0.0, math.inf),
    # 0.2 g to 2 kg modules (x 0.205 kg): below 1e-3 the inertia matrix is singular, the physics
    # unstable from the first step
    "mass_scale": (1e-3, 10.0),
}
SENSOR_NOISE_MAX = 1.0  # rad: beyond this the angles are noise
# Events that domain_randomization can draw, never part of what True draws: the friction the
# pole changes to at a random step (envs/events.py), drawn after everything else.
EVENT_BOUNDS: dict[str, tuple[float, float]] = {"friction_step": (0.0, math.inf)}


def default_randomization(model: str | ActuatorModel) -> dict[str, Any]:
    """What ``domain_randomization=True`` draws on the actuator ``model`` (a name or a model)."""
    model = actuator_model(model) if isinstance(model, str) else model
    return {**SCENE_RANDOMIZATION, **model.randomization}


def randomization_bounds(model: ActuatorModel) -> dict[str, tuple[float, float]]:
    """The widest accepted ranges of every key a draw on ``model`` can set."""
    return {**SCENE_BOUNDS, **model.randomization_bounds, **EVENT_BOUNDS}


def randomization_keys(model: ActuatorModel) -> tuple[str, ...]:
    """The keys ``domain_randomization`` accepts on ``model``."""
    return (*SCENE_RANDOMIZATION, *model.randomized(), *EVENT_BOUNDS)


def draw_order(model: ActuatorModel) -> tuple[str, ...]:
    """The physical quantities a draw on ``model`` sets, in the order they are drawn (the order
    fixes the random stream, as every version has drawn them)."""
    late = [k for k in model.randomized() if k not in model.drawn_before_mass]
    return ("pole_radius", "friction", *model.drawn_before_mass, "mass_scale", *late)


def check_randomization(
    spec: object,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    model: str | ActuatorModel = DEFAULT_MODEL,
) -> dict[str, Any]:
    """Validated domain-randomisation ranges (empty when off; ``True`` gives the defaults).

    ``spec`` is ``None``, a bool or a mapping from :func:`randomization_keys` to ``(low, high)``
    pairs with ``0 < low <= high`` within :func:`randomization_bounds` (and ``sensor_noise`` to a
    std in [0, 1]). ``bounds`` (the env's accepted ranges of its own ``pole_radius``,
    ``friction``) caps the draws: a draw is a value the constructor would have accepted. The keys
    depend on the actuator ``model`` (``True`` gives :func:`default_randomization`);
    ``control_latency`` may start at 0.
    """
    model = actuator_model(model) if isinstance(model, str) else model
    known = randomization_keys(model)
    if spec is None:
        return {}
    if isinstance(spec, bool | np.bool_):
        return default_randomization(model) if spec else {}
    if not isinstance(spec, Mapping):
        raise TypeError(
            "domain_randomization must be None, True, False or a dict with keys from "
            f"{sorted(known)}, got {shown(spec)} ({type(spec).__name__})"
        )
    limits = {**randomization_bounds(model), **(bounds or {})}
    out: dict[str, Any] = {}
    for key, value in check_mapping(
        f"domain_randomization (actuator_model {model.name!r})", spec, known
    ).items():
        name = f"domain_randomization[{key!r}]"
        if key == "sensor_noise":
            out[key] = check_range(name, value, 0.0, SENSOR_NOISE_MAX)
            continue
        lo, hi = check_sequence(name, value, 2, check_finite)
        low, high = limits[key]
        floor = 0.0 <= lo if key == "control_latency" else 0.0 < lo
        if not (low <= lo and floor and lo <= hi <= high):
            relation = "<=" if key == "control_latency" else "<"
            raise ValueError(
                f"{name} must be (low, high) with {low} <= low, 0 {relation} low <= high <= "
                f"{high}, got {shown(value)}"
            )
        out[key] = (lo, hi)
    return out


def draw_physics(
    ranges: Mapping[str, Any], nominal: Mapping[str, float], rng: np.random.Generator
) -> dict[str, float]:
    """One draw of ``nominal``'s keys, in its order (:func:`draw_order`): uniform in ``ranges``
    where given, else the nominal value."""
    return {
        key: float(rng.uniform(*ranges[key])) if key in ranges else float(value)
        for key, value in nominal.items()
    }


@dataclass(frozen=True)
class RandomizedElements:
    """The model elements a draw writes, with the compiled masses and inertias it scales."""

    pole_geom: int
    snake_geoms: np.ndarray
    snake_bodies: np.ndarray
    mass: np.ndarray
    inertia: np.ndarray

    @classmethod
    def of(cls, model: mujoco.MjModel, n_joints: int) -> RandomizedElements:
        bodies = np.array([model.body(link_name(k)).id for k in range(n_joints + 1)])
        return cls(
            pole_geom=model.geom(POLE_GEOM).id,
            snake_geoms=snake_geom_ids(model, n_joints),
            snake_bodies=bodies,
            mass=model.body_mass[bodies].copy(),
            inertia=model.body_inertia[bodies].copy(),
        )


def apply_physics(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    elements: RandomizedElements,
    values: Mapping[str, float],
    actuators: ActuatorModel,
) -> None:
    """Write a draw (:func:`draw_physics`) into ``model`` (pole size, friction, link masses and
    inertias; the actuator options through ``actuators``), then recompute what the compiler
    derived from them."""
    model.geom_size[elements.pole_geom, 0] = values["pole_radius"]
    model.geom_friction[elements.snake_geoms, 0] = values["friction"]
    model.geom_friction[elements.pole_geom, 0] = values["friction"]
    actuators.apply(model, values)
    scale = values["mass_scale"]
    model.body_mass[elements.snake_bodies] = elements.mass * scale
    model.body_inertia[elements.snake_bodies] = elements.inertia * scale
    # The broadphase bounds of the pole (geom_rbound, geom_aabb) and the subtree masses that
    # subtree_com divides by.
    mujoco.mj_setConst(model, data)


def sensor_noise_std(ranges: Mapping[str, Any], kp: float, n_joints: int) -> np.ndarray:
    """Noise std on observed joint angles (rad), velocities (10x, rad/s), torques (``kp`` x, N m:
    the servo's or the spring's stiffness)."""
    return float(ranges.get("sensor_noise", 0.0)) * np.repeat([1.0, 10.0, kp], n_joints)
