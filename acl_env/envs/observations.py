"""The observation and action layouts of ``ACLClimbEnv``, declared once: each block's name, size,
unit and meaning, in order. The env builds its spaces from them, the exporter writes their names
into a policy's metadata, warm starts match entries by name (``acl-train --init-from``), and the
docs' tables are generated from them (``docs/hooks/layouts.py``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

IMU = ("imu_quat_w", "imu_quat_x", "imu_quat_y", "imu_quat_z", "gyro_x", "gyro_y", "gyro_z")
PRIVILEGED = (
    *("com_x", "com_y", "com_z", "com_vel_x", "com_vel_y", "com_vel_z"),
    *("friction", "pole_radius", "stiffness", "control_latency"),
)


@dataclass(frozen=True)
class Block:
    """A run of consecutive entries: its entries' names, unit and meaning; ``when``: the option
    that adds it (empty: always there)."""

    names: tuple[str, ...]
    unit: str
    meaning: str
    when: str = ""

    @property
    def size(self) -> int:
        return len(self.names)


def _per(prefix: str, count: int) -> tuple[str, ...]:
    return tuple(f"{prefix}_{i}" for i in range(count))


def sensed_blocks(n_joints: int) -> list[Block]:
    """The readings of the joints and the IMU: the observation's first blocks, and what
    ``obs_history`` keeps of past steps."""
    n = n_joints
    return [
        Block(_per("angle", n), "rad", "joint angles"),
        Block(_per("velocity", n), "rad/s", "joint velocities"),
        Block(
            _per("torque", n),
            "N m",
            "joint torques (SEA: spring stiffness x deflection as the encoder counts it; servo: "
            "its output)",
        ),
        Block(IMU[:4], "-", "head IMU orientation, quaternion (w, x, y, z)"),
        Block(IMU[4:], "rad/s", "head IMU angular velocity"),
    ]


def observation_layout(
    n_joints: int, grip_sections: int = 0, privileged: bool = False, history: int = 0
) -> tuple[Block, ...]:
    """What the robot senses, in order (``grip_sections``: the compliant grip's sections, 0
    without it; ``privileged``: ``privileged_obs``; ``history``: ``obs_history``). The
    privileged block comes last, for a critic to read and an actor to skip."""
    n = n_joints
    blocks = [
        *sensed_blocks(n),
        Block(("phase_cos", "phase_sin"), "-", "cos, sin of the gait phase of the next step"),
        Block(_per("target", n), "rad", "base gait's target angles for the next step"),
    ]
    if grip_sections:
        blocks += [
            Block(
                _per("grip_offset", grip_sections),
                "-",
                "each body section's squeeze offset, as a fraction of the grip's +-2 cm range",
                "grip_target",
            ),
            Block(
                _per("grip_force", grip_sections),
                "N",
                "each body section's grip force, measured from the spring torques",
                "grip_target",
            ),
        ]
    sensed = names(tuple(sensed_blocks(n)))
    for h in range(1, history + 1):
        blocks.append(
            Block(
                tuple(f"{name}_prev{h}" for name in sensed),
                "as the readings",
                f"the joint and IMU readings (angles to gyro) {h} step{'s' * (h > 1)} before",
                "obs_history",
            )
        )
    if privileged:
        blocks += [
            Block(PRIVILEGED[:3], "m", "centre of mass position", "privileged_obs"),
            Block(PRIVILEGED[3:6], "m/s", "centre of mass velocity", "privileged_obs"),
            Block(PRIVILEGED[6:7], "-", "the pole's sliding friction now", "privileged_obs"),
            Block(PRIVILEGED[7:8], "m", "the pole's radius", "privileged_obs"),
            Block(
                PRIVILEGED[8:9],
                "N m/rad",
                "the joints' stiffness (SEA: the springs'; servo: its kp)",
                "privileged_obs",
            ),
            Block(PRIVILEGED[9:], "s", "the command latency", "privileged_obs"),
        ]
    return tuple(blocks)


class ReadingHistory:
    """The last ``frames`` steps' joint and IMU readings (``obs_history``), newest first."""

    def __init__(self, frames: int, n_joints: int) -> None:
        self.frames = frames
        self._readings = np.zeros((frames, size(tuple(sensed_blocks(n_joints)))))

    def read_then_keep(self, sensed: np.ndarray, reset: bool) -> np.ndarray:
        """The kept readings, flat (at a reset, every one is ``sensed``); then keep ``sensed``."""
        readings = self._readings
        if reset:
            readings[:] = sensed
        out = readings.ravel().copy()
        readings[1:] = readings[:-1]
        readings[0] = sensed
        return out


