"""The series elastic actuator model (acl_env.actuators): latency, spring torque, motor speed,
the arguments that set them, and their randomisation."""

from __future__ import annotations

import copy
import pickle

import gymnasium as gym
import numpy as np
import pytest

import acl_env
from acl_env.actuators.sea import DEFLECTION_RESOLUTION, MOTOR_SPEED_LIMIT, SPRING_STIFFNESS
from acl_env.constants import CONTROL_DT
from acl_env.envs.acl_climb import ACLClimbEnv

N = 20


def _twin_steps(kwargs: dict, kick_step: int, steps: int) -> tuple[list, list]:
    """Joint angles after each step of two identical episodes, one with a kick at ``kick_step``."""
    runs = []
    for kick in (False, True):
        env = ACLClimbEnv(**kwargs)
        env.reset(seed=3)
        angles = []
        for i in range(steps):
            action = np.zeros(env.action_space.shape)
            if kick and i == kick_step:
                action[:] = 1.0
            env.step(action)
            angles.append(env.data.qpos[7:].copy())
        runs.append(angles)
    return runs[0], runs[1]


def test_control_latency_of_one_step_delays_the_first_effect_by_one_step() -> None:
    kwargs = {"actuator_model": "sea", "control_latency": CONTROL_DT, "residual_scale": 0.2}
    plain, kicked = _twin_steps(kwargs, kick_step=2, steps=5)
    # The step the action is sent in plays exactly as without it...
    for i in range(3):
        np.testing.assert_array_equal(plain[i], kicked[i])
    # ... and the next one moves the joints.
    assert np.abs(kicked[3] - plain[3]).max() > 1e-3


def test_without_latency_an_action_acts_in_its_own_step() -> None:
    kwargs = {"actuator_model": "sea", "control_latency": 0.0, "residual_scale": 0.2}
    plain, kicked = _twin_steps(kwargs, kick_step=2, steps=4)
    np.testing.assert_array_equal(plain[1], kicked[1])
    assert np.abs(kicked[2] - plain[2]).max() > 1e-3


def test_torque_observation_is_spring_stiffness_times_deflection() -> None:
    stiffness = 17.0
    env = ACLClimbEnv(actuator_model="sea", sensor_latency=0.0, spring_stiffness=stiffness)
    env.reset(seed=1)
    data, dt = env.data, env.model.opt.timestep
    count = stiffness * DEFLECTION_RESOLUTION  # N m per encoder count
    checked = 0
    for _ in range(30):
        obs, *_ = env.step(env.action_space.sample())
        torque = obs[2 * N : 3 * N]
        # The sensors read the joint at the start of MuJoCo's last step (q - qdot dt); the motor
        # angle is the PID's activation.
        deflection = data.act - (data.qpos[7:] - data.qvel[6:] * dt)
        spring = stiffness * deflection
        unsaturated = np.abs(spring) < 7.0
        # within half an encoder count (no sensor noise without domain randomisation)
        np.testing.assert_allclose(torque[unsaturated], spring[unsaturated], atol=0.5 * count)
        counts = torque / count
        np.testing.assert_allclose(counts, np.round(counts), atol=1e-6)
        checked += int(unsaturated.sum())
    assert checked > 300


def test_motor_speed_never_exceeds_the_limit() -> None:
    limit = 1.0
    env = ACLClimbEnv(
        actuator_model="sea", motor_speed_limit=limit, residual_scale=0.5, control_latency=0.0
    )
    env.reset(seed=0)
    model, data = env.model, env.data
    fastest = 0.0
    rng = np.random.default_rng(0)
    for _ in range(20):
        env.step(rng.choice([-1.0, 1.0], size=env.action_space.shape))
        fastest = max(fastest, float(np.abs(data.act_dot).max()))
    # the bang-bang residual asks for 1 rad per 0.1 s step: the motors run at their limit
    assert limit * 0.99 < fastest <= limit * (1 + 1e-9)
    assert model.actuator_dynprm[0, 1] == limit


