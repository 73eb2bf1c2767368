"""The fuzz table for the env: bad constructor arguments and lifecycle misuse.

Constructor: every argument given huge integers, NaN/inf, values out of range, wrong kinds
(bools for numbers, strings, containers, nested garbage in dicts), bad randomisation ranges, gait
keywords and tuned gaits; each must raise ``TypeError`` or ``ValueError`` whose message names the
argument (never a bare ``OverflowError``, never a silent acceptance). Valid extremes are accepted
and run finite. Lifecycle: reset/step/render/close in wrong orders, bad seeds and options, bad
actions; each raises a clear error or behaves as ``envs/lifecycle.py`` documents, and no
``AttributeError`` or abort. Envs are small (few joints, few keyframes per cycle) to keep this fast.
"""

from __future__ import annotations

import copy
import inspect
import math
import pickle
from collections.abc import Callable, Iterator
from decimal import Decimal
from fractions import Fraction
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

from acl_env import ACL_CLIMB_BENCHMARK_ID
from acl_env.envs import ACLClimbEnv
from acl_env.envs.lifecycle import EnvClosed, ResetNeeded
from acl_env.envs.rewards import REWARD_WEIGHT_MAX
from acl_env.validation import shown

SMALL = {"n_joints": 4, "steps_per_cycle": 8}
HUGE = 10**400  # beyond any float: float(HUGE) raises OverflowError
HUGER = 10**5000  # beyond Python's 4300-digit int-to-str limit: repr(HUGER) raises ValueError


@pytest.fixture(autouse=True)
def _mujoco_log_in_tmp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """MuJoCo appends its warnings to MUJOCO_LOG.TXT in the working folder: keep it in tmp."""
    monkeypatch.chdir(tmp_path)


# --- the constructor -----------------------------------------------------------------------------

# Not a real number, for any numeric argument.
NOT_NUMBERS: list[Any] = [True, False, np.bool_(True), "1.0", "", b"1", [1.0], (1.0,)]
NOT_NUMBERS += [{"value": 1.0}, {1.0}, complex(1.0, 0.0), Decimal("1.0"), object()]
NON_FINITE: list[Any] = [math.nan, math.inf, -math.inf, np.float64(math.nan), np.float32(math.inf)]
HUGE_INTS: list[Any] = [HUGE, -HUGE, HUGER, Fraction(HUGE, 3)]

# Real arguments: (name, values out of range, None allowed).
REALS: dict[str, tuple[list[float], bool]] = {
    "residual_scale": ([0.0, -0.1, 3.2, 1e300], True),
    "pole_radius": ([0.0, 0.009, 0.51, -1.0, 1e300], False),
    "friction": ([0.0, -1.0, 5.01, 1e300], False),
    "friction_step": ([0.0, -0.5, 5.01, 1e300], True),
    "kp": ([0.0, -20.0, 200.5, 1e308], False),
    "squeeze": ([-0.051, 0.051, 1e300], True),
    "squeeze_slope": ([-0.1, 1.01, 1e300], False),
    "start_phase_range": ([-0.01, 1.01, 1e300], False),
    "reset_noise_scale": ([-0.01, 1.6, 1e300], False),
    "fall_distance": ([0.0, -0.2, 4.01, 1e300], False),
    "timestep": ([0.0, 0.0001, 0.006, 0.0021, -0.002, 1e300], False),
    "roll_limit": ([0.0, -1.0, 3600.5, 1e300], True),
}
# The SEA's real arguments, given with actuator_model="sea" (on the servo any value is refused).
SEA_REALS: dict[str, tuple[list[float], bool]] = {
    "spring_stiffness": ([0.0, 0.5, -20.0, 200.5, 1e300], True),
    "motor_speed_limit": ([0.0, 0.05, -2.2, 100.5, 1e300], True),
    "control_latency": ([-0.01, 0.21, 1e300], True),
    "sensor_latency": ([-0.01, 0.21, 1e300], True),
}
# The compliant grip's (envs/grip.py), given on the SEA with a target (the gain, leak and action
# scale need one; without it any value is refused).
GRIP_REALS: dict[str, list[float]] = {
    "grip_target": [-500.5, 500.5, 1e300],
    "grip_gain": [-1e-4, 0.0101, 1e300],
    "grip_leak": [0.0, 0.005, -1.0, 100.5, 1e300],
    "grip_action_scale": [-1.0, 500.5, 1e300],
}
# Integer arguments: (values out of range, None allowed).
INTS: dict[str, tuple[list[Any], bool]] = {
    "n_joints": ([2, 101, 0, -5, 20.0, 20.5], False),
    "steps_per_cycle": ([1, 2201, 0, -8, 8.0], False),
    "cycles_per_episode": ([0, 9, -1, 1.0], False),
    "width": ([0, 4097, -1, 64.0], False),
    "height": ([0, 4097, -1, 48.0], False),
    "modulation_sections": ([0, 5, -1, 2.0], True),  # at most n_joints (4 here)
    "obs_history": ([9, -1, 1.0, True], False),
}


