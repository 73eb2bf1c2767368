"""The compliant grip (acl_env/envs/grip.py): its law, its options, its task id, its tuning and
its place in the evaluation."""

from __future__ import annotations

import copy
import pickle

import gymnasium as gym
import numpy as np
import optuna
import pytest

from acl_env import (
    ACL_CLIMB_BENCHMARK_ID,
    ACL_CLIMB_COMPLIANT_ID,
    ACL_CLIMB_ID,
    ACL_CLIMB_SEA_ID,
    COMPLIANT_KWARGS,
    tuned_gaits,
)
from acl_env.envs.grip import GRIP_RANGE, GRIP_TICKS, GripController
from acl_env.envs.modulation import interpolate_offsets, section_weights

SHORT = {"steps_per_cycle": 40, "cycles_per_episode": 1}


def _run(env: gym.Env, steps: int, action: np.ndarray | None = None) -> list[dict]:
    infos = []
    a = np.zeros(env.action_space.shape) if action is None else action
    for _ in range(steps):
        _, _, terminated, truncated, info = env.step(a)
        infos.append(info)
        if terminated or truncated:
            break
    return infos


def test_no_gain_plays_the_open_loop_bit_for_bit() -> None:
    """With zero gain the loop never moves the squeeze: the physics is the SEA task's own."""
    plain = gym.make(ACL_CLIMB_SEA_ID, **SHORT).unwrapped
    grip = gym.make(ACL_CLIMB_SEA_ID, **SHORT, grip_target=50.0, grip_gain=0.0).unwrapped
    for env in (plain, grip):
        env.reset(seed=3)
    a, b = _run(plain, 15), _run(grip, 15)
    assert [i["climb"] for i in a] == [i["climb"] for i in b]
    assert [i["slip"] for i in a] == [i["slip"] for i in b]
    np.testing.assert_array_equal(plain.data.qpos, grip.data.qpos)
    assert (grip._grip.offset == 0.0).all() and (grip._grip.force != 0.0).any()


def _controller(gain: float = 1e-3, leak: float = 100.0, target: float = 100.0) -> GripController:
    env = gym.make(ACL_CLIMB_SEA_ID, **SHORT, grip_target=0.0).unwrapped
    env.reset(seed=0)
    controller = GripController(section_weights(env.n_joints, 4), target, gain, leak)
    controller.reset(env.gait, env._gait_kwargs(env.config.physics.pole_radius))
    return controller


def test_force_is_the_torques_virtual_work_on_the_squeeze() -> None:
    """Q_s = sum_j w_js tau_j dq_j/dsqueeze: torques along the squeeze direction press (Q > 0),
    against it pull (Q < 0), and torques that do no work on the squeeze give nothing."""
    c = _controller()
    d = c._sensitivity[5]
    assert np.abs(d).max() > 1.0  # rad per m: a 1 mm tighter helix bends the joints
    assert (c.measure(d, 5) > 0.0).all() and (c.measure(-d, 5) < 0.0).all()
    w = c.weights[:, 0]
    ortho = np.zeros_like(d)  # torques on the head's two joints that do no work on its squeeze
    ortho[0], ortho[1] = w[1] * d[1], -w[0] * d[0]
    assert abs(c.measure(ortho, 5)[0]) < 1e-9 * np.abs(d).max() ** 2
    # The sensitivity is the tables' own secant over one grid step (5 mm) either side.
    step = 2.0 * GRIP_RANGE / (c._tables.shape[1] - 1)
    up, down = (interpolate_offsets(c._tables, 5, np.full((1, d.size), u)) for u in (0.25, -0.25))
    np.testing.assert_allclose(up - down, 2.0 * step * d, atol=1e-12)
    assert step == 0.005


def test_law_tightens_below_target_relaxes_above_and_stays_in_range() -> None:
    c = _controller(gain=1e-3, leak=100.0, target=100.0)
    dt = 0.01
    zero = np.zeros(c.weights.shape[0])
    change = c.update(zero, 0, dt)  # measures 0 N, 100 N short: every section tightens
    np.testing.assert_allclose(c.offset, 1e-3 * dt * 100.0)
    assert np.abs(change).max() > 0.0
    for _ in range(10_000):  # held short of its target: it stops at the range's end
        c.update(zero, 0, dt)
    np.testing.assert_allclose(c.offset, GRIP_RANGE)
    c.target[:] = -400.0
    for _ in range(10_000):
        c.update(zero, 0, dt)
    np.testing.assert_allclose(c.offset, -GRIP_RANGE)
    leaky = _controller(gain=0.0, leak=0.1)
    leaky.offset[:] = 0.01
    for _ in range(100):  # 1 s, ten time constants: back to the gait's own squeeze
        leaky.update(zero, 0, dt)
    assert np.abs(leaky.offset).max() < 0.01 * np.exp(-9.0)


