"""Constructor input: the argument checks, and property tests (Hypothesis) of the env's documented
ranges: inside them the env builds, resets and steps with finite output; outside them it raises
``ValueError`` or ``TypeError`` naming the argument, never another exception."""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from acl_env.actuators import ACTUATOR_MODELS, actuator_model
from acl_env.actuators import sea as sea_model
from acl_env.actuators.base import LATENCY_RANGE
from acl_env.actuators.servo import KP_MAX
from acl_env.constants import CONTROL_DT, DEFAULT_KP
from acl_env.envs import ACLClimbEnv
from acl_env.envs.config import (
    CYCLES_PER_EPISODE_RANGE,
    FALL_DISTANCE_MAX,
    FRICTION_MAX,
    IMAGE_SIZE_RANGE,
    N_JOINTS_RANGE,
    POLE_RADIUS_RANGE,
    TIMESTEP_RANGE,
)
from acl_env.envs.contacts import SLIP_SAMPLES
from acl_env.envs.gait_config import (
    GAIT_SAMPLES_RANGE,
    RESIDUAL_SCALE_MAX,
    SQUEEZE_RANGE,
    STEPS_PER_CYCLE_RANGE,
)
from acl_env.envs.modulation import MODULATED_PARAMETERS, SECTIONS_RANGE
from acl_env.envs.randomize import (
    SENSOR_NOISE_MAX,
    default_randomization,
    randomization_bounds,
    randomization_keys,
)
from acl_env.envs.rewards import DEFAULT_REWARD_WEIGHTS
from acl_env.gait.gaits import SEA_MODULE_DIAMETER, SEA_MODULE_RADIUS
from acl_env.model import build_model
from acl_env.validation import (
    SHOWN_CHARS,
    check_bool,
    check_choice,
    check_finite,
    check_int,
    check_mapping,
    check_positive,
    check_range,
    check_sequence,
    shown,
)