def numeric_cases() -> Iterator[tuple[dict[str, Any], str]]:
    for name, (bad, none_ok) in {**REALS, **INTS}.items():
        values = [*NOT_NUMBERS, *NON_FINITE, *HUGE_INTS, *bad]
        if not none_ok:
            values.append(None)
        for value in values:
            yield {name: value}, name
    for name, (bad, _) in SEA_REALS.items():
        for value in [*NOT_NUMBERS, *NON_FINITE, *HUGE_INTS, *bad]:
            yield {name: value, "actuator_model": "sea"}, name
        yield {name: 1.0}, name  # an SEA option on the servo
    for name, bad in GRIP_REALS.items():
        target = {} if name == "grip_target" else {"grip_target": 10.0}
        for value in [*NOT_NUMBERS, *NON_FINITE, *HUGE_INTS, *bad]:
            yield {name: value, "actuator_model": "sea", **target}, name
        if name != "grip_target":
            yield {name: 1.0, "actuator_model": "sea"}, name  # without a target
    yield {"grip_target": 10.0}, "grip_target"  # on the servo: no springs to read


def mapping_garbage(name: str, keys: list[str]) -> Iterator[tuple[dict[str, Any], str]]:
    """A mapping argument given non-mappings, unknown and non-string keys, and entries that are
    not numbers (nested containers, NaN, huge integers, bools)."""
    for value in [[("a", 1.0)], "climb", 1.0, True, (1.0, 2.0)]:
        yield {name: value}, name
    yield {name: {"nope": 1.0}}, name
    yield {name: {1: 1.0}}, name
    yield {name: {(keys[0],): 1.0}}, name
    for entry in [{"x": 1.0}, [1.0], "1.0", None, True, math.nan, math.inf, HUGE, HUGER, -HUGE]:
        yield {name: {keys[0]: entry}}, name
    yield {name: {keys[-1]: {"nested": {"deeper": [math.nan]}}}}, name


def reward_weight_cases() -> Iterator[tuple[dict[str, Any], str]]:
    yield from mapping_garbage("reward_weights", ["climb", "slip", "roll"])
    for term in ["climb", "slip", "roll", "energy", "action_rate"]:
        for weight in [1.7e308, -1.7e308, REWARD_WEIGHT_MAX * 1.01, -1e7]:
            yield {"reward_weights": {term: weight}}, "reward_weights"


