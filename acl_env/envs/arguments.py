"""The checks of ``ACLClimbEnv``'s constructor arguments, and their accepted ranges.

Every argument is checked for type and range when the env is built: a value of the wrong kind
(``"false"`` for a bool, ``1`` for ``domain_randomization``, a string for a number) raises
``TypeError``, one out of range ``ValueError``, both naming the argument and what it accepts
(``acl_env.validation``). Every accepted combination resets and steps with finite output
(property-tested), so no value accepted here can crash reset or step later.

The upper bounds and why: ``n_joints <= 100``: 300 joints diverge during the reset and 1000
overflow MuJoCo's memory arena (``mujoco.FatalError``). ``steps_per_cycle <= 2200`` (10x the
paper's cadence): the gait's keyframe table is computed in one batch, about 0.1 MB per keyframe
(250 MB at 2200), which also bounds the ACL gait's ``n_samples`` to [100, 1000].
``cycles_per_episode <= 8``: the pole is 4 m tall and the snake climbs 0.25-0.38 m per cycle, so
it would reach the top after about 9 cycles; ``fall_distance <= 4`` for the same reason.
``residual_scale <= pi``: targets are clipped to +-pi/2, so a larger residual changes nothing.
``phase_rate_range``: ``high <= steps_per_cycle / 2``, beyond which the phase aliases.
``pole_radius``, ``friction``, ``kp`` and ``squeeze`` span about an order of magnitude around the
SEA snake's own; ``squeeze`` must also stay below pole + module radius on every pole an episode
can draw. ``width``, ``height <= 4096``: MuJoCo's offscreen buffer. ``gait_kwargs`` must not set
``n_joints``, ``steps_per_cycle`` (the env's), ``module_length`` or ``module_diameter`` (the
model's).
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from acl_env import tuned_gaits
from acl_env.actuators import ACTUATOR_MODELS, ActuatorModel, all_options, owners
from acl_env.actuators.base import ActuatorSetting
from acl_env.constants import (
    CONTROL_DT,
    DEFAULT_POLE_RADIUS,
    JOINT_LIMIT,
    SEA_MODULE_RADIUS,
)
from acl_env.envs.contacts import SLIP_SAMPLES
from acl_env.envs.grip import (
    GRIP_ACTION_SCALE_MAX,
    GRIP_GAIN,
    GRIP_GAIN_RANGE,
    GRIP_LEAK,
    GRIP_LEAK_RANGE,
    GRIP_TARGET_RANGE,
    check_ticks,
)
from acl_env.envs.lifecycle import check_display
from acl_env.envs.modulation import (
    DEFAULT_SECTIONS,
    check_modulation,
    check_sections,
    section_weights,
)
from acl_env.envs.randomize import check_randomization
from acl_env.envs.rewards import DEFAULT_REWARD_WEIGHTS, check_reward_weights
from acl_env.gait import ACLGait, Gait, RollingHelixGait
from acl_env.gait.gaits import DEFAULT_SQUEEZE, helix_radius
from acl_env.validation import (
    check_bool,
    check_choice,
    check_finite,
    check_int,
    check_mapping,
    check_positive,
    check_range,
    check_sequence,
    check_string,
    shown,
)

GAITS: dict[str, type[Gait] | None] = {
    "acl": ACLGait,
    "rolling_helix": RollingHelixGait,
    "none": None,
}
# Accepted ranges of the constructor's arguments (the Arguments table says why).
N_JOINTS_RANGE = (3, 100)
STEPS_PER_CYCLE_RANGE = (2, 2200)
CYCLES_PER_EPISODE_RANGE = (1, 8)
POLE_RADIUS_RANGE = (0.01, 0.5)  # m
FRICTION_MAX = 5.0
SQUEEZE_RANGE = (-0.05, 0.05)  # m
RESIDUAL_SCALE_MAX = math.pi  # rad
FALL_DISTANCE_MAX = 4.0  # m: the pole's height
ROLL_LIMIT_MAX = 3600.0  # deg: ten turns, more than any episode can roll (about 2 per cycle)
IMAGE_SIZE_RANGE = (1, 4096)  # pixels
GAIT_SAMPLES_RANGE = (100, 1000)  # the ACL gait's n_samples
# The env's own settings: a gait_kwargs entry for them would disagree with the model.
GAIT_KWARGS_REFUSED = ("n_joints", "steps_per_cycle", "module_length", "module_diameter")
# s: physics steps accepted; 5 ms was the largest without MuJoCo warnings in the fidelity panel
# (benchmarks/fidelity.py), 0.5 ms costs 200 MuJoCo steps per env step.
TIMESTEP_RANGE = (0.0005, 0.005)


@dataclass(frozen=True)
class EnvArguments:
    """The checked constructor arguments, under the env's attribute names (``frame_skip``: MuJoCo
    steps per 0.1 s control step; ``_modulated``, ``_section_weights``: the modulated gait
    parameters and the sections' hat functions, ``envs/modulation.py``)."""

    base_gait: str
    tuned_gait: str | None
    n_joints: int
    steps_per_cycle: int
    cycles_per_episode: int
    residual_scale: float
    pole_radius: float
    friction: float
    kp: float
    squeeze: float
    squeeze_slope: float
    reward_weights: dict[str, float]
    randomization: dict[str, Any]
    privileged_obs: bool
    start_phase_range: float
    reset_noise_scale: float
    fall_distance: float
    phase_rate_range: tuple[float, float] | None
    roll_limit: float | None
    gait_kwargs: dict[str, Any]
    gait_modulation: dict[str, float]
    modulation_sections: int
    _modulated: tuple[str, ...]
    _section_weights: np.ndarray
    timestep: float
    frame_skip: int
    actuator_model: str
    spring_stiffness: float | None
    motor_speed_limit: float | None
    control_latency: float | None
    sensor_latency: float | None
    actuators: ActuatorSetting
    grip_target: float | None
    grip_gain: float | None
    grip_leak: float | None
    grip_action_scale: float | None


