"""``ACLClimbEnv``'s options: its keyword arguments declared once, the typed configs they become
(one per concern: physics and pole, actuator, gait and cadence, grip, reward, randomisation,
episode, rendering), and their checks and accepted ranges.

The env's constructor takes the keyword arguments declared in ``envs/arguments.py`` (its
signature is built from them) and maps them to an :class:`EnvConfig` in one place,
:meth:`EnvConfig.from_kwargs`.
Every argument is checked for type and range when the env is built: a value of the wrong kind
(``"false"`` for a bool, ``1`` for ``domain_randomization``, a string for a number) raises
``TypeError``, one out of range ``ValueError``, both naming the argument and what it accepts
(``acl_env.validation``). Every accepted combination resets and steps with finite output
(property-tested), so no value accepted here can crash reset or step later.

The upper bounds and why (the gait's: ``envs/gait_config.py``): ``n_joints <= 100``: 300
joints diverge during the reset and 1000 overflow MuJoCo's memory arena (``mujoco.FatalError``).
``cycles_per_episode <= 8``: the pole is 4 m tall and the snake climbs 0.25-0.38 m per cycle, so
it would reach the top after about 9 cycles; ``fall_distance <= 4`` for the same reason.
``pole_radius``, ``friction`` and ``kp`` span about an order of magnitude around the SEA snake's
own. ``width``, ``height <= 4096``: MuJoCo's offscreen buffer.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import mujoco

from acl_env.actuators import ACTUATOR_MODELS, ActuatorModel, all_options, owners
from acl_env.actuators.base import ActuatorConfig
from acl_env.constants import (
    CONTROL_DT,
    JOINT_LIMIT,
)
from acl_env.envs.arguments import DEFAULTS
from acl_env.envs.contacts import SLIP_SAMPLES
from acl_env.envs.gait_config import GaitConfig
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
from acl_env.envs.randomize import check_randomization
from acl_env.envs.rewards import DEFAULT_REWARD_WEIGHTS, check_reward_weights
from acl_env.validation import (
    check_bool,
    check_choice,
    check_int,
    check_mapping,
    check_positive,
    check_range,
    check_string,
    shown,
)

# Accepted ranges of the constructor's arguments (the Arguments table says why).
N_JOINTS_RANGE = (3, 100)
CYCLES_PER_EPISODE_RANGE = (1, 8)
OBS_HISTORY_MAX = 8  # past sensor frames an observation may carry
POLE_RADIUS_RANGE = (0.01, 0.5)  # m
FRICTION_MAX = 5.0
FALL_DISTANCE_MAX = 4.0  # m: the pole's height
ROLL_LIMIT_MAX = 3600.0  # deg: ten turns, more than any episode can roll (about 2 per cycle)
IMAGE_SIZE_RANGE = (1, 4096)  # pixels
# s: physics steps accepted; 5 ms was the largest without MuJoCo warnings in the fidelity panel
# (benchmarks/fidelity.py), 0.5 ms costs 200 MuJoCo steps per env step.
TIMESTEP_RANGE = (0.0005, 0.005)


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


@dataclass(frozen=True)
class PhysicsConfig:
    """The physics and the pole: joints, pole radius (m), friction, physics step (s), the
    physics steps per 0.1 s control step (``frame_skip``), and the friction the pole drops to at
    a random step (``friction_step``; None: it does not)."""

    n_joints: int
    pole_radius: float
    friction: float
    timestep: float
    frame_skip: int
    friction_step: float | None = None  # the friction the pole drops to mid-episode (events.py)

    @classmethod
    def checked(cls, raw: Mapping[str, Any]) -> PhysicsConfig:
        step, frame_skip = _timestep(raw["timestep"])
        drop = raw["friction_step"]
        return cls(
            n_joints=check_int("n_joints", raw["n_joints"], *N_JOINTS_RANGE),
            pole_radius=check_range("pole_radius", raw["pole_radius"], *POLE_RADIUS_RANGE),
            friction=check_positive("friction", raw["friction"], FRICTION_MAX),
            timestep=step,
            frame_skip=frame_skip,
            friction_step=None
            if drop is None
            else check_positive("friction_step", drop, FRICTION_MAX),
        )


@dataclass(frozen=True)
class GripConfig:
    """The compliant grip (``envs/grip.py``): its force target (N), gain (m/(N s)), leak (s) and
    the force target's range per unit action (N)."""

    target: float
    gain: float
    leak: float
    action_scale: float

    @classmethod
    def checked(
        cls, raw: Mapping[str, Any], model: ActuatorModel, gait: GaitConfig, physics: PhysicsConfig
    ) -> GripConfig | None:
        """The grip of ``raw``, checked; None when ``grip_target`` is None. It reads the
        springs, so it needs an elastic actuator, and adapts a gait's squeeze."""
        options = ("grip_gain", "grip_leak", "grip_action_scale")
        if raw["grip_target"] is None:
            for name in options:
                if raw[name] is not None:
                    raise ValueError(f"{name} needs grip_target (the compliant grip), got None")
            return None
        if not model.elastic:
            elastic = " or ".join(repr(m.name) for m in ACTUATOR_MODELS.values() if m.elastic)
            raise ValueError(
                f"grip_target needs actuator_model={elastic} (the springs measure the grip), "
                f"got {model.name!r}"
            )
        if gait.gait_class is None:
            raise ValueError("grip_target needs a base gait to adapt, got base_gait='none'")
        gain, leak, scale = (raw[name] for name in options)
        config = cls(
            target=check_range("grip_target", raw["grip_target"], *GRIP_TARGET_RANGE),
            gain=check_range("grip_gain", GRIP_GAIN if gain is None else gain, *GRIP_GAIN_RANGE),
            leak=check_range("grip_leak", GRIP_LEAK if leak is None else leak, *GRIP_LEAK_RANGE),
            action_scale=check_range(
                "grip_action_scale", 0.0 if scale is None else scale, 0.0, GRIP_ACTION_SCALE_MAX
            ),
        )
        check_ticks(physics.frame_skip)
        return config