def randomization_cases() -> Iterator[tuple[dict[str, Any], str]]:
    name = "domain_randomization"
    for value in [1, 0, 1.0, "true", "false", [True], (0.1, 0.2), object()]:
        yield {name: value}, name
    yield {name: {"gravity": (0.1, 0.2)}}, name
    yield {name: {2: (0.1, 0.2)}}, name
    # Not a pair, reversed, non-finite, huge, not numbers; a positive quantity's low must be > 0.
    bad_pairs: list[Any] = [0.07, "0.07", (0.07,), (0.06, 0.07, 0.08), (0.08, 0.07), (0.0, 0.07)]
    bad_pairs += [(math.nan, 0.07), (0.06, math.inf), (0.06, HUGE), (HUGER, 0.07), (-0.06, 0.07)]
    bad_pairs += [(True, 0.07), ("0.06", 0.07), ({"low": 0.06}, 0.07), np.array([[0.06, 0.07]])]
    for key in ["pole_radius", "friction", "kp", "mass_scale"]:
        for pair in bad_pairs:
            yield {name: {key: pair}}, name
    above = {"pole_radius": 0.6, "friction": 5.5, "kp": 250.0, "mass_scale": 11.0}
    for key, high in above.items():
        yield {name: {key: (0.07, high)}}, name
    yield {name: {"mass_scale": (1e-300, 1e-300)}}, name  # massless modules: absurd
    yield {name: {"pole_radius": (0.001, 0.07)}}, name  # below the pole_radius argument's range
    for noise in [-0.01, 1.5, math.nan, HUGE, "0.01", None, (0.0, 0.1)]:
        yield {name: {"sensor_noise": noise}}, name
    sea = {"actuator_model": "sea"}
    for key in ["spring_stiffness", "motor_speed_limit", "control_latency"]:
        for pair in bad_pairs:
            if key == "control_latency" and isinstance(pair, tuple) and pair == (0.0, 0.07):
                continue  # no latency is a latency
            yield {name: {key: pair}, **sea}, name
        yield {name: {key: (0.01, 0.02)}}, name  # an SEA parameter on the servo
    sea_above = {"spring_stiffness": 250.0, "motor_speed_limit": 101.0, "control_latency": 0.25}
    for key, high in sea_above.items():
        yield {name: {key: (0.01, high)}, **sea}, name
    yield {name: {"kp": (15.0, 25.0)}, **sea}, name  # the servo's gain on the SEA


def sequence_cases() -> Iterator[tuple[dict[str, Any], str]]:
    name = "phase_rate_range"
    # Not a pair, out of order, outside 0 <= low <= 1 <= high <= steps_per_cycle / 2 = 4.
    values: list[Any] = [1.5, "0.5,2", (0.5,), (0.5, 1.5, 2.0), (1.5, 0.5), (-0.1, 1.5), (0.5, 0.9)]
    values += [(0.5, 4.5), (math.nan, 1.5), (0.5, math.inf), (0.5, HUGE), (HUGER, 1.5)]
    values += [(True, 1.5), (0.5, "2"), ({"low": 0.5}, 1.5), {"low": 0.5, "high": 1.5}]
    for value in [*values, np.array([[0.5, 1.5]])]:
        yield {name: value}, name


def gait_cases() -> Iterator[tuple[dict[str, Any], str]]:
    name = "gait_kwargs"
    yield from mapping_garbage(name, ["pitch", "amp_pitch"])
    for key in ["n_joints", "steps_per_cycle", "module_length", "module_diameter"]:
        yield {name: {key: 1}}, name
    bad: dict[str, list[Any]] = {
        "radius": [0.0, -0.1, 10.5, 1e300, HUGE],
        "pitch": [0.01, 10.5, 1e300, HUGE],  # below a module diameter, above 10 m
        "amp_pitch": [-0.01, 10.5, 1e300, HUGE],
        "amp_radial": [-0.01, 0.2, 1e300],  # 0.2 m: beyond the helix radius
        "spatial_freq": [20.5, -1e300, HUGE],
        "radial_freq": [-20.5, 1e300, -HUGE],
        "rolls_per_cycle": [0.5, 11, 1e300, -HUGE],
        "rock_amp": [-0.1, 3.2, HUGE],
        "rock_phase": [6.3, -1e300, HUGE],
        "n_samples": [99, 1001, 300.0, HUGE, True, "300"],
    }
    for key, values in bad.items():
        for value in values:
            yield {name: {key: value}}, name
    for key in ["amp_pitch", "spatial_freq", "radial_freq", "n_samples"]:  # not the helix's
        yield {name: {key: 1}, "base_gait": "rolling_helix"}, name
    name = "gait_modulation"
    yield from mapping_garbage(name, ["squeeze", "amp_pitch"])
    for value in [0.0, -0.001, 0.021, 1e300]:
        yield {name: {"squeeze": value}}, name
    yield {name: {"squeeze": 0.01}, "base_gait": "none"}, name