def squeeze_at(squeeze: float, squeeze_slope: float, pole_radius: float) -> float:
    """The squeeze (m) the gait's helix is commanded with on a pole of ``pole_radius``:
    ``squeeze``, less ``squeeze_slope`` times how much thinner the pole is than the default
    0.075 m. At 1 the helix keeps the radius it has on the default pole (Eq. 1's r), which the
    +-90 deg joints can still curl; a tighter one is clipped (see "Non-rolling task")."""
    return squeeze - squeeze_slope * max(0.0, DEFAULT_POLE_RADIUS - pole_radius)


def gait_kwargs_at(
    pole_radius: float,
    squeeze: float,
    gait_kwargs: Mapping[str, Any],
    n_joints: int,
    steps_per_cycle: int,
) -> dict[str, Any]:
    """The base gait's keyword arguments on a pole of ``pole_radius``: the helix radius from the
    squeeze there (Eq. 1's r: pole + module radius - squeeze), then ``gait_kwargs``, then the
    env's joints and cadence."""
    kwargs = {"radius": helix_radius(pole_radius, squeeze)}
    kwargs.update(gait_kwargs)
    return {**kwargs, "n_joints": n_joints, "steps_per_cycle": steps_per_cycle}


def check_arguments(
    *,
    base_gait: object,
    gait_kwargs: object,
    residual_scale: object,
    n_joints: object,
    pole_radius: object,
    friction: object,
    kp: object,
    squeeze: object,
    steps_per_cycle: object,
    cycles_per_episode: object,
    reward_weights: object,
    domain_randomization: object,
    privileged_obs: object,
    start_phase_range: object,
    reset_noise_scale: object,
    fall_distance: object,
    phase_rate_range: object,
    timestep: object,
    roll_limit: object,
    gait_modulation: object,
    modulation_sections: object,
    squeeze_slope: object,
    render_mode: object,
    width: object,
    height: object,
    camera_name: object,
    tuned_gait: object,
    actuator_model: object = "servo",
    spring_stiffness: object = None,
    motor_speed_limit: object = None,
    control_latency: object = None,
    sensor_latency: object = None,
    grip_target: object = None,
    grip_gain: object = None,
    grip_leak: object = None,
    grip_action_scale: object = None,
    render_modes: tuple[str, ...],
) -> EnvArguments:
    """Every constructor argument checked, in the constructor's order (the first bad one raises);
    ``render_modes``: the env's ``metadata["render_modes"]``. The camera is checked against the
    model once it is built."""
    base_gait = check_choice("base_gait", base_gait, tuple(GAITS))
    if tuned_gait is not None:
        # A shipped tuned gait by key (acl_env.tuned_gaits): its squeeze and gait_kwargs.
        check_string("tuned_gait", tuned_gait)
        if base_gait != "acl":
            raise ValueError(f"tuned_gait needs base_gait 'acl', got {base_gait!r}")
        shape = tuned_gaits.resolve(
            {"tuned_gait": tuned_gait, "squeeze": squeeze, "gait_kwargs": gait_kwargs}
        )
        squeeze, gait_kwargs = shape["squeeze"], shape["gait_kwargs"]
    squeeze = DEFAULT_SQUEEZE if squeeze is None else squeeze
    n_joints = check_int("n_joints", n_joints, *N_JOINTS_RANGE)
    steps_per_cycle = check_int("steps_per_cycle", steps_per_cycle, *STEPS_PER_CYCLE_RANGE)
    cycles_per_episode = check_int(
        "cycles_per_episode", cycles_per_episode, *CYCLES_PER_EPISODE_RANGE
    )
    default_scale = JOINT_LIMIT if base_gait == "none" else 0.2
    residual_scale = check_positive(
        "residual_scale",
        default_scale if residual_scale is None else residual_scale,
        RESIDUAL_SCALE_MAX,
    )
    pole_radius = check_range("pole_radius", pole_radius, *POLE_RADIUS_RANGE)
    friction = check_positive("friction", friction, FRICTION_MAX)
    squeeze = check_range("squeeze", squeeze, *SQUEEZE_RANGE)
    squeeze_slope = check_range("squeeze_slope", squeeze_slope, 0.0, 1.0)
    weights = check_reward_weights(
        None
        if reward_weights is None
        else check_mapping("reward_weights", reward_weights, DEFAULT_REWARD_WEIGHTS)
    )
    actuator_model = check_choice("actuator_model", actuator_model, tuple(ACTUATOR_MODELS))
    model = ACTUATOR_MODELS[actuator_model]
    given = {
        "kp": kp,
        "spring_stiffness": spring_stiffness,
        "motor_speed_limit": motor_speed_limit,
        "control_latency": control_latency,
        "sensor_latency": sensor_latency,
    }
    options = actuator_options(model, given)
    randomization = check_randomization(
        domain_randomization,
        {"pole_radius": POLE_RADIUS_RANGE, "friction": (0.0, FRICTION_MAX)},
        model,
    )
    privileged_obs = check_bool("privileged_obs", privileged_obs)
    start_phase_range = check_range("start_phase_range", start_phase_range, 0.0, 1.0)
    reset_noise_scale = check_range("reset_noise_scale", reset_noise_scale, 0.0, JOINT_LIMIT)
    fall_distance = check_positive("fall_distance", fall_distance, FALL_DISTANCE_MAX)
    rate_range = _phase_rate_range(phase_rate_range, steps_per_cycle)
    roll_limit = (
        None if roll_limit is None else check_positive("roll_limit", roll_limit, ROLL_LIMIT_MAX)
    )
    if render_mode is not None:
        check_choice("render_mode", render_mode, render_modes)
        check_display(render_mode)  # "human" needs a window: refused here rather than aborting
    check_int("width", width, *IMAGE_SIZE_RANGE)
    check_int("height", height, *IMAGE_SIZE_RANGE)
    check_string("camera_name", camera_name)
    gait_kwargs = _gait_kwargs(gait_kwargs, base_gait)
    # The gait must exist for every pole the episodes can draw (its radius follows the pole).
    for radius in sorted({pole_radius, *randomization.get("pole_radius", ())}):
        squeeze_there = squeeze_at(squeeze, squeeze_slope, radius)
        if helix_radius(radius, squeeze_there) <= 0.0 and "radius" not in gait_kwargs:
            raise ValueError(
                f"squeeze={squeeze_there} leaves no helix radius for a pole of {radius} m "
                f"(squeeze must be below pole radius + {SEA_MODULE_RADIUS} m)"
            )
        start_gait = GAITS[base_gait] or ACLGait
        kwargs = gait_kwargs_at(radius, squeeze_there, gait_kwargs, n_joints, steps_per_cycle)
        try:
            start_gait(**kwargs)  # raises naming the bad entry
        except (TypeError, ValueError) as error:
            if not gait_kwargs:
                raise
            kind = ValueError if isinstance(error, ValueError) else TypeError
            raise kind(f"gait_kwargs={shown(gait_kwargs)} on a {radius} m pole: {error}") from None
    modulation = check_modulation(gait_modulation)
    sections = check_sections(
        min(DEFAULT_SECTIONS, n_joints) if modulation_sections is None else modulation_sections,
        n_joints,
    )
    if modulation and GAITS[base_gait] is None:
        raise ValueError("gait_modulation needs a base gait to modulate, got base_gait='none'")
    timestep, frame_skip = _timestep(timestep)
    grip = _grip_options(grip_target, grip_gain, grip_leak, grip_action_scale, model, base_gait)
    if grip:
        check_ticks(frame_skip)
    history = randomization.get("control_latency", (0.0, 0.0))[1]
    setting = ActuatorSetting(model, options, history_latency=history)
    return EnvArguments(
        base_gait=base_gait,
        tuned_gait=tuned_gait,
        n_joints=n_joints,
        steps_per_cycle=steps_per_cycle,
        cycles_per_episode=cycles_per_episode,
        residual_scale=residual_scale,
        pole_radius=pole_radius,
        friction=friction,
        kp=options.get("kp", all_options()["kp"].default),
        squeeze=squeeze,
        squeeze_slope=squeeze_slope,
        reward_weights=weights,
        randomization=randomization,
        privileged_obs=privileged_obs,
        start_phase_range=start_phase_range,
        reset_noise_scale=reset_noise_scale,
        fall_distance=fall_distance,
        phase_rate_range=rate_range,
        roll_limit=roll_limit,
        gait_kwargs=gait_kwargs,
        gait_modulation=modulation,
        modulation_sections=sections,
        _modulated=tuple(modulation),
        _section_weights=section_weights(n_joints, sections),
        timestep=timestep,
        frame_skip=frame_skip,
        actuator_model=actuator_model,
        spring_stiffness=options.get("spring_stiffness"),
        motor_speed_limit=options.get("motor_speed_limit"),
        control_latency=options.get("control_latency"),
        sensor_latency=options.get("sensor_latency"),
        actuators=setting,
        grip_target=grip.get("grip_target"),
        grip_gain=grip.get("grip_gain"),
        grip_leak=grip.get("grip_leak"),
        grip_action_scale=grip.get("grip_action_scale"),
    )