@dataclass(frozen=True)
class EpisodeConfig:
    """The episode: its length in cycles, the start's phase range and joint noise (rad), the
    fall distance (m), the roll limit (deg), whether the centre of mass and the physics are
    observed, and how many past sensor frames are."""

    cycles_per_episode: int
    start_phase_range: float
    reset_noise_scale: float
    fall_distance: float
    roll_limit: float | None
    privileged_obs: bool
    obs_history: int

    @classmethod
    def checked(cls, raw: Mapping[str, Any]) -> EpisodeConfig:
        roll_limit = raw["roll_limit"]
        return cls(
            cycles_per_episode=check_int(
                "cycles_per_episode", raw["cycles_per_episode"], *CYCLES_PER_EPISODE_RANGE
            ),
            start_phase_range=check_range("start_phase_range", raw["start_phase_range"], 0.0, 1.0),
            reset_noise_scale=check_range(
                "reset_noise_scale", raw["reset_noise_scale"], 0.0, JOINT_LIMIT
            ),
            fall_distance=check_positive("fall_distance", raw["fall_distance"], FALL_DISTANCE_MAX),
            roll_limit=None
            if roll_limit is None
            else check_positive("roll_limit", roll_limit, ROLL_LIMIT_MAX),
            privileged_obs=check_bool("privileged_obs", raw["privileged_obs"]),
            obs_history=check_int("obs_history", raw["obs_history"], 0, OBS_HISTORY_MAX),
        )


