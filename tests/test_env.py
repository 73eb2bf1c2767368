"""The Gymnasium environments: API conformance, determinism, reward bookkeeping, physics."""

from __future__ import annotations

import pickle
import warnings
from pathlib import Path

import gymnasium as gym
import mujoco
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from acl_env import (
    ACL_CLIMB_ID,
    ACL_CLIMB_NOROLL_SEA_ID,
    ACL_CLIMB_SEA_ID,
    ROLLING_HELIX_CLIMB_ID,
)
from acl_env.constants import (
    PHYSICS_TIMESTEP,
    POLE_GEOM,
    SEA_MODULE_LENGTH,
    SEA_MODULE_RADIUS,
    joint_name,
)
from acl_env.envs import ACLClimbEnv
from acl_env.envs import observations as layouts
from acl_env.envs.observations import PRIVILEGED
from acl_env.gait import ACLGait
from acl_env.gait.kinematics import (
    clear_placement,
    forward_kinematics,
    min_axis_distance,
    rigid_fit,
)

ENV_IDS = [ACL_CLIMB_ID, ROLLING_HELIX_CLIMB_ID]
SHORT = {"steps_per_cycle": 20, "cycles_per_episode": 1}


def rollout(env: gym.Env, seed: int, actions: np.ndarray) -> list[tuple]:
    """Observations, rewards and infos of a reset plus the given actions."""
    obs, info = env.reset(seed=seed)
    out = [(obs.copy(), 0.0, info)]
    for action in actions:
        obs, reward, terminated, truncated, info = env.step(action)
        out.append((obs.copy(), reward, info))
        if terminated or truncated:
            break
    return out


def assert_same(a: list[tuple], b: list[tuple]) -> None:
    assert len(a) == len(b)
    for (obs_a, rew_a, info_a), (obs_b, rew_b, info_b) in zip(a, b, strict=True):
        np.testing.assert_array_equal(obs_a, obs_b)
        assert rew_a == rew_b
        assert info_a == info_b


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_gymnasium_check_env(env_id: str) -> None:
    env = gym.make(env_id, **SHORT)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped, skip_render_check=True)
    # Unbounded observations (velocities, torques) are expected, as in Gymnasium's MuJoCo envs.
    unexpected = [str(w.message) for w in caught if "infinity" not in str(w.message)]
    assert not unexpected, unexpected
    env.close()


@pytest.mark.parametrize("env_id", [ACL_CLIMB_SEA_ID, ACL_CLIMB_NOROLL_SEA_ID])
def test_gymnasium_check_env_on_the_sea(env_id: str) -> None:
    test_gymnasium_check_env(env_id)


@pytest.mark.parametrize("env_id", [ACL_CLIMB_ID, ACL_CLIMB_SEA_ID])
def test_sb3_check_env(env_id: str) -> None:
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = gym.make(env_id, **SHORT)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sb3_check_env(env.unwrapped, warn=True)
    assert not [str(w.message) for w in caught]
    env.close()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_registered_with_gait(env_id: str) -> None:
    env = gym.make(env_id)
    expected = "ACLGait" if "ACL" in env_id else "RollingHelixGait"
    assert type(env.unwrapped.gait).__name__ == expected
    assert env.unwrapped.dt == pytest.approx(0.1)
    assert env.action_space.shape == (20,)
    assert env.observation_space.shape == (89,)


def test_same_seed_same_rollout() -> None:
    actions = np.random.default_rng(0).uniform(-1, 1, (15, 20)).astype(np.float32)
    env_a, env_b = gym.make(ACL_CLIMB_ID), gym.make(ACL_CLIMB_ID)
    assert_same(rollout(env_a, 3, actions), rollout(env_b, 3, actions))
    # A different seed gives a different start.
    other = rollout(env_a, 4, actions[:1])
    assert not np.array_equal(other[0][0], rollout(env_b, 3, actions[:1])[0][0])