def actuator_options(model: ActuatorModel, given: Mapping[str, object]) -> dict[str, float]:
    """The actuator ``model``'s options, checked (their defaults where not given): an option of
    another model that was given (not None, nor the constructor's own default) is refused."""
    known = all_options()
    for name, value in given.items():
        option = known[name]
        if option in model.options or value == option.unset:
            continue
        if option.unset is not None:  # an argument every env has: its stiffness
            raise ValueError(
                f"{name} sets the {'/'.join(owners(name))}'s stiffness; with actuator_model="
                f"{model.name!r} set {model.stiffness} instead, got {name}={shown(value)}"
            )
        models = " or ".join(map(repr, owners(name)))
        raise ValueError(f"{name} needs actuator_model={models}, got {model.name!r}")
    out = {}
    for option in model.options:
        value = given.get(option.name)
        value = option.default if value is None and option.unset is None else value
        if option.low_open:
            out[option.name] = check_positive(option.name, value, option.high)
        else:
            out[option.name] = check_range(option.name, value, option.low, option.high)
    return out


def _grip_options(
    target: object,
    gain: object,
    leak: object,
    action_scale: object,
    model: ActuatorModel,
    base_gait: str,
) -> dict[str, float]:
    """The compliant grip's options (``envs/grip.py``), checked; empty when ``grip_target`` is
    None. It reads the springs, so it needs the SEA, and adapts a gait's squeeze."""
    if target is None:
        options = (("grip_gain", gain), ("grip_leak", leak), ("grip_action_scale", action_scale))
        for name, value in options:
            if value is not None:
                raise ValueError(f"{name} needs grip_target (the compliant grip), got None")
        return {}
    if not model.elastic:
        elastic = " or ".join(repr(m.name) for m in ACTUATOR_MODELS.values() if m.elastic)
        raise ValueError(
            f"grip_target needs actuator_model={elastic} (the springs measure the grip), "
            f"got {model.name!r}"
        )
    if GAITS[base_gait] is None:
        raise ValueError("grip_target needs a base gait to adapt, got base_gait='none'")
    return {
        "grip_target": check_range("grip_target", target, *GRIP_TARGET_RANGE),
        "grip_gain": check_range(
            "grip_gain", GRIP_GAIN if gain is None else gain, *GRIP_GAIN_RANGE
        ),
        "grip_leak": check_range(
            "grip_leak", GRIP_LEAK if leak is None else leak, *GRIP_LEAK_RANGE
        ),
        "grip_action_scale": check_range(
            "grip_action_scale",
            0.0 if action_scale is None else action_scale,
            0.0,
            GRIP_ACTION_SCALE_MAX,
        ),
    }


