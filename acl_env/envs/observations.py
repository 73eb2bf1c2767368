"""What each observation entry of ``ACLClimbEnv`` is, in order: its names, for tools that carry a
trained policy over to an env that observes more (``acl-train --init-from``)."""

from __future__ import annotations

from typing import Any

from acl_env.envs.grip import GripController

IMU = ("imu_quat_w", "imu_quat_x", "imu_quat_y", "imu_quat_z", "gyro_x", "gyro_y", "gyro_z")
PRIVILEGED = ("com_x", "com_y", "com_z", "com_vel_x", "com_vel_y", "com_vel_z")


def observation_names(n_joints: int, grip_sections: int = 0, privileged: bool = False) -> tuple:
    """``angle_<j>``, ``velocity_<j>``, ``torque_<j>``, the head IMU, ``phase_cos``,
    ``phase_sin``, ``target_<j>`` (the gait's), then with the compliant grip
    ``grip_offset_<s>`` and ``grip_force_<s>`` per section, then the privileged centre of mass
    and its velocity."""
    joints = range(n_joints)
    names = [f"{q}_{j}" for q in ("angle", "velocity", "torque") for j in joints]
    names += [*IMU, "phase_cos", "phase_sin", *(f"target_{j}" for j in joints)]
    for quantity in ("offset", "force"):
        names += [f"grip_{quantity}_{s}" for s in range(grip_sections)]
    return tuple(names + (list(PRIVILEGED) if privileged else []))


def env_observation_names(env: Any) -> tuple:
    """:func:`observation_names` of an ``ACLClimbEnv`` (unwrapped)."""
    grip: GripController | None = env._grip
    sections = 0 if grip is None else grip.weights.shape[1]
    return observation_names(env.n_joints, sections, env.privileged_obs)


__all__ = ["env_observation_names", "observation_names"]
