"""The ideal position servo (``actuator_model="servo"``): the actuator of the servo tasks
(ACLClimbServo-v1, ACLClimbNoRollServo-v1) and the base envs they build on.

MuJoCo's ``position`` actuator of stiffness ``kp`` and damping 0.3 (the scene template's), no
speed limit, no latency, read without delay: the joint state itself and the servo's output
torque.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import mujoco

from acl_env.actuators.base import ActuatorConfig, ActuatorModel, Option
from acl_env.constants import DEFAULT_KP, actuator_name

KP_MAX = 200.0  # N m/rad

KP = Option(
    "kp",
    DEFAULT_KP,
    0.0,
    KP_MAX,
    "N m/rad",
    "servo stiffness (the series spring of the paper's model)",
    unset=DEFAULT_KP,
    low_open=True,
)


def set_servo_stiffness(model: mujoco.MjModel, kp: float) -> None:
    """The servo's stiffness ``kp`` (N m/rad): MuJoCo's position actuator keeps it as the gain and,
    negated, as the bias on the joint angle."""
    model.actuator_gainprm[:, 0] = kp
    model.actuator_biasprm[:, 1] = -kp


class Servo(ActuatorModel):
    """Ideal position servos: the template's actuators as they are."""

    name: ClassVar[str] = "servo"
    summary: ClassVar[str] = "ideal position servo, stiffness kp, no latency"
    options: ClassVar[tuple[Option, ...]] = (KP,)
    stiffness: ClassVar[str] = "kp"
    elastic: ClassVar[bool] = False
    randomization: ClassVar[dict[str, Any]] = {"kp": (15.0, 30.0)}
    randomization_bounds: ClassVar[dict[str, tuple[float, float]]] = {"kp": (0.0, KP_MAX)}
    drawn_before_mass: ClassVar[tuple[str, ...]] = ("kp",)

    def configure(self, spec: mujoco.MjSpec, setting: ActuatorConfig, n_joints: int) -> None:
        """The template's position servos, at stiffness ``kp`` (when given: else the
        template's)."""
        kp = setting.values.get("kp")
        if kp is None:
            return
        for j in range(n_joints):
            actuator = spec.actuator(actuator_name(j))
            actuator.gainprm[0] = kp
            actuator.biasprm[1] = -kp

    def apply(self, model: mujoco.MjModel, values: Mapping[str, float]) -> None:
        set_servo_stiffness(model, values["kp"])


__all__ = ["KP", "KP_MAX", "Servo", "set_servo_stiffness"]