def check_camera(model: mujoco.MjModel, camera_name: str) -> None:
    """``camera_name`` must name a camera of the built ``model``."""
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera_name) < 0:
        cameras = [model.camera(i).name for i in range(model.ncam)]
        raise ValueError(
            f"camera_name must be one of the model's cameras {cameras}, got {camera_name!r}"
        )


def _timestep(value: object) -> tuple[float, int]:
    """Validated physics step (s) and the MuJoCo steps per control step (``frame_skip``): the
    0.1 s control step must be a whole number of physics steps, and of contact samples."""
    timestep = check_positive("timestep", value)
    if not TIMESTEP_RANGE[0] <= timestep <= TIMESTEP_RANGE[1]:
        raise ValueError(
            f"timestep must be in [{TIMESTEP_RANGE[0]}, {TIMESTEP_RANGE[1]}] s, got {timestep}"
        )
    frame_skip = round(CONTROL_DT / timestep)
    if frame_skip < 1 or not math.isclose(frame_skip * timestep, CONTROL_DT, rel_tol=1e-9):
        raise ValueError(
            f"timestep must divide the {CONTROL_DT} s control step into whole steps, got {timestep}"
        )
    if frame_skip % SLIP_SAMPLES:
        raise ValueError(
            f"timestep must give a multiple of {SLIP_SAMPLES} physics steps per control step "
            f"(the contact samples), got {timestep} ({frame_skip} steps)"
        )
    return timestep, frame_skip