# No example database: nothing is written into the working folder; the draws are seeded.
PROPERTY = settings(
    max_examples=25,
    deadline=None,
    database=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
FAST_REJECT = settings(PROPERTY, max_examples=300)
_MODEL = build_model()
CAMERAS = tuple(_MODEL.camera(i).name for i in range(_MODEL.ncam))


@pytest.fixture(autouse=True, scope="module")
def _mujoco_log_in_tmp(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """MuJoCo appends warnings (extreme but accepted physics) to MUJOCO_LOG.TXT in the cwd."""
    with pytest.MonkeyPatch.context() as patch:
        patch.chdir(tmp_path_factory.mktemp("mujoco_log"))
        yield


# --- the helpers ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("check", "value", "error"),
    [
        (lambda v: check_bool("flag", v), "false", TypeError),
        (lambda v: check_bool("flag", v), 1, TypeError),
        (lambda v: check_bool("flag", v), None, TypeError),
        (lambda v: check_finite("x", v), "0.5", TypeError),
        (lambda v: check_finite("x", v), None, TypeError),
        (lambda v: check_finite("x", v), True, TypeError),
        (lambda v: check_finite("x", v), [0.5], TypeError),
        (lambda v: check_finite("x", v), math.nan, ValueError),
        (lambda v: check_finite("x", v), -math.inf, ValueError),
        (lambda v: check_positive("x", v), 0.0, ValueError),
        (lambda v: check_positive("x", v, 2.0), 2.5, ValueError),
        (lambda v: check_range("x", v, 0.0, 1.0), 1.5, ValueError),
        (lambda v: check_range("x", v, 0.0, 1.0, low_open=True), 0.0, ValueError),
        (lambda v: check_int("x", v, 1), "3", TypeError),
        (lambda v: check_int("x", v, 1), False, TypeError),
        (lambda v: check_int("x", v, 1), 3.0, ValueError),
        (lambda v: check_int("x", v, 1), 3.5, ValueError),
        (lambda v: check_int("x", v, 1, 10), 11, ValueError),
        (lambda v: check_int("x", v, 1), 0, ValueError),
        (lambda v: check_choice("x", v, ("a", "b")), "c", ValueError),
        (lambda v: check_choice("x", v, ("a", "b")), 1, TypeError),
        (lambda v: check_sequence("x", v, 2, check_finite), 0.5, TypeError),
        (lambda v: check_sequence("x", v, 2, check_finite), "ab", TypeError),
        (lambda v: check_sequence("x", v, 2, check_finite), (1.0, 2.0, 3.0), ValueError),
        (lambda v: check_sequence("x", v, 2, check_finite), (1.0, "2"), TypeError),
        (lambda v: check_mapping("x", v, ("a",)), [("a", 1)], TypeError),
        (lambda v: check_mapping("x", v, ("a",)), {"b": 1}, ValueError),
        (lambda v: check_mapping("x", v, ("a",)), {1: 1}, TypeError),
        # Integers beyond any float, or beyond Python's 4300-digit printing limit.
        (lambda v: check_finite("x", v), 10**400, ValueError),
        (lambda v: check_positive("x", v), -(10**400), ValueError),
        (lambda v: check_range("x", v, 0.0, 1.0), 10**5000, ValueError),
        (lambda v: check_int("x", v, 1, 10), 10**5000, ValueError),
        (lambda v: check_sequence("x", v, 2, check_finite), (0.5, 10**400), ValueError),
        (lambda v: check_sequence("x", v, 2, check_finite), [10**5000], ValueError),
        (lambda v: check_choice("x", v, (1, 2)), 10**5000, ValueError),
        (lambda v: check_mapping("x", v, ("a",)), {10**5000: 1}, TypeError),
    ],
    ids=lambda v: shown(v) if isinstance(v, int) else None,  # pytest cannot print 10**5000
)
def test_checks_refuse_naming_the_argument(check: Any, value: object, error: type) -> None:
    with pytest.raises(error) as caught:
        check(value)
    assert type(caught.value) is error
    assert caught.value.args[0].split()[0].startswith(("x", "flag"))


def test_messages_show_values_abbreviated() -> None:
    """A 5000-digit integer cannot be printed (Python refuses), a huge list should not be."""
    assert shown(10**400) == "an integer of about 401 digits"
    assert shown(-(10**5000)) == "an integer of about 5001 digits"
    assert shown([10**5000]) == "<list>"
    assert len(shown(list(range(1000)))) == SHOWN_CHARS and shown(list(range(1000))).endswith("...")
    assert shown(2**63) == repr(2**63) and shown("x") == "'x'"
    with pytest.raises(ValueError, match=r"^x must be finite, got an integer of about 401 digits$"):
        check_finite("x", 10**400)


def test_checks_accept_and_convert() -> None:
    assert check_bool("b", np.bool_(True)) is True
    assert check_finite("x", np.float32(0.5)) == 0.5 and type(check_finite("x", 2)) is float
    assert check_int("n", np.int64(4), 3, 5) == 4 and type(check_int("n", np.int64(4), 3)) is int
    assert check_range("x", 1.0, 0.0, 1.0) == 1.0
    assert check_sequence("p", np.array([0.5, 1.5]), 2, check_finite) == (0.5, 1.5)
    assert check_sequence("p", [1, 2], 2, check_finite) == (1.0, 2.0)
    assert check_mapping("m", {"a": 1}, ("a", "b")) == {"a": 1}
    assert check_choice("c", None, (None, "a")) is None


# --- the reported examples ------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "error", "name"),
    [
        ({"pole_radius": None}, TypeError, "pole_radius"),
        ({"kp": "20"}, TypeError, "kp"),
        ({"phase_rate_range": (0.5, 1.5, 2)}, ValueError, "phase_rate_range"),
        ({"phase_rate_range": 1.5}, TypeError, "phase_rate_range"),
        ({"domain_randomization": 1}, TypeError, "domain_randomization"),
        ({"domain_randomization": "false"}, TypeError, "domain_randomization"),
        ({"domain_randomization": {"kp": (15.0, 900.0)}}, ValueError, "domain_randomization"),
        ({"domain_randomization": {"pole_radius": 0.07}}, TypeError, "domain_randomization"),
        ({"reward_weights": [1, 2]}, TypeError, "reward_weights"),
        ({"reward_weights": {"climb": "1"}}, TypeError, "reward_weights"),
        ({"privileged_obs": "false"}, TypeError, "privileged_obs"),
        ({"privileged_obs": 1}, TypeError, "privileged_obs"),
        ({"width": 0}, ValueError, "width"),
        ({"height": 10_000}, ValueError, "height"),
        ({"camera_name": "nope"}, ValueError, "camera_name"),
        ({"camera_name": 0}, TypeError, "camera_name"),
        ({"render_mode": "bogus"}, ValueError, "render_mode"),
        ({"n_joints": 1000}, ValueError, "n_joints"),
        ({"n_joints": 20.0}, ValueError, "n_joints"),
        ({"steps_per_cycle": 10**6}, ValueError, "steps_per_cycle"),
        ({"cycles_per_episode": 100}, ValueError, "cycles_per_episode"),
        ({"gait_kwargs": {"foo": 1.0}}, ValueError, "gait_kwargs"),
        ({"gait_kwargs": {"module_length": 0.1}}, ValueError, "gait_kwargs"),
        ({"gait_kwargs": {"n_samples": 10**6}}, ValueError, "gait_kwargs"),
        ({"gait_kwargs": {"pitch": "0.1"}}, TypeError, "gait_kwargs"),
        ({"gait_kwargs": [1]}, TypeError, "gait_kwargs"),
        ({"base_gait": None}, TypeError, "base_gait"),
        ({"squeeze": 0.04, "pole_radius": 0.01}, ValueError, "squeeze"),
        ({"residual_scale": 4.0}, ValueError, "residual_scale"),
    ],
)
def test_constructor_refuses_naming_the_argument(
    kwargs: dict[str, Any], error: type, name: str
) -> None:
    with pytest.raises(error, match=name):
        ACLClimbEnv(**kwargs)


