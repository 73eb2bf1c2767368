"""The joint actuators: the CMU SEA snake's series elastic actuator, or an ideal position servo.

``"sea"`` (the default of ACLClimb-v3 and ACLClimbNoRoll-v5) models each joint as the robot has
it: a geared motor, position-controlled by its firmware, drives the joint through a torsional
spring. It is built from MuJoCo's own facilities, nothing integrated by hand:

* the motor is MuJoCo's ``pid`` actuator with ``slewmax``: its activation is the motor's angle,
  which follows the command at most ``motor_speed_limit`` rad/s (the gearmotor's top speed; a
  high-ratio gearbox is not back-drivable, so the spring's torque does not move the motor);
* the spring is the actuator's gain, ``spring_stiffness`` N m/rad times the deflection (motor
  angle - joint angle), limited to the motor's +-7 N m peak; its damping is the joint's;
* the commands reach the motor ``control_latency`` s late (the actuator's ``delay``, with a
  history buffer), and the joint sensors (angle, velocity, spring torque) report
  ``sensor_latency`` s late (the sensors' ``delay``);
* the observed torque is the spring torque, ``spring_stiffness`` x deflection, read as the robot
  reads it: quantised by the deflection encoder (:data:`DEFLECTION_RESOLUTION` rad per count).

``"servo"`` is the ideal servo of the servo tasks (ACLClimbServo-v1, ACLClimbNoRollServo-v1) and
the base envs they build on: a ``position`` actuator of stiffness ``kp`` and damping 0.3, no speed
limit, no latency, read without delay. The comparison of the two, and of a
two-hinge model with the rotor inertia behind the spring, is in ``docs/actuators.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from acl_env.constants import (
    CONTROL_DT,
    PEAK_TORQUE,
    actuator_name,
    joint_name,
    sensor_name,
)

ACTUATOR_MODELS = ("sea", "servo")
# -- the SEA's numbers (docs/actuators.md says where each comes from) ---------------------------
# Not published for the SEA snake: chosen equal to the servo stiffness the v1 tasks were tuned on
# (kp 10-40 N m/rad climbs, 5 holds, 2 falls), and randomised over +-30 % in training.
SPRING_STIFFNESS = 20.0  # N m/rad
SPRING_DAMPING = 0.35  # N m s/rad: the joint's damping (the servo's 0.3 plus the joint's 0.05)
MOTOR_SPEED_LIMIT = 2.2  # rad/s: the module's top joint speed (CMU's published URDF)
# One tick of the 100 Hz SEA firmware between a command and the motor, and one 200 Hz feedback
# period between the joint and the observation.
CONTROL_LATENCY = 0.01  # s
SENSOR_LATENCY = 0.005  # s
# Not published: a 12-bit absolute encoder across the spring (0.0015 rad, 0.03 N m at 20 N m/rad).
DEFLECTION_RESOLUTION = 2.0 * math.pi / 4096  # rad per count
# The two-hinge candidate of benchmarks/step_response.py and two_hinge.py (not the shipped model):
# not published, about 3e-7 kg m^2 of rotor through the 349:1 gearbox of HEBI's SEA snake gain
# files, and a motor position loop 10x the spring.
ROTOR_INERTIA = 3e-7 * 349**2  # kg m^2 at the joint
MOTOR_KP = 200.0  # N m/rad
# Accepted ranges of the arguments (envs/arguments.py checks them by name).
SPRING_STIFFNESS_RANGE = (1.0, 200.0)  # N m/rad: below 1 the snake cannot lift its own modules
MOTOR_SPEED_LIMIT_RANGE = (0.1, 100.0)  # rad/s
LATENCY_RANGE = (0.0, 2 * CONTROL_DT)  # s: up to two control steps


@dataclass(frozen=True)
class ActuatorConfig:
    """What the model builder needs to know of the actuators (``actuator_model`` "sea" or
    "servo"); ``max_control_latency`` sizes the command history for randomised latencies."""

    model: str = "servo"
    spring_stiffness: float = SPRING_STIFFNESS
    motor_speed_limit: float = MOTOR_SPEED_LIMIT
    control_latency: float = 0.0
    sensor_latency: float = 0.0
    max_control_latency: float = 0.0

    @property
    def sea(self) -> bool:
        return self.model == "sea"


def history_samples(latency: float, timestep: float) -> int:
    """Samples a MuJoCo history buffer needs to look ``latency`` s back (0: no buffer)."""
    if latency <= 0.0:
        return 0
    return math.ceil(latency / timestep - 1e-9) + 2


def configure_spec(spec: mujoco.MjSpec, config: ActuatorConfig, n_joints: int) -> None:
    """Turn the template's position servos into series elastic actuators (``config.sea``), with
    their delays and joint sensors; a servo config leaves the spec as it is."""
    if not config.sea:
        return
    timestep = spec.option.timestep
    for j in range(n_joints):
        actuator = spec.actuator(actuator_name(j))
        actuator.set_to_pid(
            kp=config.spring_stiffness,
            kv=0.0,
            slewmax=config.motor_speed_limit,
            ctrlspec=int(mujoco.mjtCtrlInput.mjINPUT_POS),
        )
        actuator.forcerange = [-PEAK_TORQUE, PEAK_TORQUE]
        latency = max(config.control_latency, config.max_control_latency)
        if latency > 0.0:
            actuator.nsample = history_samples(latency, timestep)
            actuator.delay = config.control_latency
        joint = spec.joint(joint_name(j))
        joint.damping[0] = SPRING_DAMPING
    for kind, quantity in (
        (mujoco.mjtSensor.mjSENS_JOINTPOS, "angle"),
        (mujoco.mjtSensor.mjSENS_JOINTVEL, "velocity"),
        (mujoco.mjtSensor.mjSENS_ACTUATORFRC, "torque"),
    ):
        for j in range(n_joints):
            torque = kind == mujoco.mjtSensor.mjSENS_ACTUATORFRC
            sensor = spec.add_sensor(
                name=sensor_name(quantity, j),
                type=kind,
                objtype=mujoco.mjtObj.mjOBJ_ACTUATOR if torque else mujoco.mjtObj.mjOBJ_JOINT,
                objname=actuator_name(j) if torque else joint_name(j),
            )
            if config.sensor_latency > 0.0:
                sensor.nsample = history_samples(config.sensor_latency, timestep)
                sensor.delay = config.sensor_latency


def joint_sensor_indices(model: mujoco.MjModel, n_joints: int) -> np.ndarray:
    """Indices into ``sensordata`` of the SEA's joint angles, velocities and spring torques."""
    return np.array(
        [
            model.sensor_adr[model.sensor(sensor_name(quantity, j)).id]
            for quantity in ("angle", "velocity", "torque")
            for j in range(n_joints)
        ]
    )