def _phase_rate_range(value: object, steps_per_cycle: int) -> tuple[float, float] | None:
    """Validated (low, high) keyframes per step; None keeps the gait's cadence fixed."""
    if value is None:
        return None
    lo, hi = check_sequence("phase_rate_range", value, 2, check_finite)
    if not 0.0 <= lo <= 1.0 <= hi <= steps_per_cycle / 2:
        raise ValueError(
            "phase_rate_range must satisfy 0 <= low <= 1 <= high <= steps_per_cycle / 2 "
            f"= {steps_per_cycle / 2}, got {shown(value)}"
        )
    return (lo, hi)


def _gait_kwargs(value: object, base_gait: str) -> dict[str, Any]:
    """Validated keyword arguments of the base gait (of ACL, which places the start pose, for
    ``"none"``): known keys, real numbers, an integer ``n_samples`` within its memory bound."""
    if value is None:
        return {}
    gait_class = GAITS[base_gait] or ACLGait
    known = [k for k in inspect.signature(gait_class).parameters if k not in GAIT_KWARGS_REFUSED]
    for key in GAIT_KWARGS_REFUSED:
        if isinstance(value, Mapping) and key in value:
            owner = (
                "pass it to the env" if key in ("n_joints", "steps_per_cycle") else "the model's"
            )
            raise ValueError(f"gait_kwargs must not set {key!r} ({owner})")
    kwargs = check_mapping("gait_kwargs", value, known)
    return {
        key: check_int(f"gait_kwargs[{key!r}]", v, *GAIT_SAMPLES_RANGE)
        if key == "n_samples"
        else check_finite(f"gait_kwargs[{key!r}]", v)
        for key, v in kwargs.items()
    }


__all__ = [
    "CYCLES_PER_EPISODE_RANGE",
    "FALL_DISTANCE_MAX",
    "FRICTION_MAX",
    "GAITS",
    "GAIT_KWARGS_REFUSED",
    "GAIT_SAMPLES_RANGE",
    "IMAGE_SIZE_RANGE",
    "N_JOINTS_RANGE",
    "POLE_RADIUS_RANGE",
    "RESIDUAL_SCALE_MAX",
    "ROLL_LIMIT_MAX",
    "SQUEEZE_RANGE",
    "STEPS_PER_CYCLE_RANGE",
    "TIMESTEP_RANGE",
    "EnvArguments",
    "actuator_options",
    "check_arguments",
    "check_camera",
    "gait_kwargs_at",
    "squeeze_at",
]