def test_pickled_env_reproduces_reset_and_step() -> None:
    """A pickle of an env that was reset and stepped continues exactly where the original was
    (this episode's randomised physics, phase, RNG), then resets like it."""
    actions = np.random.default_rng(1).uniform(-1, 1, (10, 20)).astype(np.float32)
    env = gym.make(ENV_IDS[0], domain_randomization=True).unwrapped
    env.reset(seed=7)
    for action in actions[:4]:
        env.step(action)
    clone = pickle.loads(pickle.dumps(env))
    for action in actions[4:]:
        (obs_a, *rest_a), (obs_b, *rest_b) = env.step(action), clone.step(action)
        np.testing.assert_array_equal(obs_a, obs_b)
        assert rest_a == rest_b
    assert_same(rollout(env, 8, actions), rollout(clone, 8, actions))


def test_reward_is_sum_of_terms_and_obs_in_space() -> None:
    weights = {"climb": 2.0, "slip": 3.0, "energy": 1e-3, "action_rate": 0.5}
    env = gym.make(ACL_CLIMB_ID, reward_weights=weights)
    obs, _ = env.reset(seed=0)
    assert env.observation_space.contains(obs)
    rng = np.random.default_rng(2)
    last = np.zeros(20)  # the step after a reset compares with a zero action
    for _ in range(30):
        action = rng.uniform(-1.5, 1.5, 20)  # partly outside the box: the clipped action counts
        obs, reward, _, _, info = env.step(action)
        terms = [v for k, v in info.items() if k.startswith("reward_")]
        assert sorted(k for k in info if k.startswith("reward_")) == [
            "reward_action_rate",
            "reward_climb",
            "reward_energy",
            "reward_roll",
            "reward_slip",
        ]
        assert reward == sum(terms)
        assert info["reward_roll"] == 0.0  # off by default (the non-rolling task weighs it)
        assert info["reward_energy"] == -1e-3 * info["energy"] < 0.0
        assert info["reward_climb"] == 2.0 * info["climb"]
        assert info["reward_slip"] == -3.0 * info["slip"]
        clipped = np.clip(action, -1.0, 1.0)
        assert info["action_rate"] == pytest.approx(np.mean((clipped - last) ** 2), rel=1e-12)
        assert info["reward_action_rate"] == -0.5 * info["action_rate"] < 0.0
        last = clipped
        assert info["slip"] >= 0.0 and info["energy"] >= 0.0
        assert np.all(np.isfinite(obs)) and env.observation_space.contains(obs)


def test_action_rate_restarts_from_zero_at_reset() -> None:
    env = gym.make(ACL_CLIMB_ID)
    env.reset(seed=0)
    env.step(np.ones(20))
    _, _, _, _, info = env.step(np.ones(20))
    assert info["action_rate"] == 0.0 and info["reward_action_rate"] == 0.0  # weight 0: off
    env.reset(seed=1)
    _, _, _, _, info = env.step(np.full(20, 0.5))
    assert info["action_rate"] == pytest.approx(0.25)


def test_zero_action_is_the_open_loop_gait_and_residual_is_clipped() -> None:
    env = gym.make(ACL_CLIMB_ID, residual_scale=0.3).unwrapped
    env.reset(seed=0)
    table = env.gait.cycle()
    k = env._k0 + 1  # the reset ramp ends holding keyframe k0; the first step plays the next
    env.step(np.zeros(20, dtype=np.float32))
    np.testing.assert_array_equal(env.data.ctrl, table[k])
    # target = clip(gait + scale * clip(action, -1, 1), joint range)
    action = np.linspace(-3.0, 3.0, 20)
    env.step(action)
    expected = np.clip(table[k + 1] + 0.3 * np.clip(action, -1, 1), -np.pi / 2, np.pi / 2)
    np.testing.assert_allclose(env.data.ctrl, expected, rtol=0, atol=1e-12)
    assert np.all(np.abs(env.data.ctrl) <= np.pi / 2)


def test_out_of_range_actions_equal_clipped_actions() -> None:
    big = np.full((5, 20), 7.0, dtype=np.float32)
    env_a, env_b = gym.make(ACL_CLIMB_ID), gym.make(ACL_CLIMB_ID)
    assert_same(rollout(env_a, 0, big), rollout(env_b, 0, np.clip(big, -1, 1)))