def choice_cases() -> Iterator[tuple[dict[str, Any], str]]:
    choices: dict[str, list[Any]] = {
        "base_gait": ["ACL", "", "rolling", None, 1, True, ["acl"], b"acl", {"acl": 1}],
        "render_mode": ["bogus", "RGB_ARRAY", "", 1, True, ["human"], b"rgb_array"],
        "camera_name": ["nope", "", 0, None, True, ["track"], b"track", HUGER],
        "privileged_obs": [1, 0, "false", "true", None, 1.0, [True], HUGE],
        "tuned_gait": ["nope", "", "ACL", 1, True, 1.5, ["acl"], {"acl": 1}, HUGER],
        "actuator_model": ["SEA", "", "servo ", None, 1, True, ["sea"], b"sea", HUGER],
    }
    for name, values in choices.items():
        for value in values:
            yield {name: value}, name
    yield {"tuned_gait": "acl", "base_gait": "rolling_helix"}, "tuned_gait"
    yield {"tuned_gait": "acl", "squeeze": 0.01}, "tuned_gait"
    yield {"tuned_gait": "acl", "gait_kwargs": {"pitch": 0.1}}, "tuned_gait"


CONSTRUCTOR_CASES = [*numeric_cases(), *reward_weight_cases(), *randomization_cases()]
CONSTRUCTOR_CASES += [*sequence_cases(), *gait_cases(), *choice_cases()]


def case_id(case: tuple[dict[str, Any], str]) -> str:
    return ",".join(f"{k}={shown(v)[:24]}" for k, v in case[0].items())


def test_the_table_has_its_cases() -> None:
    """The target: at least 250 constructor cases over every argument."""
    assert len(CONSTRUCTOR_CASES) >= 250, len(CONSTRUCTOR_CASES)

    covered = {name for _, name in CONSTRUCTOR_CASES}
    assert set(inspect.signature(ACLClimbEnv).parameters) <= covered


@pytest.mark.parametrize(
    ("kwargs", "name"), CONSTRUCTOR_CASES, ids=[case_id(c) for c in CONSTRUCTOR_CASES]
)
def test_a_bad_argument_is_refused_by_name(kwargs: dict[str, Any], name: str) -> None:
    with pytest.raises((TypeError, ValueError)) as caught:
        ACLClimbEnv(**{**SMALL, **kwargs})
    assert isinstance(caught.value, TypeError | ValueError)
    message = str(caught.value)
    assert name in message, message
    assert len(message) < 1000, message  # values are shown abbreviated, never 400 digits


# Valid extremes: accepted, and they reset and step with finite output.
VALID_EXTREMES: list[dict[str, Any]] = [
    {"pole_radius": 0.01, "squeeze": -0.05},
    {"pole_radius": np.float32(0.5), "squeeze": 0.05, "kp": np.float64(200.0)},
    {"friction": 1e-300, "kp": 1e-300},  # frictionless and limp: the snake falls, finitely
    {"n_joints": np.int64(3), "steps_per_cycle": np.int32(2)},
    {"pole_radius": Fraction(3, 40), "fall_distance": 4},
    {"reward_weights": {"climb": REWARD_WEIGHT_MAX, "energy": REWARD_WEIGHT_MAX}},
    {"reward_weights": {"slip": -REWARD_WEIGHT_MAX, "climb": -1.0}},  # negative: allowed
    {"reward_weights": {"action_rate": np.float32(1e6), "roll": 0}},
    {"domain_randomization": {"mass_scale": (1e-3, 10.0), "sensor_noise": 1.0}},
    {"domain_randomization": {"pole_radius": np.array([0.01, 0.5]), "kp": [1e-3, 200]}},
    {"gait_kwargs": {"radius": 10.0, "pitch": 10.0, "amp_pitch": 10.0}},
    {"gait_kwargs": {"spatial_freq": -20, "radial_freq": 20, "amp_radial": 0.05}},
    {"gait_kwargs": {"rolls_per_cycle": -10, "rock_amp": math.pi, "rock_phase": 2 * math.pi}},
    {"gait_kwargs": {"n_samples": 1000}, "residual_scale": math.pi},
    {"phase_rate_range": (0, 4), "roll_limit": 3600, "timestep": 0.0005},
    {"gait_modulation": {"squeeze": 0.02, "amp_pitch": 0.02, "amp_radial": 0.02}},
    {"width": 1, "height": 4096, "camera_name": "side", "render_mode": "rgb_array"},
    {"tuned_gait": "acl_noroll", "squeeze_slope": 1.0, "cycles_per_episode": 8},
    {"actuator_model": "sea", "spring_stiffness": 1.0, "motor_speed_limit": 0.1},
    {"actuator_model": "sea", "spring_stiffness": 200.0, "motor_speed_limit": 100.0},
    {"actuator_model": "sea", "control_latency": 0.2, "sensor_latency": 0.2},
    {"actuator_model": "sea", "control_latency": 0.0, "sensor_latency": 0.0},
    {"actuator_model": "sea", "domain_randomization": {"control_latency": (0.0, 0.2)}},
    {"actuator_model": "sea", "grip_target": 500.0, "grip_gain": 0.01, "grip_leak": 0.01},
    {
        "actuator_model": "sea",
        "grip_target": -500.0,
        "grip_gain": 0.01,
        "grip_leak": 100.0,
        "grip_action_scale": 500.0,
    },
    {"actuator_model": "sea", "domain_randomization": True, "timestep": 0.005},
]