def test_randomized_gait_must_exist_for_every_drawn_pole() -> None:
    """A gait argument that is valid for the nominal pole but not for the thinnest drawn one is
    refused at construction, not at some later reset."""
    ACLClimbEnv(gait_kwargs={"amp_radial": 0.09})
    with pytest.raises(ValueError, match="amp_radial"):
        ACLClimbEnv(gait_kwargs={"amp_radial": 0.09}, domain_randomization=True)


# --- inside the documented ranges: the env runs ------------------------------------------------


def run_briefly(env: ACLClimbEnv, seed: int) -> None:
    """Reset and two random steps: every output finite and inside its space."""
    obs, info = env.reset(seed=seed)
    assert obs.shape == env.observation_space.shape and np.all(np.isfinite(obs))
    rng = np.random.default_rng(seed)
    for _ in range(2):
        action = rng.uniform(-1.0, 1.0, env.action_space.shape)
        obs, reward, terminated, truncated, info = env.step(action)
        assert obs.shape == env.observation_space.shape and np.all(np.isfinite(obs))
        assert math.isfinite(reward)
        assert all(math.isfinite(v) for v in info.values() if isinstance(v, float))
        if terminated or truncated:
            break
    env.close()


def within(bounds: tuple[float, float], *, open_low: bool = False) -> st.SearchStrategy[float]:
    return st.floats(*bounds, exclude_min=open_low, allow_nan=False)


def dr_range(key: str, limits: tuple[float, float]) -> st.SearchStrategy[tuple[float, float]]:
    low = max(limits[0], 1e-6)
    return st.tuples(within((low, limits[1])), within((low, limits[1]))).map(
        lambda pair: (min(pair), max(pair))
    )


RANGE_BOUNDS = {
    k: v for model in ACTUATOR_MODELS.values() for k, v in randomization_bounds(model).items()
}
DEFAULT_RANDOMIZATION = default_randomization("servo")
RANDOMIZATION_LIMITS = {
    **RANGE_BOUNDS,
    "pole_radius": POLE_RADIUS_RANGE,
    "friction": (0.0, FRICTION_MAX),
    "friction_step": (0.0, FRICTION_MAX),
    "kp": (0.0, KP_MAX),
}


SEA_RANGES = {
    "spring_stiffness": sea_model.SPRING_STIFFNESS_RANGE,
    "motor_speed_limit": sea_model.MOTOR_SPEED_LIMIT_RANGE,
    "control_latency": LATENCY_RANGE,
    "sensor_latency": LATENCY_RANGE,
}