def test_closed_loop_moves_the_measured_force_toward_the_target() -> None:
    """In MuJoCo: a target above what the open loop presses makes the sections press harder than
    a target below it, and the loop runs at every firmware tick (10 per step)."""
    forces = {}
    for target in (20.0, 200.0):
        env = gym.make(ACL_CLIMB_SEA_ID, **SHORT, grip_target=target, grip_gain=1e-4).unwrapped
        env.reset(seed=1)
        grip, ticks = env._grip, []
        update = grip.update
        grip.update = lambda *args, _u=update, _t=ticks: _t.append(1) or _u(*args)
        measured = []
        for info in _run(env, 20):
            measured.append(grip.force.copy())
            assert not info["fell"]
        assert len(ticks) == GRIP_TICKS * len(measured)
        forces[target] = np.mean(measured[10:])
    assert forces[200.0] > forces[20.0] + 20.0


def test_compliant_task_id() -> None:
    """ACLClimbCompliant-v1: ACLClimb-v3 with the tuned grip and one grip-target action per
    section (before the cadence), observing the controller's state."""
    env = gym.make(ACL_CLIMB_COMPLIANT_ID).unwrapped
    sea = gym.make(ACL_CLIMB_SEA_ID).unwrapped
    assert env.config.grip.target == tuned_gaits.grip("acl_sea_grip")["grip_target"]
    assert env.config.grip.action_scale == COMPLIANT_KWARGS["grip_action_scale"] == 100.0
    names = env.action_names
    assert names[:-5] == sea.action_names[:-1] and names[-1] == "cadence"
    assert names[-5:-1] == tuple(f"grip_section_{s}" for s in range(4))
    assert env.observation_space.shape[0] == sea.observation_space.shape[0] + 8
    env.reset(seed=0)
    action = np.zeros(env.action_space.shape, dtype=np.float32)
    action[-4] = 1.0  # section 1's target, +100 N
    obs, *_ = env.step(action)
    expected = env.config.grip.target + np.array([0.0, 100.0, 0.0, 0.0])
    np.testing.assert_allclose(env._grip.target, expected)
    np.testing.assert_allclose(obs[-8:-4], env._grip.offset / GRIP_RANGE)
    np.testing.assert_allclose(obs[-4:], env._grip.force)


def test_a_copy_carries_the_controller_state() -> None:
    env = gym.make(ACL_CLIMB_COMPLIANT_ID, **SHORT).unwrapped
    env.reset(seed=2)
    rng = np.random.default_rng(0)
    for _ in range(5):
        env.step(rng.uniform(-1, 1, env.action_space.shape).astype(np.float32))
    copies = [pickle.loads(pickle.dumps(env)), copy.deepcopy(env)]
    actions = rng.uniform(-1, 1, (5, *env.action_space.shape)).astype(np.float32)
    runs = [[e.step(a)[0] for a in actions] for e in (env, *copies)]
    for other in runs[1:]:
        np.testing.assert_array_equal(np.array(runs[0]), np.array(other))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"grip_target": 50.0, "actuator_model": "servo"}, "grip_target needs actuator_model"),
        ({"grip_gain": 1e-4}, "grip_gain needs grip_target"),
        ({"grip_leak": 1.0}, "grip_leak needs grip_target"),
        ({"grip_action_scale": 10.0}, "grip_action_scale needs grip_target"),
        ({"grip_target": 1e4}, "grip_target"),
        ({"grip_target": 50.0, "grip_gain": -1.0}, "grip_gain"),
        ({"grip_target": 50.0, "grip_leak": 0.0}, "grip_leak"),
        ({"grip_target": 50.0, "grip_action_scale": 1e4}, "grip_action_scale"),
        ({"grip_target": 50.0, "base_gait": "none", "tuned_gait": None}, "base gait"),
        ({"grip_target": 50.0, "timestep": 0.004}, "firmware ticks"),
    ],
)
def test_bad_grip_options_are_refused_by_name(kwargs: dict, message: str) -> None:
    env_id = ACL_CLIMB_SEA_ID if kwargs.get("actuator_model") != "servo" else ACL_CLIMB_ID
    kwargs = {
        k: v for k, v in kwargs.items() if env_id == ACL_CLIMB_SEA_ID or k != "actuator_model"
    }
    with pytest.raises(ValueError, match=message):
        gym.make(env_id, **kwargs)