@pytest.mark.parametrize("kwargs", VALID_EXTREMES, ids=[shown(k) for k in VALID_EXTREMES])
def test_valid_extremes_are_accepted_and_run_finite(kwargs: dict[str, Any]) -> None:
    env = ACLClimbEnv(**{**SMALL, **kwargs})
    obs, _ = env.reset(seed=0)
    assert np.isfinite(obs).all()
    for _ in range(3):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert np.isfinite(obs).all() and math.isfinite(reward) and type(reward) is float
        assert all(math.isfinite(v) for v in info.values() if type(v) is float)
        if terminated or truncated:
            break
    env.close()


# --- the lifecycle -------------------------------------------------------------------------------


def small(**kwargs: Any) -> ACLClimbEnv:
    return ACLClimbEnv(**{**SMALL, **kwargs})


def reset(env: ACLClimbEnv) -> ACLClimbEnv:
    env.reset(seed=0)
    return env


def closed(env: ACLClimbEnv) -> ACLClimbEnv:
    env.close()
    return env


def zero(env: ACLClimbEnv) -> np.ndarray:
    return np.zeros(env.action_space.shape)


def rgb() -> ACLClimbEnv:
    return small(render_mode="rgb_array")


def step(env: ACLClimbEnv) -> Any:
    return env.step(zero(env))


def failed_reset() -> ACLClimbEnv:
    env = small()
    with pytest.raises(TypeError, match="seed"):
        env.reset(seed=True)
    return env


# Wrong orders: (setup, call) -> the error class; each also a RuntimeError.
Setup = Callable[[], ACLClimbEnv]
ORDERS: dict[str, tuple[Setup, Callable[[ACLClimbEnv], Any], type]] = {
    "step before reset": (small, step, ResetNeeded),
    "render before reset": (rgb, lambda e: e.render(), ResetNeeded),
    "render None before reset": (small, lambda e: e.render(), ResetNeeded),
    "step after a failed reset": (failed_reset, step, ResetNeeded),
    "step after close": (lambda: closed(reset(small())), step, EnvClosed),
    "reset after close": (lambda: closed(reset(small())), lambda e: e.reset(seed=0), EnvClosed),
    "render after close": (lambda: closed(reset(rgb())), lambda e: e.render(), EnvClosed),
    "step after close without reset": (lambda: closed(small()), step, EnvClosed),
    "reset after close without reset": (lambda: closed(small()), lambda e: e.reset(), EnvClosed),
    "reset after two closes": (lambda: closed(closed(small())), lambda e: e.reset(), EnvClosed),
    "bad action after close": (lambda: closed(reset(small())), lambda e: e.step(None), EnvClosed),
    "step of a fresh copy": (lambda: pickle.loads(pickle.dumps(small())), step, ResetNeeded),
    "step of a fresh deepcopy": (lambda: copy.deepcopy(small()), step, ResetNeeded),
    "wrapped env, step before reset": (
        lambda: gym.make(ACL_CLIMB_BENCHMARK_ID, **SMALL).unwrapped,
        step,
        ResetNeeded,
    ),
}


