"""The series elastic actuator whose motor carries its rotor's inertia behind the spring
(``actuator_model="sea_rotor"``).

The shipped SEA (:mod:`acl_env.actuators.sea`) treats the motor as a position source: its angle
is the PID actuator's activation, and nothing the spring does can slow it. Here the motor is a
degree of freedom of its own, as in the two-hinge candidate of ``benchmarks/two_hinge.py``:

* per joint a rotor body (``rotor_<j>``, no geometry) with a hinge (``motor_<j>``) whose armature
  is the rotor's inertia reflected through the gearbox, :data:`ROTOR_INERTIA`;
* the spring is a fixed tendon (``spring_<j>``: joint angle - motor angle) of stiffness
  ``spring_stiffness`` and the SEA's damping; the joint hinge has no damping of its own;
* the motor is MuJoCo's PID actuator on the rotor hinge, stiff (:data:`MOTOR_KP`, critically
  damped), with the SEA's slew limit, +-7 N m and command latency;
* the torque sensor reads the spring's deflection (the tendon's length); the spring torque is
  ``-spring_stiffness`` times it, quantised by the SEA's encoder.

In generalised coordinates this is the two-hinge model's Lagrangian (the rotor's kinetic energy
on its own angle, the spring's on the deflection), with the snake's joints first in ``qpos``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import ClassVar

import mujoco
import numpy as np

from acl_env.actuators.base import ActuatorConfig, Array, Data, JointReadout, Model
from acl_env.actuators.sea import (
    SEA,
    SPRING_DAMPING,
    SensedReadout,
    add_joint_sensors,
    configure_motors,
    set_control_latency,
    set_motor_speed_limit,
    start_motors,
)
from acl_env.constants import actuator_name, joint_name

# Not published: about 3e-7 kg m^2 of rotor through the 349:1 gearbox of HEBI's SEA snake gain
# files, and a motor position loop 10x the spring.
ROTOR_INERTIA = 3e-7 * 349**2  # kg m^2 at the joint
MOTOR_KP = 200.0  # N m/rad
ROTOR_MASS = 1e-3  # kg: a rotor body's own mass, on its axis (its inertia is the armature's)


def rotor_name(j: int) -> str:
    return f"rotor_{j}"


def motor_name(j: int) -> str:
    return f"motor_{j}"


def spring_name(j: int) -> str:
    return f"spring_{j}"


def motor_qpos(model: mujoco.MjModel, n_joints: int) -> slice | np.ndarray:
    """Where the motors' angles sit in ``qpos`` (a slice: the rotors come after the snake)."""
    adr = [int(model.joint(motor_name(j)).qposadr[0]) for j in range(n_joints)]
    if adr == list(range(adr[0], adr[0] + n_joints)):
        return slice(adr[0], adr[0] + n_joints)
    return np.array(adr)


class RotorSEA(SEA):
    """The SEA with the motor as a rotor behind the spring."""

    name: ClassVar[str] = "sea_rotor"
    summary: ClassVar[str] = (
        "series elastic, the motor a rotor (reflected inertia) behind the spring"
    )

    def configure(self, spec: mujoco.MjSpec, setting: ActuatorConfig, n_joints: int) -> None:
        values = setting.values
        for j in range(n_joints):
            joint = spec.joint(joint_name(j))
            joint.damping[0] = 0.0
            rotor = spec.worldbody.add_body(
                name=rotor_name(j),
                mass=ROTOR_MASS,
                inertia=[1e-9, 1e-9, 1e-9],
                explicitinertial=True,
            )
            rotor.add_joint(
                name=motor_name(j), type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 0.0, 1.0]
            ).armature = ROTOR_INERTIA
            spring = spec.add_tendon(
                name=spring_name(j), stiffness=values["spring_stiffness"], damping=SPRING_DAMPING
            )
            spring.wrap_joint(joint_name(j), 1.0)
            spring.wrap_joint(motor_name(j), -1.0)
            spec.actuator(actuator_name(j)).target = motor_name(j)
        configure_motors(spec, setting, n_joints, kp=MOTOR_KP, dampratio=1.0)
        deflection = (mujoco.mjtSensor.mjSENS_TENDONPOS, mujoco.mjtObj.mjOBJ_TENDON)
        add_joint_sensors(
            spec, n_joints, lambda j: (*deflection, spring_name(j)), values["sensor_latency"]
        )

    def readout(self, model: mujoco.MjModel, data: mujoco.MjData, n_joints: int) -> JointReadout:
        return RotorReadout(model, data, n_joints, data.qpos[motor_qpos(model, n_joints)])

    def apply(self, model: mujoco.MjModel, values: Mapping[str, float]) -> None:
        model.tendon_stiffness[:] = values["spring_stiffness"]
        set_motor_speed_limit(model, values["motor_speed_limit"])
        set_control_latency(model, values["control_latency"])

    def start(self, model: Model, data: Data, pose: Array, target: Array, shortest: float) -> float:
        data.qpos[motor_qpos(model, len(pose))] = pose  # relaxed springs
        return start_motors(model, data, pose, target, shortest)


class RotorReadout(SensedReadout):
    """The SEA's readout, with the torque sensor reading the spring's deflection."""

    def spring_torque(self, reading: np.ndarray, stiffness: float) -> np.ndarray:
        return -stiffness * reading


__all__ = ["MOTOR_KP", "ROTOR_INERTIA", "RotorReadout", "RotorSEA", "motor_qpos"]
