"""What an actuator model is: its options, how it builds and reads the joints, and how a draw of
its randomised options is written into a compiled model.

An actuator model is one module of :mod:`acl_env.actuators` holding one :class:`ActuatorModel`
subclass. The env, the model builder, the randomisation and the evaluation ask it; none of them
names a model. The registry (``acl_env/actuators/__init__.py``) maps ``actuator_model`` to it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

import mujoco
import numpy as np

from acl_env.constants import CONTROL_DT

Model, Data, Array = mujoco.MjModel, mujoco.MjData, np.ndarray  # the methods' short types
# Accepted command and sensor latencies (s): up to two control steps.
LATENCY_RANGE = (0.0, 2 * CONTROL_DT)


@dataclass(frozen=True)
class Option:
    """One keyword argument of the env that an actuator model owns: its default (used when the
    argument is ``unset``), its accepted range, unit and meaning."""

    name: str
    default: float
    low: float
    high: float
    unit: str
    doc: str
    unset: float | None = None  # what the env's constructor passes when the user gives nothing
    low_open: bool = False  # the range excludes ``low``


@dataclass(frozen=True)
class ActuatorConfig:
    """A model with its checked option values, as the model builder needs it;
    ``history_latency`` (s) sizes the command history for randomised latencies."""

    model: ActuatorModel
    values: Mapping[str, float] = field(default_factory=dict)
    history_latency: float = 0.0

    def configure(self, spec: mujoco.MjSpec, n_joints: int) -> None:
        """Edit ``spec``'s joints and actuators (:meth:`ActuatorModel.configure`)."""
        self.model.configure(spec, self, n_joints)


class JointReadout:
    """What ideal joints report to the observation and the energy count: the joint state itself
    and the actuators' output torque. Holds views of MuJoCo's buffers, made once."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, n_joints: int) -> None:
        self.n = n_joints
        self._data = data
        self.torque = data.actuator_force  # applied torque, for the energy count
        self._angle, self._speed = data.qpos[7 : 7 + n_joints], data.qvel[6 : 6 + n_joints]

    def begin_step(self) -> None:
        """Mark where a step starts (models whose work needs it)."""

    def work(self, dt: float) -> float:
        """The actuators' work over the last ``dt`` s (J; motors do not regenerate): |torque|
        times the joint's speed now, times ``dt``."""
        return float(np.abs(self.torque) @ np.abs(self._speed)) * dt

    def read_torque(self, stiffness: float) -> np.ndarray:
        """The joint torques (N m) as the joints read them now."""
        return self.torque.copy()

    def observe(self, stiffness: float) -> np.ndarray:
        """Joint angles, velocities and torques, ``3 n`` values (``stiffness``: the joints'), in
        a new array (the env adds the sensor noise to it)."""
        return np.concatenate((self._angle, self._speed, self.torque))


class ActuatorModel:
    """One actuator model. Subclasses set the class attributes and override the methods whose
    default (the ideal position servo's behaviour) does not fit."""

    name: ClassVar[str]
    summary: ClassVar[str]  # one line for the docs' table
    options: ClassVar[tuple[Option, ...]]
    stiffness: ClassVar[str]  # the option that is the joint's stiffness (N m/rad)
    # Whether the joints measure a spring's torque: the compliant grip reads it, and the tasks on
    # this model play the gaits tuned on the SEA.
    elastic: ClassVar[bool]
    randomization: ClassVar[dict[str, Any]]  # what domain_randomization=True draws
    # Widest accepted (low, high) of each randomised option of this model.
    randomization_bounds: ClassVar[dict[str, tuple[float, float]]]
    # The model's options drawn before ``mass_scale`` (the order fixes the random stream: the
    # servo's ``kp`` has been drawn there since v1); the rest are drawn after it.
    drawn_before_mass: ClassVar[tuple[str, ...]] = ()

    def option(self, name: str) -> Option:
        """The option called ``name``."""
        return next(o for o in self.options if o.name == name)

    def defaults(self) -> dict[str, float]:
        """Every option at its default."""
        return {o.name: o.default for o in self.options}

    def randomized(self) -> tuple[str, ...]:
        """The options a draw can set, in the order they are drawn."""
        return tuple(self.randomization_bounds)

    def configure(self, spec: mujoco.MjSpec, setting: ActuatorConfig, n_joints: int) -> None:
        """Edit the template's position servos (``spec``) into this model's actuators, with the
        option values of ``setting``."""

    def readout(self, model: mujoco.MjModel, data: mujoco.MjData, n_joints: int) -> JointReadout:
        """What the joints report (:class:`JointReadout`)."""
        return JointReadout(model, data, n_joints)

    def apply(self, model: mujoco.MjModel, values: Mapping[str, float]) -> None:
        """Write a draw of :meth:`randomized` into a compiled ``model``."""

    def start(self, model: Model, data: Data, pose: Array, target: Array, shortest: float) -> float:
        """Put the actuators at rest at the placed pose ``pose`` (rad) before the start ramp;
        returns how long (s) the ramp to ``target`` must last, at least ``shortest``."""
        return shortest


def history_samples(latency: float, timestep: float) -> int:
    """Samples a MuJoCo history buffer needs to look ``latency`` s back (0: no buffer)."""
    if latency <= 0.0:
        return 0
    return math.ceil(latency / timestep - 1e-9) + 2


__all__ = [
    "LATENCY_RANGE",
    "ActuatorConfig",
    "ActuatorModel",
    "JointReadout",
    "Option",
    "history_samples",
]
