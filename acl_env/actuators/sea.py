"""The CMU SEA snake's series elastic actuator (``actuator_model="sea"``, the default of
ACLClimb-v3 and ACLClimbNoRoll-v5).

Each joint as the robot has it: a geared motor, position-controlled by its firmware, drives the
joint through a torsional spring. It is built from MuJoCo's own facilities, nothing integrated by
hand:

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

The comparison with the ideal servo, and with a SEA whose motor carries its rotor's inertia, is
in ``docs/actuators.md``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, ClassVar

import mujoco
import numpy as np

from acl_env.actuators.base import (
    LATENCY_RANGE,
    ActuatorConfig,
    ActuatorModel,
    Array,
    Data,
    JointReadout,
    Model,
    Option,
)
from acl_env.actuators.base import history_samples as history_samples
from acl_env.constants import PEAK_TORQUE, actuator_name, joint_name, sensor_name

# -- the SEA's numbers (docs/actuators.md says where each comes from) ---------------------------
# Not published for the SEA snake: chosen equal to the servo stiffness the v1 tasks were tuned on
# (kp 10-40 N m/rad climbs, 5 holds, 2 falls), and randomised over +-20 % in training.
SPRING_STIFFNESS = 20.0  # N m/rad
SPRING_DAMPING = 0.35  # N m s/rad: the joint's damping (the servo's 0.3 plus the joint's 0.05)
MOTOR_SPEED_LIMIT = 2.2  # rad/s: the module's top joint speed (CMU's published URDF)
# One tick of the 100 Hz SEA firmware between a command and the motor, and one 200 Hz feedback
# period between the joint and the observation.
CONTROL_LATENCY = 0.01  # s
SENSOR_LATENCY = 0.005  # s
# Not published: a 12-bit absolute encoder across the spring (0.0015 rad, 0.03 N m at 20 N m/rad).
DEFLECTION_RESOLUTION = 2.0 * math.pi / 4096  # rad per count
# Accepted ranges of the options.
SPRING_STIFFNESS_RANGE = (1.0, 200.0)  # N m/rad: below 1 the snake cannot lift its own modules
MOTOR_SPEED_LIMIT_RANGE = (0.1, 100.0)  # rad/s

SEA_OPTIONS = (
    Option("spring_stiffness", SPRING_STIFFNESS, *SPRING_STIFFNESS_RANGE, "N m/rad", "SEA spring"),
    Option(
        "motor_speed_limit", MOTOR_SPEED_LIMIT, *MOTOR_SPEED_LIMIT_RANGE, "rad/s", "motor top speed"
    ),
    Option("control_latency", CONTROL_LATENCY, *LATENCY_RANGE, "s", "from a command to the motors"),
    Option("sensor_latency", SENSOR_LATENCY, *LATENCY_RANGE, "s", "from the joints to the sensors"),
)
# domain_randomization=True: the spring +-20 % (0.7x and 1.3x stay held out), the motor's top
# speed from the URDF's 2.2 rad/s to the 3.2 rad/s that the gearmotor reaches unloaded at 48 V,
# and up to two firmware ticks of command latency.
SEA_RANDOMIZATION: dict[str, Any] = {
    "spring_stiffness": (16.0, 24.0),
    "motor_speed_limit": (2.2, 3.2),
    "control_latency": (0.0, 0.02),
}
SEA_RANDOMIZATION_BOUNDS: dict[str, tuple[float, float]] = {
    "spring_stiffness": SPRING_STIFFNESS_RANGE,
    "motor_speed_limit": MOTOR_SPEED_LIMIT_RANGE,
    "control_latency": LATENCY_RANGE,
}
SENSED = ("angle", "velocity", "torque")  # the joint sensors, in the observation's order


def add_joint_sensors(spec: mujoco.MjSpec, n_joints: int, torque: Any, latency: float) -> None:
    """The joints' angle and velocity sensors and, per joint, the sensor ``torque(j)`` returns
    (its type, object type and object name), each ``latency`` s late."""
    timestep = spec.option.timestep
    for quantity in SENSED:
        for j in range(n_joints):
            if quantity == "torque":
                kind, objtype, objname = torque(j)
            else:
                kind = (
                    mujoco.mjtSensor.mjSENS_JOINTPOS
                    if quantity == "angle"
                    else mujoco.mjtSensor.mjSENS_JOINTVEL
                )
                objtype, objname = mujoco.mjtObj.mjOBJ_JOINT, joint_name(j)
            sensor = spec.add_sensor(
                name=sensor_name(quantity, j), type=kind, objtype=objtype, objname=objname
            )
            if latency > 0.0:
                sensor.nsample = history_samples(latency, timestep)
                sensor.delay = latency


def configure_motors(spec: mujoco.MjSpec, setting: ActuatorConfig, n_joints: int, **pid) -> None:
    """Each joint's actuator as a slew-limited PID motor at +-7 N m with the command delay
    (``pid``: the PID's gains), and room in its history for ``setting.history_latency``."""
    values = setting.values
    timestep = spec.option.timestep
    for j in range(n_joints):
        actuator = spec.actuator(actuator_name(j))
        actuator.set_to_pid(
            **pid,
            slewmax=values["motor_speed_limit"],
            ctrlspec=int(mujoco.mjtCtrlInput.mjINPUT_POS),
        )
        actuator.forcerange = [-PEAK_TORQUE, PEAK_TORQUE]
        latency = max(values["control_latency"], setting.history_latency)
        if latency > 0.0:
            actuator.nsample = history_samples(latency, timestep)
            actuator.delay = values["control_latency"]


def joint_sensor_indices(model: mujoco.MjModel, n_joints: int) -> np.ndarray:
    """Indices into ``sensordata`` of the joints' angles, velocities and torque readings."""
    return np.array(
        [
            model.sensor_adr[model.sensor(sensor_name(quantity, j)).id]
            for quantity in SENSED
            for j in range(n_joints)
        ]
    )


def set_motor_speed_limit(model: mujoco.MjModel, speed: float) -> None:
    """The motors' top speed (rad/s): the PID actuator's ``slewmax``."""
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


def start_motors(model: Model, data: Data, pose: Array, target: Array, shortest: float) -> float:
    """Motors at rest at ``pose`` (the placed pose), with a command history that has always asked
    for it: the start ramp then begins from relaxed springs, not from zero. Returns how long the
    ramp to ``target`` must last for the motors to follow (:func:`ramp_time`)."""
    data.act[:] = pose
    data.ctrl[:] = pose
    for j, angle in enumerate(pose):
        samples = int(model.actuator_history[j, 0])
        if samples > 0:
            values = np.full((samples, 1), float(angle))
            mujoco.mj_initCtrlHistory(model, data, j, None, values)
    return ramp_time(model, pose, target, shortest)


def ramp_time(
    model: mujoco.MjModel, start: np.ndarray, target: np.ndarray, shortest: float
) -> float:
    """How long (s) the start ramp from ``start`` to ``target`` must last for the motors to
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


class SensedReadout(JointReadout):
    """What the SEA's joints report: their sensors (angle, velocity, encoder-read spring torque,
    ``sensor_latency`` late); the energy count takes each motor's displacement (``motor``, the
    motors' angles as a view of MuJoCo's buffer)."""

    def __init__(
        self, model: mujoco.MjModel, data: mujoco.MjData, n_joints: int, motor: np.ndarray
    ) -> None:
        super().__init__(model, data, n_joints)
        sensed = joint_sensor_indices(model, n_joints)
        if (np.diff(sensed) == 1).all():  # added in order: one view
            self._sensed: slice | np.ndarray = slice(int(sensed[0]), int(sensed[-1]) + 1)
            self._torque_view: slice | np.ndarray = slice(
                int(sensed[0]) + 2 * n_joints, int(sensed[-1]) + 1
            )
        else:
            self._sensed, self._torque_view = sensed, sensed[2 * n_joints :]
        self._motor = motor
        self._last_motor, self._moved = np.zeros(n_joints), np.zeros(n_joints)

    def spring_torque(self, reading: np.ndarray, stiffness: float) -> np.ndarray:
        """The spring torque (N m) of a torque sensor ``reading`` (here: the torque itself)."""
        return reading

    def begin_step(self) -> None:
        self._last_motor[:] = self._motor

    def work(self, dt: float) -> float:
        """|torque| times each motor's displacement over the step (a motor that slews in short
        bursts after each command is counted whole, which instants of its speed would miss)."""
        moved = self._moved
        np.subtract(self._motor, self._last_motor, out=moved)
        self._last_motor[:] = self._motor
        return float(np.abs(self.torque) @ np.abs(moved, out=moved))

    def read_torque(self, stiffness: float) -> np.ndarray:
        """The spring torques (N m) as the joints read them now (:func:`read_torque`, the
        sensors' ``sensor_latency`` late)."""
        reading = self._data.sensordata[self._torque_view]
        return read_torque(self.spring_torque(reading, stiffness), stiffness)

    def observe(self, stiffness: float) -> np.ndarray:
        n = self.n
        out = self._data.sensordata[self._sensed].copy()  # (a slice is a view of MuJoCo's buffer)
        out[2 * n :] = read_torque(self.spring_torque(out[2 * n :], stiffness), stiffness)
        return out


class SEA(ActuatorModel):
    """The series elastic actuator: MuJoCo's PID actuator as motor and spring."""

    name: ClassVar[str] = "sea"
    summary: ClassVar[str] = "series elastic: slew-limited motor, spring as the PID's gain"
    options: ClassVar[tuple[Option, ...]] = SEA_OPTIONS
    stiffness: ClassVar[str] = "spring_stiffness"
    elastic: ClassVar[bool] = True
    randomization: ClassVar[dict[str, Any]] = SEA_RANDOMIZATION
    randomization_bounds: ClassVar[dict[str, tuple[float, float]]] = SEA_RANDOMIZATION_BOUNDS

    def configure(self, spec: mujoco.MjSpec, setting: ActuatorConfig, n_joints: int) -> None:
        """Turn the template's position servos into series elastic actuators, with their delays
        and joint sensors (the torque sensor: the PID's force, the spring torque)."""
        values = setting.values
        pid = {"kp": values["spring_stiffness"], "kv": 0.0}
        configure_motors(spec, setting, n_joints, **pid)
        for j in range(n_joints):
            spec.joint(joint_name(j)).damping[0] = SPRING_DAMPING
        force = (mujoco.mjtSensor.mjSENS_ACTUATORFRC, mujoco.mjtObj.mjOBJ_ACTUATOR)
        add_joint_sensors(
            spec, n_joints, lambda j: (*force, actuator_name(j)), values["sensor_latency"]
        )

    def readout(self, model: mujoco.MjModel, data: mujoco.MjData, n_joints: int) -> JointReadout:
        return SensedReadout(model, data, n_joints, data.act)

    def apply(self, model: mujoco.MjModel, values: Mapping[str, float]) -> None:
        # MuJoCo's PID actuator keeps its kp, negated, as the bias on the error between its
        # activation (the motor angle) and the joint angle.
        model.actuator_biasprm[:, 1] = -values["spring_stiffness"]
        set_motor_speed_limit(model, values["motor_speed_limit"])
        set_control_latency(model, values["control_latency"])

    def start(self, model: Model, data: Data, pose: Array, target: Array, shortest: float) -> float:
        return start_motors(model, data, pose, target, shortest)


__all__ = [
    "CONTROL_LATENCY",
    "DEFLECTION_RESOLUTION",
    "MOTOR_SPEED_LIMIT",
    "MOTOR_SPEED_LIMIT_RANGE",
    "SEA",
    "SEA_OPTIONS",
    "SEA_RANDOMIZATION",
    "SENSOR_LATENCY",
    "SPRING_DAMPING",
    "SPRING_STIFFNESS",
    "SPRING_STIFFNESS_RANGE",
    "SensedReadout",
    "add_joint_sensors",
    "configure_motors",
    "joint_sensor_indices",
    "ramp_time",
    "read_torque",
    "set_control_latency",
    "set_motor_speed_limit",
    "start_motors",
]