def privileged_physics(model: mujoco.MjModel, pole_geom: int, stiffness: float) -> np.ndarray:
    """The physics entries of the privileged block: the pole's sliding friction as the model holds
    it now (after a friction step, the new one), its radius, the joints' ``stiffness`` (N m/rad)
    and the command latency (s)."""
    friction, radius = model.geom_friction[pole_geom, 0], model.geom_size[pole_geom, 0]
    latency = float(model.actuator_delay.max()) if model.nu else 0.0
    return np.array([friction, radius, stiffness, latency])


def action_layout(
    n_joints: int,
    modulated: tuple[str, ...] = (),
    sections: int = 0,
    grip: bool = False,
    cadence: bool = False,
) -> tuple[Block, ...]:
    """What each action entry drives, in order: the joints' residuals, then per modulated gait
    parameter one entry per body section (head first), then the grip's target per section, then
    the cadence. Every entry is in [-1, 1]."""
    blocks = [Block(_per("joint", n_joints), "residual_scale rad", "residual of each joint")]
    for key in modulated:
        blocks.append(
            Block(
                _per(f"{key}_section", sections),
                "gait_modulation m",
                f"offset of the gait's {key} in each body section",
                "gait_modulation",
            )
        )
    if grip:
        blocks.append(
            Block(
                _per("grip_section", sections),
                "grip_action_scale N",
                "change of each section's grip target",
                "grip_action_scale",
            )
        )
    if cadence:
        blocks.append(
            Block(("cadence",), "-", "keyframes the gait advances this step", "phase_rate_range")
        )
    return tuple(blocks)


def names(layout: tuple[Block, ...]) -> tuple[str, ...]:
    """Every entry's name, in order."""
    return tuple(name for block in layout for name in block.names)


def size(layout: tuple[Block, ...]) -> int:
    """The number of entries."""
    return sum(block.size for block in layout)


def env_observation_layout(env: Any) -> tuple[Block, ...]:
    """:func:`observation_layout` of an ``ACLClimbEnv`` (unwrapped), from its config."""
    config = env.config
    sections = 0 if config.grip is None else config.gait.modulation_sections
    episode = config.episode
    return observation_layout(env.n_joints, sections, episode.privileged_obs, episode.obs_history)


def env_action_layout(env: Any) -> tuple[Block, ...]:
    """:func:`action_layout` of an ``ACLClimbEnv`` (unwrapped), from its config."""
    gait, grip = env.config.gait, env.config.grip
    return action_layout(
        env.n_joints,
        gait.modulated,
        gait.modulation_sections,
        grip=grip is not None and grip.action_scale > 0.0,
        cadence=gait.phase_rate_range is not None,
    )


def env_observation_names(env: Any) -> tuple[str, ...]:
    """The names of an ``ACLClimbEnv``'s (unwrapped) observation entries."""
    return names(env_observation_layout(env))


__all__ = [
    "Block",
    "ReadingHistory",
    "action_layout",
    "env_action_layout",
    "env_observation_layout",
    "env_observation_names",
    "names",
    "observation_layout",
    "privileged_physics",
    "sensed_blocks",
    "size",
]