@dataclass(frozen=True)
class RenderConfig:
    """Rendering: Gymnasium's render mode, the frame's size (pixels) and the camera (checked
    against the model once it is built: :func:`check_camera`)."""

    render_mode: str | None
    width: int
    height: int
    camera_name: str

    @classmethod
    def checked(cls, raw: Mapping[str, Any], render_modes: Sequence[str]) -> RenderConfig:
        mode = raw["render_mode"]
        if mode is not None:
            check_choice("render_mode", mode, tuple(render_modes))
            check_display(mode)  # "human" needs a window: refused here rather than aborting
        return cls(
            render_mode=mode,
            width=check_int("width", raw["width"], *IMAGE_SIZE_RANGE),
            height=check_int("height", raw["height"], *IMAGE_SIZE_RANGE),
            camera_name=check_string("camera_name", raw["camera_name"]),
        )


@dataclass(frozen=True)
class EnvConfig:
    """Every option of an ``ACLClimbEnv``, one typed config per concern, each checked once.
    ``randomization``: the checked ranges (``envs/randomize.py``; empty when off);
    ``reward_weights``: the weight of each reward term (``envs/rewards.py``)."""

    physics: PhysicsConfig
    actuator: ActuatorConfig
    gait: GaitConfig
    grip: GripConfig | None
    reward_weights: dict[str, float]
    randomization: dict[str, Any]
    episode: EpisodeConfig
    render: RenderConfig

    @classmethod
    def from_kwargs(cls, kwargs: Mapping[str, Any], render_modes: Sequence[str]) -> EnvConfig:
        """The configs of the env's keyword arguments ``kwargs`` (defaults: ``envs/arguments.py``);
        ``render_modes``: the env's ``metadata["render_modes"]``."""
        unknown = sorted(set(kwargs) - set(DEFAULTS))
        if unknown:
            raise TypeError(
                f"ACLClimbEnv got an unexpected keyword argument {unknown[0]!r} "
                f"(accepted: {', '.join(DEFAULTS)})"
            )
        raw = {**DEFAULTS, **kwargs}
        physics = PhysicsConfig.checked(raw)
        name = check_choice("actuator_model", raw["actuator_model"], tuple(ACTUATOR_MODELS))
        model = ACTUATOR_MODELS[name]
        options = actuator_options(model, {o: raw[o] for o in all_options()})
        friction = (0.0, FRICTION_MAX)
        bounds = {"pole_radius": POLE_RADIUS_RANGE, "friction": friction, "friction_step": friction}
        ranges = check_randomization(raw["domain_randomization"], bounds, model)
        if physics.friction_step is not None and "friction_step" in ranges:
            raise ValueError(
                "friction_step and domain_randomization['friction_step'] are both given: "
                "a fixed friction step or a drawn one, not both"
            )
        history = ranges.get("control_latency", (0.0, 0.0))[1]
        poles = (physics.pole_radius, *ranges.get("pole_radius", ()))
        gait = GaitConfig.checked(raw, physics.n_joints, poles)
        weights = raw["reward_weights"]
        if weights is not None:
            weights = check_mapping("reward_weights", weights, DEFAULT_REWARD_WEIGHTS)
        return cls(
            physics=physics,
            actuator=ActuatorConfig(model, options, history_latency=history),
            gait=gait,
            grip=GripConfig.checked(raw, model, gait, physics),
            reward_weights=check_reward_weights(weights),
            randomization=ranges,
            episode=EpisodeConfig.checked(raw),
            render=RenderConfig.checked(raw, render_modes),
        )


__all__ = [
    "CYCLES_PER_EPISODE_RANGE",
    "FALL_DISTANCE_MAX",
    "FRICTION_MAX",
    "IMAGE_SIZE_RANGE",
    "N_JOINTS_RANGE",
    "OBS_HISTORY_MAX",
    "POLE_RADIUS_RANGE",
    "ROLL_LIMIT_MAX",
    "TIMESTEP_RANGE",
    "EnvConfig",
    "EpisodeConfig",
    "GripConfig",
    "PhysicsConfig",
    "RenderConfig",
    "actuator_options",
    "check_camera",
]