@pytest.mark.parametrize("case", sorted(ORDERS))
def test_calls_in_the_wrong_order_raise_clearly(case: str) -> None:
    setup, call, error = ORDERS[case]
    env = setup()
    with pytest.raises(error) as caught:
        call(env)
    assert isinstance(caught.value, RuntimeError)
    assert any(word in str(caught.value) for word in ("reset()", "close()")), caught.value


def test_wrappers_refuse_steps_before_reset_as_gymnasium_does() -> None:
    env = gym.make(ACL_CLIMB_BENCHMARK_ID, **SMALL)
    with pytest.raises(gym.error.ResetNeeded):
        env.step(zero(env.unwrapped))
    env.close()
    env.close()


# Valid sequences, with what they do (envs/lifecycle.py documents them).
def _close_twice(env: ACLClimbEnv) -> None:
    env.close()
    env.close()


def _reset_twice(env: ACLClimbEnv) -> None:
    first, _ = env.reset(seed=3)
    second, _ = env.reset(seed=3)
    np.testing.assert_array_equal(first, second)


def _step_past_the_end(env: ACLClimbEnv) -> None:
    env = small(cycles_per_episode=1, steps_per_cycle=2)
    env.reset(seed=0)
    env.step(zero(env))
    assert env.step(zero(env))[3] is True
    assert env.step(zero(env))[3] is True  # the physics continues; the flag stays set


def _step_after_a_fall(env: ACLClimbEnv) -> None:
    env = small(kp=1e-3)
    env.reset(seed=0)
    outcomes = [env.step(zero(env))[2] for _ in range(40)]
    assert any(outcomes) and all(type(done) is bool for done in outcomes)


def _render_none(env: ACLClimbEnv) -> None:
    env.reset(seed=0)
    with pytest.warns(UserWarning, match="render_mode"):
        assert env.render() is None


def _render_rgb(env: ACLClimbEnv) -> None:
    env = small(render_mode="rgb_array", width=16, height=12)
    env.reset(seed=0)
    assert env.render().shape == (12, 16, 3)
    env.close()


def _copy_of_closed_is_open(env: ACLClimbEnv) -> None:
    env.reset(seed=0)
    env.close()
    twin = pickle.loads(pickle.dumps(env))
    twin.step(zero(twin))  # it had been reset: it continues; its own simulation is open
    twin.close()


def _close_before_reset(env: ACLClimbEnv) -> None:
    env.close()


def _reset_after_done_starts_anew(env: ACLClimbEnv) -> None:
    env = small(cycles_per_episode=1, steps_per_cycle=2)
    env.reset(seed=0)
    while not env.step(zero(env))[3]:
        pass
    env.reset(seed=1)
    assert env.step(zero(env))[3] is False


def _vector_env(env: ACLClimbEnv) -> None:
    envs = gym.vector.SyncVectorEnv([lambda: small() for _ in range(2)])
    envs.reset(seed=[1, 2])
    envs.step(np.zeros(envs.action_space.shape))
    envs.close()
    envs.close()


VALID_SEQUENCES: dict[str, Callable[[ACLClimbEnv], None]] = {
    "close twice": _close_twice,
    "close before reset": _close_before_reset,
    "reset twice, same seed, same start": _reset_twice,
    "step past the truncation": _step_past_the_end,
    "step after a fall": _step_after_a_fall,
    "render with render_mode None warns": _render_none,
    "render rgb_array": _render_rgb,
    "copy of a closed env": _copy_of_closed_is_open,
    "reset after the end": _reset_after_done_starts_anew,
    "vector env closed twice": _vector_env,
}


@pytest.mark.parametrize("case", sorted(VALID_SEQUENCES))
def test_valid_sequences_behave_as_documented(case: str) -> None:
    VALID_SEQUENCES[case](small())


WRONG_KIND_SEEDS: list[Any] = [True, False, np.bool_(True), 1.0, 1.5, math.nan, "1", b"1", [1]]
WRONG_KIND_SEEDS += [(1, 2), {"seed": 1}, np.array(1), Decimal(1), object()]
BAD_SEEDS = [(seed, TypeError) for seed in WRONG_KIND_SEEDS]
BAD_SEEDS += [(seed, ValueError) for seed in (-1, -HUGE, np.int64(-3))]