def set_servo_stiffness(model: mujoco.MjModel, kp: float) -> None:
    """The servo's stiffness ``kp`` (N m/rad): MuJoCo's position actuator keeps it as the gain and,
    negated, as the bias on the joint angle."""
    model.actuator_gainprm[:, 0] = kp
    model.actuator_biasprm[:, 1] = -kp


def set_spring_stiffness(model: mujoco.MjModel, stiffness: float) -> None:
    """The SEA springs' stiffness (N m/rad): MuJoCo's PID actuator keeps its kp, negated, as the
    bias on the error between its activation (the motor angle) and the joint angle."""
    model.actuator_biasprm[:, 1] = -stiffness


def set_motor_speed_limit(model: mujoco.MjModel, speed: float) -> None:
    """The SEA motors' top speed (rad/s): the PID actuator's ``slewmax``."""
    model.actuator_dynprm[:, 1] = speed


def set_control_latency(model: mujoco.MjModel, latency: float) -> None:
    """The command latency (s) of every actuator, within the history the model was built with."""
    if latency == 0.0:
        model.actuator_delay[:] = 0.0
        return
    capacity = (model.actuator_history[:, 0].min() - 1) * model.opt.timestep
    if latency > capacity + 1e-12:
        raise ValueError(
            f"control_latency={latency} s exceeds the {capacity:.4g} s of command history the "
            "model was built with"
        )
    model.actuator_delay[:] = latency


def start_motors(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    start: np.ndarray,
    target: np.ndarray,
    shortest: float,
) -> float:
    """Motors at rest at ``start`` (the placed pose), with a command history that has always asked
    for it: the start ramp then begins from relaxed springs, not from zero. Returns how long the
    ramp to ``target`` must last for the motors to follow (:func:`ramp_time`)."""
    data.act[:] = start
    data.ctrl[:] = start
    for j, angle in enumerate(start):
        samples = int(model.actuator_history[j, 0])
        if samples > 0:
            values = np.full((samples, 1), float(angle))
            mujoco.mj_initCtrlHistory(model, data, j, None, values)
    return ramp_time(model, start, target, shortest)


