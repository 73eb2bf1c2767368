"""Domain randomisation of the climbing scene: the ranges, their validation, and one draw applied.

At every reset the env draws ``pole_radius``, ``friction``, ``mass_scale`` and the actuators'
parameters (the servo's ``kp``; the SEA's ``spring_stiffness``, ``motor_speed_limit`` and
``control_latency``) uniformly from their ``(low, high)`` ranges (the others keep the env's
nominal values), writes them into the compiled model, and scales the Gaussian sensor noise of the
observation.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from acl_env import actuators
from acl_env.constants import POLE_GEOM, link_name
from acl_env.model import snake_geom_ids
from acl_env.validation import check_finite, check_mapping, check_range, check_sequence, shown

DEFAULT_RANDOMIZATION: dict[str, Any] = {
    "pole_radius": (0.065, 0.09),
    "friction": (0.7, 1.2),
    "kp": (15.0, 30.0),
    "mass_scale": (0.9, 1.1),
    "sensor_noise": 0.01,
}
# The SEA model's defaults: the servo's, with the spring instead of kp (+-20 %: 0.7x and 1.3x
# stay held out), the motor's top speed from the URDF's 2.2 rad/s to the 3.2 rad/s that the
# gearmotor reaches unloaded at 48 V, and up to two firmware ticks of command latency.
SEA_RANDOMIZATION: dict[str, Any] = {
    "pole_radius": (0.065, 0.09),
    "friction": (0.7, 1.2),
    "spring_stiffness": (16.0, 24.0),
    "mass_scale": (0.9, 1.1),
    "sensor_noise": 0.01,
    "motor_speed_limit": (2.2, 3.2),
    "control_latency": (0.0, 0.02),
}
# The keys each actuator model accepts.
RANDOMIZATION_KEYS = {
    "servo": tuple(DEFAULT_RANDOMIZATION),
    "sea": tuple(SEA_RANDOMIZATION),
}
# Widest accepted (low, high) of each range; the env passes its own argument bounds as well.
RANGE_BOUNDS: dict[str, tuple[float, float]] = {
    "pole_radius": (0.0, math.inf),
    "friction": (0.0, math.inf),
    "kp": (0.0, math.inf),
    # 0.2 g to 2 kg modules (x 0.205 kg): below 1e-3 the inertia matrix is singular, the physics
    # unstable from the first step
    "mass_scale": (1e-3, 10.0),
    "spring_stiffness": actuators.SPRING_STIFFNESS_RANGE,
    "motor_speed_limit": actuators.MOTOR_SPEED_LIMIT_RANGE,
    "control_latency": actuators.LATENCY_RANGE,
}
SENSOR_NOISE_MAX = 1.0  # rad: beyond this the angles are noise
# The physical quantities a draw sets, in the order they are drawn (the order fixes the stream).
# Keys an actuator model does not have are None in its nominal values and never drawn.
PHYSICS_KEYS = (
    "pole_radius",
    "friction",
    "kp",
    "mass_scale",
    "spring_stiffness",
    "motor_speed_limit",
    "control_latency",
)


def check_randomization(
    spec: object,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    actuator_model: str = "servo",
) -> dict[str, Any]:
    """Validated domain-randomisation ranges (empty when off; ``True`` gives the defaults).

    ``spec`` is ``None``, a bool or a mapping from :data:`DEFAULT_RANDOMIZATION`'s keys to
    ``(low, high)`` pairs with ``0 < low <= high`` within :data:`RANGE_BOUNDS` (and
    ``sensor_noise`` to a std in [0, 1]).
    ``bounds`` (the env's accepted ranges of its own ``pole_radius``, ``friction``, ``kp``) caps
    the draws: a draw is a value the constructor would have accepted. The keys depend on the
    ``actuator_model`` (:data:`RANDOMIZATION_KEYS`; ``True`` gives :data:`SEA_RANDOMIZATION` for
    the SEA); ``control_latency`` may start at 0.
    """
    known = RANDOMIZATION_KEYS[actuator_model]
    if spec is None:
        return {}
    if isinstance(spec, bool | np.bool_):
        defaults = SEA_RANDOMIZATION if actuator_model == "sea" else DEFAULT_RANDOMIZATION
        return dict(defaults) if spec else {}
    if not isinstance(spec, Mapping):
        raise TypeError(
            "domain_randomization must be None, True, False or a dict with keys from "
            f"{sorted(known)}, got {shown(spec)} ({type(spec).__name__})"
        )
    limits = {**RANGE_BOUNDS, **(bounds or {})}
    out: dict[str, Any] = {}
    for key, value in check_mapping(
        f"domain_randomization (actuator_model {actuator_model!r})", spec, known
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
    ranges: Mapping[str, Any], nominal: Mapping[str, float | None], rng: np.random.Generator
) -> dict[str, float]:
    """One draw of :data:`PHYSICS_KEYS`: uniform in ``ranges`` where given, else ``nominal``;
    the keys whose nominal value is None (not of this actuator model) are left out."""
    return {
        key: float(rng.uniform(*ranges[key])) if key in ranges else float(value)
        for key in PHYSICS_KEYS
        if (value := nominal[key]) is not None
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
) -> None:
    """Write a draw of :data:`PHYSICS_KEYS` into ``model`` (pole size, friction, actuator
    parameters, link masses and inertias), then recompute what the compiler derived from them."""
    model.geom_size[elements.pole_geom, 0] = values["pole_radius"]
    model.geom_friction[elements.snake_geoms, 0] = values["friction"]
    model.geom_friction[elements.pole_geom, 0] = values["friction"]
    if "kp" in values:
        actuators.set_servo_stiffness(model, values["kp"])
    if "spring_stiffness" in values:
        actuators.set_spring_stiffness(model, values["spring_stiffness"])
        actuators.set_motor_speed_limit(model, values["motor_speed_limit"])
        actuators.set_control_latency(model, values["control_latency"])
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