@pytest.mark.parametrize(
    ("action", "match"),
    [
        (np.full(20, np.nan), "finite"),
        (np.full(20, np.inf), "finite"),
        (np.zeros(19), "shape"),
    ],
)
def test_bad_actions_raise(action: np.ndarray, match: str) -> None:
    env = gym.make(ACL_CLIMB_ID).unwrapped
    env.reset(seed=0)
    with pytest.raises(ValueError, match=match):
        env.step(action)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"base_gait": "slither"}, "base_gait"),
        ({"n_joints": 2}, "n_joints"),
        ({"pole_radius": -0.1}, "pole_radius"),
        ({"pole_radius": float("nan")}, "pole_radius"),
        ({"friction": 0.0}, "friction"),
        ({"kp": -5.0}, "kp"),
        ({"residual_scale": 0.0}, "residual_scale"),
        ({"steps_per_cycle": 1}, "steps_per_cycle"),
        ({"cycles_per_episode": 0}, "cycles_per_episode"),
        ({"reward_weights": {"speed": 1.0}}, "reward_weights"),
        ({"reward_weights": {"climb": float("inf")}}, "reward_weights"),
        ({"domain_randomization": {"pole_radius": (0.09, 0.06)}}, "pole_radius"),
        ({"domain_randomization": {"gravity": (1, 2)}}, "domain_randomization"),
        ({"gait_kwargs": {"pitch": 0.01}}, "pitch"),
        ({"gait_kwargs": {"n_joints": 8}}, "n_joints"),
        ({"fall_distance": 0.0}, "fall_distance"),
        ({"squeeze_slope": -0.1}, "squeeze_slope"),
        ({"squeeze_slope": 1.5}, "squeeze_slope"),
        ({"squeeze_slope": float("nan")}, "squeeze_slope"),
    ],
)
def test_bad_kwargs_raise_naming_the_parameter(kwargs: dict, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        ACLClimbEnv(**kwargs)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_mujoco_kinematics_fit_the_gait_backbone(env_id: str) -> None:
    """MuJoCo's own joint anchors, posed at the gait's angles, lie on the commanded backbone."""
    env = gym.make(env_id).unwrapped
    model, data, gait = env.model, env.data, env.gait
    joint_ids = [model.joint(joint_name(j)).id for j in range(gait.n_joints)]
    worst = 0.0
    for phase in np.linspace(0.0, 1.0, 12, endpoint=False):
        data.qpos[7:] = gait.joint_angles(phase)
        mujoco.mj_kinematics(model, data)
        _, _, rms = rigid_fit(data.xanchor[joint_ids].copy(), gait.backbone(phase))
        worst = max(worst, rms)
    assert worst <= 0.015


def test_model_has_no_unnamed_elements() -> None:
    model = gym.make(ACL_CLIMB_ID).unwrapped.model
    groups = {
        "body": model.nbody,
        "joint": model.njnt,
        "geom": model.ngeom,
        "site": model.nsite,
        "camera": model.ncam,
        "light": model.nlight,
        "actuator": model.nu,
        "sensor": model.nsensor,
        "material": model.nmat,
        "texture": model.ntex,
    }
    for kind, count in groups.items():
        for i in range(count):
            name = mujoco.mj_id2name(model, getattr(mujoco.mjtObj, f"mjOBJ_{kind.upper()}"), i)
            assert name, f"{kind} {i} has no name"
    assert model.ncam >= 2


@pytest.mark.parametrize("mode", ["sync", "async"])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_make_vec(env_id: str, mode: str) -> None:
    """Each vector slot rolls out exactly like a single env with the same seed and actions, in
    one process (sync) or in worker processes (async), domain randomisation included."""
    seeds, steps = [0, 1], 8
    kwargs = {**SHORT, "domain_randomization": True}
    actions = np.random.default_rng(3).uniform(-1, 1, (steps, 2, 20)).astype(np.float32)
    envs = gym.make_vec(env_id, num_envs=2, vectorization_mode=mode, **kwargs)
    try:
        obs, _ = envs.reset(seed=seeds)
        assert obs.shape == (2, 89) and not np.array_equal(obs[0], obs[1])
        vector = [(obs.copy(), None, None)]
        for t in range(steps):
            obs, reward, terminated, _, info = envs.step(actions[t])
            assert obs.shape == (2, 89) and reward.shape == (2,) and not terminated.any()
            vector.append((obs.copy(), reward.copy(), info["climb"].copy()))
    finally:
        envs.close()
    for i, seed in enumerate(seeds):
        single = gym.make(env_id, **kwargs)
        obs, _ = single.reset(seed=seed)
        np.testing.assert_array_equal(vector[0][0][i], obs)
        for t in range(steps):
            obs, reward, _, _, info = single.step(actions[t, i])
            np.testing.assert_array_equal(vector[t + 1][0][i], obs)
            assert vector[t + 1][1][i] == reward and vector[t + 1][2][i] == info["climb"]
        single.close()


def test_domain_randomization_varies_physics_deterministically() -> None:
    env = ACLClimbEnv(domain_randomization=True)
    radii = []
    for seed in (0, 1, 0):
        env.reset(seed=seed)
        radii.append(float(env.model.geom_size[env.model.geom(POLE_GEOM).id, 0]))
        lo, hi = env.config.randomization["pole_radius"]
        assert lo <= radii[-1] <= hi
        assert env.gait.radius == pytest.approx(radii[-1] + 0.0254 - env.config.gait.squeeze)
    assert radii[0] == radii[2] != radii[1]
    for _ in range(5):
        obs, *_ = env.step(np.zeros(20))
        assert np.all(np.isfinite(obs))


def test_weak_springs_fall_off_and_terminate() -> None:
    """kp = 2 N m/rad cannot hold the pole (docs/robot_and_contact.md#spring-stiffness); the env
    must say the snake fell."""
    env = ACLClimbEnv(kp=2.0)
    env.reset(seed=0)
    for _ in range(200):
        _, _, terminated, _, info = env.step(np.zeros(20))
        if terminated:
            break
    assert terminated and info["fell"] and not info["unstable"]


def test_unstable_physics_terminates_without_crash(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)  # MuJoCo writes the warning to MUJOCO_LOG.TXT in the cwd
    env = ACLClimbEnv()
    env.reset(seed=0)
    env.model.opt.timestep = 5.0  # guaranteed divergence
    obs, reward, terminated, _, info = env.step(np.ones(20))
    assert terminated and info["unstable"]
    assert np.all(np.isfinite(obs)) and np.isfinite(reward)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_open_loop_gait_climbs(env_id: str) -> None:
    """The open loop (a zero action) climbs >= 0.15 m of centre-of-mass per cycle, no fall,
    no warning."""
    env = gym.make(env_id).unwrapped
    _, info = env.reset(seed=0)
    start, climbs = info["com_height"], []
    while True:
        _, _, terminated, truncated, info = env.step(np.zeros(20))
        climbs.append(info["climb"])
        if terminated or truncated:
            break
    assert not terminated
    assert len(climbs) == 440
    assert int(env.data.warning.number.sum()) == 0
    per_cycle = np.add.reduceat(climbs, [0, 220])
    assert np.all(per_cycle >= 0.15), per_cycle
    assert info["com_height"] - start == pytest.approx(sum(climbs), abs=1e-9)


def test_rgb_render() -> None:
    env = gym.make(ACL_CLIMB_ID, render_mode="rgb_array", width=160, height=120)
    env.reset(seed=0)
    frame = env.render()
    assert frame.shape == (120, 160, 3) and frame.dtype == np.uint8
    assert frame.std() > 5.0  # not a blank image
    env.close()


def test_phase_rate_option_keeps_zero_action_open_loop_and_sets_cadence() -> None:
    """PMTG option: one more action sets the keyframes advanced per step; 0 is the open loop."""
    plain = gym.make(ACL_CLIMB_ID)
    pmtg = gym.make(ACL_CLIMB_ID, phase_rate_range=(0.5, 1.5))
    assert pmtg.action_space.shape == (21,)
    assert_same(rollout(plain, 0, np.zeros((6, 20))), rollout(pmtg, 0, np.zeros((6, 21))))
    env = pmtg.unwrapped
    env.reset(seed=0)
    phase0 = env._keyframe
    rates = []
    for a in (1.0, -1.0, 0.5, 3.0):
        *_, info = env.step(np.r_[np.zeros(20), a])
        rates.append(info["phase_rate"])
    assert rates == [1.5, 0.5, 1.25, 1.5]
    assert env._keyframe == pytest.approx(phase0 + sum(rates))
    # Between keyframes the base target is the linear interpolation of the table.
    table, k = env.gait.cycle(), int(env._keyframe)
    frac = env._keyframe - k
    env.step(np.zeros(21))
    np.testing.assert_allclose(env.data.ctrl, (1 - frac) * table[k] + frac * table[k + 1])


@pytest.mark.parametrize("value", [(1.2, 1.5), (0.5, 0.9), (-0.1, 1.5), (0.5, float("nan"))])
def test_bad_phase_rate_range_raises(value: tuple[float, float]) -> None:
    with pytest.raises(ValueError, match="phase_rate_range"):
        ACLClimbEnv(phase_rate_range=value)


def test_mass_randomization_keeps_the_centre_of_mass() -> None:
    """Scaling every module's mass moves no centre of mass (subtree masses recomputed)."""
    heavy = ACLClimbEnv(domain_randomization={"mass_scale": (1.1, 1.1)}, reset_noise_scale=0.0)
    plain = ACLClimbEnv(reset_noise_scale=0.0)
    for env in (heavy, plain):
        env.reset(seed=0)
        env.data.qpos[:] = plain.init_qpos
        mujoco.mj_forward(env.model, env.data)
    np.testing.assert_allclose(heavy._com_view, plain._com_view, atol=1e-12)


def test_randomized_pole_radius_equals_configured_pole() -> None:
    """A 0.09 m pole drawn by domain randomisation simulates like pole_radius=0.09."""
    drawn = ACLClimbEnv(domain_randomization={"pole_radius": (0.09, 0.09)})
    built = ACLClimbEnv(pole_radius=0.09)
    drawn.reset(seed=0)
    built.reset(seed=0)
    pole = built.model.geom(POLE_GEOM).id
    for field in ("geom_size", "geom_rbound", "geom_aabb"):
        np.testing.assert_allclose(
            getattr(drawn.model, field)[pole], getattr(built.model, field)[pole]
        )
    drawn.set_state(built.data.qpos.copy(), built.data.qvel.copy())
    drawn._keyframe = built._keyframe
    for _ in range(20):
        obs_a, *_, info_a = drawn.step(np.zeros(20))
        obs_b, *_, info_b = built.step(np.zeros(20))
        np.testing.assert_allclose(obs_a, obs_b, rtol=0, atol=1e-9)
    assert info_a["climb"] == pytest.approx(info_b["climb"], abs=1e-12)


def test_privileged_obs_is_centre_of_mass_state_and_the_physics() -> None:
    env = ACLClimbEnv(privileged_obs=True)
    obs, info = env.reset(seed=0)
    assert obs.shape == (99,)
    assert obs[-8] == pytest.approx(info["com_height"])
    heights = []
    for _ in range(3):
        obs, *_, info = env.step(np.zeros(20))
        heights.append(info["com_height"])
    mujoco.mj_subtreeVel(env.model, env.data)
    np.testing.assert_allclose(obs[-7:-4], env.data.subtree_linvel[1], atol=1e-12)
    # The velocity is the centre of mass's: about 0.2 m per 22 s cycle upward, not a link's.
    assert abs(obs[-5]) < 0.05
    # friction, pole radius, stiffness, latency: this episode's, drawn or set
    np.testing.assert_array_equal(obs[-4:], [1.0, 0.075, 20.0, 0.0])
    env = ACLClimbEnv(
        privileged_obs=True,
        actuator_model="sea",
        control_latency=0.05,
        friction_step=0.4,
        domain_randomization={"pole_radius": (0.06, 0.1), "spring_stiffness": (12.0, 28.0)},
    )
    obs, _ = env.reset(seed=3)
    model, pole = env.model, env._elements.pole_geom
    radius, stiffness = obs[-3], obs[-2]
    assert radius == model.geom_size[pole, 0] and 0.06 <= radius <= 0.1 and radius != 0.075
    assert 12.0 <= stiffness <= 28.0 and stiffness != 20.0
    assert obs[-1] == 0.05
    frictions = {float(env.step(np.zeros(20))[0][-4]) for _ in range(440)}
    assert frictions == {1.0, 0.4}  # the friction step, when it comes


def test_obs_history_carries_the_last_steps_readings_before_the_privileged_block() -> None:
    """``obs_history=2``: the readings (joints, IMU, with their noise) of the last two steps,
    newest first, each the reset's at reset; then the privileged block, last."""
    env = ACLClimbEnv(obs_history=2, privileged_obs=True, domain_randomization=True)
    names = layouts.env_observation_names(env)
    sensed = layouts.size(tuple(layouts.sensed_blocks(20)))
    first, second = names.index("angle_0_prev1"), names.index("angle_0_prev2")
    assert second == first + sensed and names[-10:] == PRIVILEGED
    assert names[first + sensed - 1] == "gyro_z_prev1"
    frames = [env.reset(seed=0)[0]]
    for _ in range(3):
        frames.append(env.step(np.zeros(20))[0])
    now = [f[:sensed] for f in frames]
    np.testing.assert_array_equal(frames[0][first:second], now[0])
    np.testing.assert_array_equal(frames[0][second : second + sensed], now[0])
    for t in (2, 3):
        np.testing.assert_array_equal(frames[t][first:second], now[t - 1])
        np.testing.assert_array_equal(frames[t][second : second + sensed], now[t - 2])
    assert not np.array_equal(now[1], now[2])
    plain = ACLClimbEnv(privileged_obs=True, domain_randomization=True)
    obs, _ = plain.reset(seed=0)  # the option adds entries, and changes nothing else
    np.testing.assert_array_equal(obs, np.concatenate([frames[0][:first], frames[0][-10:]]))


def test_energy_is_absolute_actuator_work() -> None:
    env = ACLClimbEnv()
    env.reset(seed=0)
    *_, info = env.step(np.zeros(20))
    assert info["energy"] > 0.0
    # Holding still (gravity off, target = current pose) costs almost nothing.
    env.model.opt.gravity[:] = 0.0
    env.data.qvel[:] = 0.0
    env._table = np.tile(env.data.qpos[7:], (env.steps_per_cycle, 1))
    *_, info = env.step(np.zeros(20))
    assert info["energy"] < 1e-2


@pytest.mark.parametrize("timestep", [0.001, 0.002, 0.0025, PHYSICS_TIMESTEP])
def test_timestep_sets_the_physics_step_and_keeps_the_control_step(timestep: float) -> None:
    env = gym.make(ACL_CLIMB_ID, timestep=timestep).unwrapped
    assert env.model.opt.timestep == pytest.approx(timestep)
    assert env.frame_skip * timestep == pytest.approx(0.1)
    assert env.dt == pytest.approx(0.1)
    env.reset(seed=0)
    _, _, terminated, _, info = env.step(np.zeros(20))
    assert not terminated and np.isfinite(info["slip"])


@pytest.mark.parametrize("timestep", [0.003, 0.0, -0.002, 0.01, 0.0004, 0.1 / 7, float("nan")])
def test_bad_timestep_raises_naming_it(timestep: float) -> None:
    with pytest.raises(ValueError, match="timestep"):
        ACLClimbEnv(timestep=timestep)


def test_start_pose_clears_the_pole() -> None:
    """The start-pose search loosens the helix until the placed chain clears the pole."""
    pole, clearance = 0.075, 0.005
    contact = pole + SEA_MODULE_RADIUS
    angles, rotation, translation = clear_placement(
        lambda radius: ACLGait(radius=radius), 0.0, contact, clearance, height=0.3
    )
    joints, ends, _ = forward_kinematics(angles, SEA_MODULE_LENGTH)
    points = np.concatenate([ends[:1], joints, ends[1:]]) @ rotation.T + translation
    np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-12)
    assert min_axis_distance(points) >= contact + clearance - 2e-3
    assert points[:, 2].min() == pytest.approx(0.3)