def ramp_time(
    model: mujoco.MjModel, start: np.ndarray, target: np.ndarray, shortest: float
) -> float:
    """How long (s) the start ramp from ``start`` to ``target`` must last for the SEA's motors to
    follow it: the largest move at 80 % of the slowest motor's top speed, plus the command
    latency; at least ``shortest`` (the servo's ramp)."""
    speed = float(model.actuator_dynprm[:, 1].min())
    latency = float(model.actuator_delay.max())
    return max(shortest, float(np.abs(target - start).max()) / (0.8 * speed) + latency)


def read_torque(torque: np.ndarray, stiffness: float) -> np.ndarray:
    """The spring torque as the robot reads it (N m): ``stiffness`` x the deflection, which the
    encoder across the spring counts in steps of :data:`DEFLECTION_RESOLUTION`."""
    step = stiffness * DEFLECTION_RESOLUTION
    return np.round(torque / step) * step


class JointReadout:
    """What the joints report to the observation and the energy count: for the SEA its sensors
    (angle, velocity, encoder-read spring torque, ``sensor_latency`` late) and the motors' speed;
    for the servo the joint state itself and the servo's output torque."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, n_joints: int, sea: bool):
        self.sea, self.n = sea, n_joints
        self._data = data
        sensed = joint_sensor_indices(model, n_joints) if sea else None
        if sensed is not None and (np.diff(sensed) == 1).all():  # added in order: one view
            sensed = slice(int(sensed[0]), int(sensed[-1]) + 1)
        self._sensed = sensed
        self._torque_view = None  # the spring torques' part of it
        if isinstance(sensed, slice):
            self._torque_view = slice(sensed.start + 2 * n_joints, sensed.stop)
        elif sensed is not None:
            self._torque_view = sensed[2 * n_joints :]
        self.torque = data.actuator_force  # applied torque, for the energy count
        self._motor, self._joint_speed = data.act, data.qvel[6:]
        self._last_motor, self._moved = np.zeros(n_joints), np.zeros(n_joints)

    def begin_step(self) -> None:
        """Mark the motors' angles where a step starts (for :meth:`work`)."""
        if self.sea:
            self._last_motor[:] = self._motor

    def work(self, dt: float) -> float:
        """The actuators' work over the last ``dt`` s (J, motors that do not regenerate): for the
        SEA, |torque| times each motor's displacement over ``dt`` (a motor that slews in short
        bursts after each command is counted whole, which instants of its speed would miss); for
        the servo, |torque| times the joint's speed now, times ``dt``."""
        if not self.sea:
            return float(np.abs(self.torque) @ np.abs(self._joint_speed)) * dt
        moved = self._moved
        np.subtract(self._motor, self._last_motor, out=moved)
        self._last_motor[:] = self._motor
        return float(np.abs(self.torque) @ np.abs(moved, out=moved))

    def read_torque(self, stiffness: float) -> np.ndarray:
        """The spring torques (N m) as the joints read them now (:func:`read_torque`, the
        sensors' ``sensor_latency`` late); the servo's output torques."""
        if self._torque_view is None:
            return self.torque.copy()
        return read_torque(self._data.sensordata[self._torque_view], stiffness)

    def observe(self, stiffness: float) -> np.ndarray:
        """Joint angles, velocities and torques, ``3 n`` values (``stiffness``: the spring's)."""
        data = self._data
        if self._sensed is None:
            return np.concatenate((data.qpos[7:], data.qvel[6:], data.actuator_force))
        out = data.sensordata[self._sensed].copy()  # (a slice is a view of MuJoCo's buffer)
        out[2 * self.n :] = read_torque(out[2 * self.n :], stiffness)
        return out


__all__ = [
    "ACTUATOR_MODELS",
    "CONTROL_LATENCY",
    "DEFLECTION_RESOLUTION",
    "MOTOR_SPEED_LIMIT",
    "SENSOR_LATENCY",
    "SPRING_DAMPING",
    "SPRING_STIFFNESS",
    "ActuatorConfig",
    "JointReadout",
    "configure_spec",
    "history_samples",
    "joint_sensor_indices",
    "ramp_time",
    "read_torque",
    "set_control_latency",
    "set_motor_speed_limit",
    "set_servo_stiffness",
    "set_spring_stiffness",
    "start_motors",
]