@st.composite
def valid_kwargs(draw: st.DrawFn) -> dict[str, Any]:
    """Arguments inside the documented ranges; episodes kept tiny (few keyframes per cycle)."""
    steps = draw(st.integers(STEPS_PER_CYCLE_RANGE[0], 12))
    base_gait = draw(st.sampled_from(["acl", "rolling_helix", "none"]))
    sea = draw(st.booleans())
    # The keys each actuator model randomises: the servo's kp, or the SEA's parameters.
    dr_limits = {
        k: v
        for k, v in RANDOMIZATION_LIMITS.items()
        if k in randomization_keys(actuator_model("sea" if sea else "servo"))
    }
    gait_options: dict[str, st.SearchStrategy[Any]] = {"pitch": within((SEA_MODULE_DIAMETER, 0.3))}
    if base_gait != "rolling_helix":  # the ACL gait's (it also places "none"'s start pose)
        gait_options["n_samples"] = st.integers(GAIT_SAMPLES_RANGE[0], 400)
    kwargs: dict[str, Any] = {
        "base_gait": base_gait,
        "n_joints": draw(st.integers(*N_JOINTS_RANGE)),
        "steps_per_cycle": steps,
        "cycles_per_episode": CYCLES_PER_EPISODE_RANGE[0],
        "pole_radius": draw(within(POLE_RADIUS_RANGE)),
        "friction": draw(within((0.0, FRICTION_MAX), open_low=True)),
        "kp": DEFAULT_KP if sea else draw(within((0.0, KP_MAX), open_low=True)),
        "residual_scale": draw(st.none() | within((0.0, RESIDUAL_SCALE_MAX), open_low=True)),
        "privileged_obs": draw(st.booleans()),
        "start_phase_range": draw(within((0.0, 1.0))),
        "reset_noise_scale": draw(within((0.0, math.pi / 2))),
        "fall_distance": draw(within((0.0, FALL_DISTANCE_MAX), open_low=True)),
        "reward_weights": draw(
            st.none()
            | st.dictionaries(
                st.sampled_from(sorted(DEFAULT_REWARD_WEIGHTS)), within((-10.0, 10.0))
            )
        ),
        "phase_rate_range": draw(
            st.none() | st.tuples(within((0.0, 1.0)), within((1.0, steps / 2)))
        ),
        "domain_randomization": draw(
            st.none()
            | st.booleans()
            | st.fixed_dictionaries(
                {},
                optional={
                    **{k: dr_range(k, v) for k, v in dr_limits.items()},
                    "sensor_noise": within((0.0, SENSOR_NOISE_MAX)),
                },
            )
        ),
        "gait_kwargs": draw(st.none() | st.fixed_dictionaries({}, optional=gait_options)),
        "width": draw(st.integers(*IMAGE_SIZE_RANGE)),
        "height": draw(st.integers(*IMAGE_SIZE_RANGE)),
        "camera_name": draw(st.sampled_from(CAMERAS)),
        # Documented as 0.1 s / (5 k) within the range: 5 contact samples of whole steps.
        "timestep": draw(st.integers(4, 40).map(lambda k: CONTROL_DT / (SLIP_SAMPLES * k))),
    }
    if sea:
        kwargs["actuator_model"] = "sea"
        for name, bounds in SEA_RANGES.items():
            kwargs[name] = draw(st.none() | within(bounds))
    modulated = {"acl": MODULATED_PARAMETERS, "rolling_helix": {"squeeze": 0.02}}
    if base_gait in modulated:
        options = {k: within((0.0, v), open_low=True) for k, v in modulated[base_gait].items()}
        kwargs["gait_modulation"] = draw(st.none() | st.fixed_dictionaries({}, optional=options))
        top_sections = min(SECTIONS_RANGE[1], kwargs["n_joints"])
        kwargs["modulation_sections"] = draw(st.none() | st.integers(1, top_sections))
    # squeeze must leave a helix radius for every pole the episodes can draw.
    dr = kwargs["domain_randomization"]
    poles = [kwargs["pole_radius"]]
    if dr is True:
        poles.append(DEFAULT_RANDOMIZATION["pole_radius"][0])
    elif isinstance(dr, dict) and "pole_radius" in dr:
        poles.append(dr["pole_radius"][0])
    top = min(SQUEEZE_RANGE[1], min(poles) + SEA_MODULE_RADIUS - 1e-3)
    kwargs["squeeze"] = draw(within((SQUEEZE_RANGE[0], top)))
    return kwargs