def test_evaluation_meets_compliant_acl_and_open_loops_without_the_grip(tmp_path) -> None:
    """A policy on the compliant task is judged against compliant_acl (the tuned grip on the
    tuned gait, also at the policy's cadence) and against open loops that have no grip."""
    from acl_env.evaluation.baselines import (
        COMPLIANT,
        COMPLIANT_SAME_CADENCE,
        DEFAULT_TUNED_GAITS,
        GRIP_KWARGS,
        build_controllers,
    )
    from acl_env.training.policy import PolicyFolder

    hyperparams = {"env_kwargs": {"domain_randomization": True}}
    folder = PolicyFolder(tmp_path, ACL_CLIMB_COMPLIANT_ID, hyperparams, tmp_path / "m.zip", None)
    controllers, notes = build_controllers(folder, {}, None, DEFAULT_TUNED_GAITS)
    by_name = {c.name: c for c in controllers}
    grip = tuned_gaits.grip("acl_sea_grip")
    assert by_name["policy"].env_kwargs["grip_action_scale"] == 100.0
    for name in (COMPLIANT, COMPLIANT_SAME_CADENCE):
        kwargs = by_name[name].env_kwargs
        assert {k: kwargs[k] for k in GRIP_KWARGS} == grip, notes
        assert "grip_action_scale" not in kwargs
    assert by_name[COMPLIANT_SAME_CADENCE].phase_rate == 1.0
    for name in ("open_loop_acl", "open_loop_tuned", "open_loop_acl_same_cadence"):
        env = by_name[name].make_env().unwrapped
        assert env.config.grip is None, name
        assert env.config.actuator.model.name == "sea"
    tuned = by_name["open_loop_tuned"].env_kwargs
    assert {k: v for k, v in by_name[COMPLIANT].env_kwargs.items() if k not in GRIP_KWARGS} == tuned


def test_a_grip_study_does_not_disqualify_its_fixed_gaits_clipping(tmp_path) -> None:
    """On the 0.055 m pole acl_sea's table clips 9.6 % of its entries: above --max-clipped 0.05 a
    gait study prunes it, while a grip study, whose gait is the same in every trial, scores it."""
    from acl_env.tuning.arguments import make_parser
    from acl_env.tuning.objective import make_objective
    from acl_env.tuning.settings import settings_from_args

    argv = ["--env", ACL_CLIMB_SEA_ID, "--steps-per-cycle", "40", "--cycles", "1", "--seeds", "0"]
    argv += ["--condition", "pole_radius:0.055", "--max-clipped", "0.05"]
    for grip, expected in ((False, optuna.trial.TrialState.PRUNED), (True, None)):
        settings = settings_from_args(make_parser().parse_args([*argv, *(["--grip"] * grip)]))
        study = optuna.create_study(direction="maximize")
        study.enqueue_trial(settings.default_params)
        study.optimize(make_objective(settings), n_trials=1)
        trial = study.trials[0]
        assert trial.user_attrs["clipped_fraction"] > 0.05
        if expected is not None:
            assert trial.state == expected and trial.user_attrs["disqualified"] == "saturated"
        else:
            assert trial.state == optuna.trial.TrialState.COMPLETE
            assert "disqualified" not in trial.user_attrs


def test_tuner_grip_mode_searches_the_grip_on_the_ids_gait(tmp_path) -> None:
    from acl_env.tuning.arguments import make_parser
    from acl_env.tuning.cli import main
    from acl_env.tuning.settings import settings_from_args
    from acl_env.tuning.space import GRIP_DEFAULT_PARAMS, GRIP_SPACE, UsageError

    argv = ["--grip", "--env", ACL_CLIMB_SEA_ID, "--steps-per-cycle", "40", "--cycles", "1"]
    settings = settings_from_args(make_parser().parse_args([*argv, "--seeds", "0"]))
    assert settings.space == GRIP_SPACE and settings.default_params == GRIP_DEFAULT_PARAMS
    assert settings.env_kwargs({"grip_target": 5.0}) == {"grip_target": 5.0}
    envs = settings.make_envs({"grip_target": 5.0, "grip_gain": 1e-5, "grip_leak": 1.0})
    assert (
        envs[0].unwrapped.config.gait.tuned_gait == "acl_sea"
        and envs[0].unwrapped.config.grip.target == 5.0
    )
    for extra in (["--space", "pitch:0.1:0.12"], ["--start-from", "acl"]):
        with pytest.raises(UsageError, match=extra[0]):
            settings_from_args(make_parser().parse_args([*argv, *extra]))
    with pytest.raises(UsageError, match="--grip"):  # the servo has no springs to read
        settings_from_args(make_parser().parse_args(["--grip", "--env", ACL_CLIMB_BENCHMARK_ID]))
    output = tmp_path / "tuned.json"
    entry = main(
        [*argv, "--seeds", "0", "--n-trials", "2", "--validate-seeds", "1", "--validate-top",
         "1", "--storage", str(tmp_path / "t.db"), "--output", str(output), "--plot", "",
         "--key", "g", "--no-progress-bar", "--sampler-seed", "0"]
    )  # fmt: skip
    assert set(entry["env_kwargs"]) == set(GRIP_SPACE)
    assert entry["default_gait_metrics"]["climb_per_gait_cycle_m"] > 0.0  # trial 0: the open loop
    assert tuned_gaits.grip("g", output) == entry["env_kwargs"]