@pytest.mark.parametrize(("seed", "error"), BAD_SEEDS, ids=[shown(s) for s, _ in BAD_SEEDS])
def test_bad_seeds_are_refused_by_name(seed: Any, error: type) -> None:
    env = small()
    with pytest.raises(error, match="seed"):
        env.reset(seed=seed)


@pytest.mark.parametrize("seed", [None, 0, 7, np.int64(7), np.uint8(7), 2**64, HUGE], ids=shown)
def test_good_seeds_reset(seed: Any) -> None:
    env = small()
    obs, _ = env.reset(seed=seed)
    assert np.isfinite(obs).all()
    if seed is not None:
        again, _ = small().reset(seed=int(seed))
        np.testing.assert_array_equal(obs, again)


@pytest.mark.parametrize("options", [[], "x", 1, ("a", 1)], ids=shown)
def test_bad_options_are_refused_by_name(options: Any) -> None:
    with pytest.raises(TypeError, match="options"):
        small().reset(seed=0, options=options)


def test_options_mapping_is_accepted_and_unused() -> None:
    a, _ = small().reset(seed=0, options={})
    b, _ = small().reset(seed=0, options={"anything": 1})
    np.testing.assert_array_equal(a, b)


N = SMALL["n_joints"]
# Wrong shapes and non-finite entries (ValueError); not real numbers (TypeError).
WRONG_SHAPES: list[Any] = [np.zeros(N - 1), np.zeros(N + 1), np.zeros(()), np.zeros((1, N)), []]
WRONG_SHAPES += [np.zeros((N, 1)), 0.0, np.full(N, math.nan), np.array([0.0, math.inf, 0.0, 0.0])]
WRONG_SHAPES += [np.array([0, 0, -math.inf, 0]), np.array([0, 0, 0, math.nan], dtype=np.float32)]
NOT_REAL: list[Any] = [np.zeros(N, dtype=bool), np.zeros(N, dtype=complex), np.array([None] * N)]
NOT_REAL += [["0"] * N, "abcd", None, {"joint_0": 0.0}, [[0.0, 0.0], [0.0]], [HUGE] * N]
NOT_REAL += [np.zeros(N, dtype="datetime64[s]")]  # [HUGE] * N: an object array, as is ragged
BAD_ACTIONS = [(a, ValueError) for a in WRONG_SHAPES] + [(a, TypeError) for a in NOT_REAL]


@pytest.mark.parametrize(("action", "error"), BAD_ACTIONS, ids=[shown(a) for a, _ in BAD_ACTIONS])
def test_bad_actions_are_refused_by_name(action: Any, error: type) -> None:
    env = reset(small())
    with pytest.raises(error, match="action"):
        env.step(action)
    env.step(zero(env))  # the env is still usable


# Real arrays of any dtype; values outside [-1, 1] clipped, as documented.
GOOD_ACTIONS: list[Any] = [np.zeros(N, dtype=np.float32), np.zeros(N, dtype=np.float16)]
GOOD_ACTIONS += [np.zeros(N, dtype=np.int32), np.ones(N, dtype=np.uint8), [0.5] * N, (0, 1, -1, 0)]
GOOD_ACTIONS += [np.full(N, 1e300), np.full(N, -5.0)]


@pytest.mark.parametrize("action", GOOD_ACTIONS, ids=shown)
def test_real_actions_of_any_dtype_step(action: Any) -> None:
    env = reset(small())
    obs, reward, *_ = env.step(action)
    assert np.isfinite(obs).all() and type(reward) is float
    clipped = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
    twin = reset(small())
    np.testing.assert_array_equal(obs, twin.step(clipped)[0])


def test_the_lifecycle_table_has_its_cases() -> None:
    """The target: at least 60 lifecycle cases (plain outputs and human rendering without
    a display: tests/test_env_robustness.py)."""
    cases = (
        len(ORDERS)
        + len(VALID_SEQUENCES)
        + len(BAD_SEEDS)
        + 7  # good seeds
        + 5  # options
        + len(BAD_ACTIONS)
        + len(GOOD_ACTIONS)
        + 1  # wrappers
    )
    assert cases >= 60, cases