@PROPERTY
@given(kwargs=valid_kwargs(), seed=st.integers(0, 2**31 - 1))
def test_documented_ranges_construct_reset_and_step(kwargs: dict[str, Any], seed: int) -> None:
    run_briefly(ACLClimbEnv(**kwargs), seed)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"n_joints": N_JOINTS_RANGE[1], "steps_per_cycle": 4},
        {"n_joints": N_JOINTS_RANGE[0]},
        {"steps_per_cycle": STEPS_PER_CYCLE_RANGE[1]},
        {"cycles_per_episode": CYCLES_PER_EPISODE_RANGE[1], "steps_per_cycle": 4},
        {"pole_radius": POLE_RADIUS_RANGE[0], "squeeze": SQUEEZE_RANGE[0]},
        {"pole_radius": POLE_RADIUS_RANGE[1], "squeeze": SQUEEZE_RANGE[1]},
        {"kp": KP_MAX, "friction": FRICTION_MAX, "residual_scale": RESIDUAL_SCALE_MAX},
        {"reset_noise_scale": math.pi / 2, "start_phase_range": 1.0, "steps_per_cycle": 4},
        {"base_gait": "none", "n_joints": N_JOINTS_RANGE[1], "steps_per_cycle": 4},
        {
            "domain_randomization": {
                "pole_radius": POLE_RADIUS_RANGE,
                "kp": (1e-3, KP_MAX),
                "mass_scale": (1e-3, RANGE_BOUNDS["mass_scale"][1]),
                "sensor_noise": SENSOR_NOISE_MAX,
            },
            "squeeze": 0.0,
            "steps_per_cycle": 4,
        },
    ],
    ids=lambda kwargs: ",".join(kwargs),
)
def test_documented_bounds_run(kwargs: dict[str, Any]) -> None:
    """The ends of every documented range, where a crash or a runaway allocation would be."""
    run_briefly(ACLClimbEnv(**kwargs), seed=0)


# --- outside them: a clear error -----------------------------------------------------------------

NOT_A_NUMBER = st.one_of(st.text(max_size=5), st.none(), st.booleans(), st.lists(st.floats()))
NON_FINITE = st.sampled_from([math.nan, math.inf, -math.inf])


def outside(low: float, high: float, *, open_low: bool = False) -> st.SearchStrategy[Any]:
    below = st.floats(max_value=low, exclude_max=not open_low, allow_nan=False)
    above = st.floats(min_value=high, exclude_min=True, allow_nan=False)
    return below | above | NON_FINITE | NOT_A_NUMBER


def outside_int(low: int, high: int) -> st.SearchStrategy[Any]:
    ints = st.integers(max_value=low - 1) | st.integers(min_value=high + 1)
    return ints | st.floats(allow_nan=True) | NOT_A_NUMBER


def bad_pair(limits: tuple[float, float]) -> st.SearchStrategy[Any]:
    """Not a (low, high) inside ``limits``: wrong length, wrong kind, reversed or out of range."""
    low, high = max(limits[0], 0.0), limits[1]
    open_low = limits[0] <= 0.0  # a range of a positive quantity: low = 0 is refused too
    return st.one_of(
        st.floats(allow_nan=False),
        st.text(max_size=3),
        st.lists(st.floats(low, high), min_size=3, max_size=4).map(tuple),
        st.tuples(st.floats(low, high), st.floats(low, high))
        .filter(lambda p: p[0] > p[1])
        .map(tuple),
        st.tuples(outside(low, high, open_low=open_low), st.floats(low, high)),
    )


def whole_samples(timestep: float) -> bool:
    """The documented rule: 0.1 s is 5 k physics steps (5 contact samples of k steps)."""
    steps = round(CONTROL_DT / timestep)
    return steps % SLIP_SAMPLES == 0 and math.isclose(steps * timestep, CONTROL_DT, rel_tol=1e-9)