def test_sea_options_are_exposed_validated_and_refused_on_the_servo() -> None:
    env = gym.make(acl_env.ACL_CLIMB_SEA_ID).unwrapped
    assert env.config.actuator.model.name == "sea"
    assert env.config.actuator.values["spring_stiffness"] == SPRING_STIFFNESS
    assert env.config.actuator.values["motor_speed_limit"] == MOTOR_SPEED_LIMIT
    assert env.config.actuator.values["control_latency"] == 0.01
    assert env.config.actuator.values["sensor_latency"] == 0.005
    servo = ACLClimbEnv()
    assert servo.config.actuator.model.name == "servo"
    assert "spring_stiffness" not in servo.config.actuator.values
    with pytest.raises(ValueError, match="spring_stiffness needs actuator_model='sea'"):
        ACLClimbEnv(spring_stiffness=20.0)
    with pytest.raises(ValueError, match="kp sets the servo's stiffness"):
        ACLClimbEnv(actuator_model="sea", kp=30.0)
    with pytest.raises(ValueError, match="motor_speed_limit"):
        ACLClimbEnv(actuator_model="sea", motor_speed_limit=0.0)
    with pytest.raises(ValueError, match="control_latency"):
        ACLClimbEnv(actuator_model="sea", control_latency=0.5)
    with pytest.raises(ValueError, match="actuator_model"):
        ACLClimbEnv(actuator_model="hydraulic")
    with pytest.raises(ValueError, match="kp"):
        ACLClimbEnv(actuator_model="sea", domain_randomization={"kp": (15.0, 25.0)})


def test_randomisation_draws_the_sea_parameters_into_the_model() -> None:
    ranges = {
        "spring_stiffness": (12.0, 14.0),
        "motor_speed_limit": (1.0, 1.5),
        "control_latency": (0.05, 0.1),
    }
    env = ACLClimbEnv(actuator_model="sea", domain_randomization=ranges)
    seen = []
    for seed in range(3):
        env.reset(seed=seed)
        stiffness = -env.model.actuator_biasprm[0, 1]
        speed = env.model.actuator_dynprm[0, 1]
        latency = env.model.actuator_delay[0]
        assert 12.0 <= stiffness <= 14.0 and 1.0 <= speed <= 1.5 and 0.05 <= latency <= 0.1
        seen.append((stiffness, speed, latency))
        env.step(np.zeros(env.action_space.shape))
    assert len(set(seen)) == 3
    assert set(
        ACLClimbEnv(actuator_model="sea", domain_randomization=True).config.randomization
    ) >= {
        "spring_stiffness",
        "motor_speed_limit",
        "control_latency",
    }


def test_sea_copies_continue_exactly() -> None:
    env = gym.make(acl_env.ACL_CLIMB_SEA_ID).unwrapped
    env.reset(seed=4)
    rng = np.random.default_rng(1)
    for _ in range(3):
        env.step(rng.uniform(-1, 1, env.action_space.shape))
    twins = [pickle.loads(pickle.dumps(env)), copy.deepcopy(env)]
    actions = rng.uniform(-1, 1, (4, *env.action_space.shape))
    expected = [env.step(a)[0] for a in actions]
    for twin in twins:
        np.testing.assert_array_equal([twin.step(a)[0] for a in actions], expected)


def test_servo_tasks_are_unchanged_by_the_sea_option() -> None:
    # the servo model builds no sensors, no history and no PID: the v1/v2 physics as published
    env = gym.make(acl_env.ACL_CLIMB_BENCHMARK_ID).unwrapped
    assert env.model.nhistory == 0
    assert env.model.nsensor == 2
    assert (env.model.actuator_dyntype == 0).all()


def test_the_start_ramp_waits_for_the_motors() -> None:
    """The SEA's motors reach the first keyframe before the episode starts, however far the placed
    pose is from it at their speed (a slow motor gets a longer ramp)."""
    for speed in (MOTOR_SPEED_LIMIT, 0.5):
        env = ACLClimbEnv(actuator_model="sea", motor_speed_limit=speed)
        for seed in range(3):
            env.reset(seed=seed)
            np.testing.assert_allclose(env.data.act, env.data.ctrl, atol=1e-9)
            np.testing.assert_allclose(env.data.ctrl, env._table[env._k0], atol=1e-12)