BAD_ARGUMENTS: dict[str, st.SearchStrategy[Any]] = {
    "base_gait": st.text(max_size=8).filter(lambda s: s not in ("acl", "rolling_helix", "none"))
    | st.integers()
    | st.none(),
    "n_joints": outside_int(*N_JOINTS_RANGE),
    "steps_per_cycle": outside_int(*STEPS_PER_CYCLE_RANGE),
    "cycles_per_episode": outside_int(*CYCLES_PER_EPISODE_RANGE),
    "pole_radius": outside(*POLE_RADIUS_RANGE),
    "friction": outside(0.0, FRICTION_MAX, open_low=True),
    "kp": outside(0.0, KP_MAX, open_low=True),
    # None is squeeze's default (0.008 m; set by tuned_gait when that is given).
    "squeeze": outside(*SQUEEZE_RANGE).filter(lambda v: v is not None),
    "tuned_gait": st.text(max_size=8).filter(lambda s: s not in ("acl", "acl_noroll"))
    | st.integers()
    | st.floats(),
    "residual_scale": outside(0.0, RESIDUAL_SCALE_MAX, open_low=True).filter(
        lambda v: v is not None
    ),
    "start_phase_range": outside(0.0, 1.0),
    "reset_noise_scale": outside(0.0, math.pi / 2),
    "fall_distance": outside(0.0, FALL_DISTANCE_MAX, open_low=True),
    "timestep": outside(*TIMESTEP_RANGE, open_low=True)
    | st.floats(*TIMESTEP_RANGE).filter(lambda t: not whole_samples(t)),
    "privileged_obs": st.integers() | st.text(max_size=5) | st.floats(),
    "width": outside_int(*IMAGE_SIZE_RANGE),
    "height": outside_int(*IMAGE_SIZE_RANGE),
    "camera_name": st.text(max_size=8).filter(lambda s: s not in CAMERAS) | st.integers(),
    "render_mode": st.text(max_size=8).filter(
        lambda s: s not in ACLClimbEnv.metadata["render_modes"]
    )
    | st.integers(),
    "phase_rate_range": st.one_of(
        st.floats(allow_nan=False),
        st.text(max_size=3),
        st.lists(st.floats(0.0, 2.0), min_size=3, max_size=4).map(tuple),
        st.tuples(outside(0.0, 1.0), st.floats(1.0, 2.0)),  # low outside [0, 1]
        st.tuples(st.floats(0.0, 1.0), st.floats(max_value=1.0, exclude_max=True)),  # high < 1
        st.tuples(st.floats(0.0, 1.0), st.floats(111.0, 1e6)),  # high > steps_per_cycle / 2
        st.tuples(st.floats(0.0, 1.0), NON_FINITE | NOT_A_NUMBER),
    ),
    "reward_weights": st.one_of(
        st.lists(st.floats(), max_size=3),
        st.integers(),
        st.text(max_size=3),
        st.dictionaries(
            st.text(max_size=6).filter(lambda k: k not in DEFAULT_REWARD_WEIGHTS),
            st.floats(-1, 1),
            min_size=1,
        ),
        st.fixed_dictionaries({"climb": NON_FINITE | NOT_A_NUMBER}),
    ),
    "domain_randomization": st.one_of(
        st.integers(),
        st.text(max_size=5),
        st.lists(st.booleans(), max_size=2),
        st.dictionaries(
            st.text(max_size=6).filter(lambda k: k not in DEFAULT_RANDOMIZATION),
            st.floats(),
            min_size=1,
        ),
        st.sampled_from(sorted(RANDOMIZATION_LIMITS)).flatmap(
            lambda k: bad_pair(RANDOMIZATION_LIMITS[k]).map(lambda v: {k: v})
        ),
        outside(0.0, SENSOR_NOISE_MAX).map(lambda v: {"sensor_noise": v}),
    ),
    "gait_kwargs": st.one_of(
        st.lists(st.integers(), max_size=2),
        st.text(max_size=3),
        st.dictionaries(
            st.text(max_size=6).filter(lambda k: k not in ("pitch", "radius")),
            st.floats(),
            min_size=1,
        ),
        st.sampled_from(["n_joints", "steps_per_cycle", "module_length", "module_diameter"]).map(
            lambda k: {k: 1}
        ),
        st.fixed_dictionaries({"pitch": NOT_A_NUMBER}),
        outside_int(*GAIT_SAMPLES_RANGE).map(lambda v: {"n_samples": v}),
    ),
}


@FAST_REJECT
@given(data=st.data(), name=st.sampled_from(sorted(BAD_ARGUMENTS)))
def test_outside_the_ranges_raises_naming_the_argument(data: st.DataObject, name: str) -> None:
    value = data.draw(BAD_ARGUMENTS[name], label=name)
    with pytest.raises((ValueError, TypeError)) as caught:
        ACLClimbEnv(**{name: value})
    assert name in str(caught.value), str(caught.value)
