"""``ACLClimbEnv``'s keyword arguments, declared once: name, default, type, the concern (config)
each belongs to, what it accepts and what it means. The constructor's signature is built from
them (:func:`signature`), the check of configuration files reads their types
(``envs/kwargs.py``), :class:`acl_env.envs.config.EnvConfig` maps them to the typed configs, and
the docs' table is rendered from them (:func:`markdown_table`, ``docs/hooks/layouts.py``).
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from acl_env.actuators import DEFAULT_MODEL, all_options
from acl_env.constants import (
    DEFAULT_FRICTION,
    DEFAULT_N_JOINTS,
    DEFAULT_POLE_RADIUS,
    DEFAULT_STEPS_PER_CYCLE,
    PHYSICS_TIMESTEP,
    TRACK_CAMERA,
)


@dataclass(frozen=True)
class Argument:
    """One keyword argument of the env."""

    name: str
    default: Any
    annotation: Any
    concern: str  # the EnvConfig field it becomes part of
    accepted: str
    meaning: str


def _actuator_arguments() -> tuple[Argument, ...]:
    """The actuator models' options (:mod:`acl_env.actuators`), each an argument of every env,
    refused on the models that do not have it."""
    out = []
    for option in all_options().values():
        always = option.unset is not None  # passed by every env (the servo's kp)
        accepted = f"{'(' if option.low_open else '['}{option.low:g}, {option.high:g}]"
        meaning = f"{option.doc}, {option.unit}" + ("" if always else f" ({option.default:g})")
        annotation = float if always else float | None
        out.append(Argument(option.name, option.unset, annotation, "actuator", accepted, meaning))
    return tuple(out)


ARGUMENTS: tuple[Argument, ...] = (
    Argument(
        "base_gait",
        "acl",
        str,
        "gait",
        '"acl", "rolling_helix", "none"',
        'base gait ("none": pure RL ablation)',
    ),
    Argument(
        "gait_kwargs",
        None,
        Mapping[str, Any] | None,
        "gait",
        "dict of numbers in the gait's ranges",
        "to the gait; radius: see squeeze",
    ),
    Argument(
        "residual_scale",
        None,
        float | None,
        "gait",
        "(0, pi]",
        'rad of joint target per unit action (0.2; pi/2 for "none")',
    ),
    Argument("n_joints", DEFAULT_N_JOINTS, int, "physics", "int in [3, 100]", "joints (links - 1)"),
    Argument("pole_radius", DEFAULT_POLE_RADIUS, float, "physics", "[0.01, 0.5]", "m"),
    Argument("friction", DEFAULT_FRICTION, float, "physics", "(0, 5]", "of the skin and the pole"),
    Argument(
        "friction_step",
        None,
        float | None,
        "physics",
        "None or (0, 5]",
        "friction the pole drops to at a random step of the episode",
    ),
    Argument(
        "squeeze",
        None,
        float | None,
        "gait",
        "[-0.05, 0.05]",
        "m the helix is commanded inside the pole contact (0.008)",
    ),
    Argument(
        "steps_per_cycle",
        DEFAULT_STEPS_PER_CYCLE,
        int,
        "gait",
        "int in [2, 2200]",
        "keyframes per gait cycle (one per 0.1 s step)",
    ),
    Argument("cycles_per_episode", 2, int, "episode", "int in [1, 8]", "episode length, cycles"),
    Argument(
        "reward_weights",
        None,
        Mapping[str, float] | None,
        "reward_weights",
        "dict of [-1e6, 1e6]",
        'weights of the reward terms ({"climb": 1, "slip": 1})',
    ),
    Argument(
        "domain_randomization",
        None,
        bool | Mapping[str, Any] | None,
        "randomization",
        "None, bool or dict",
        "True for the actuator model's defaults, or (low, high) ranges",
    ),
    Argument(
        "privileged_obs",
        False,
        bool,
        "episode",
        "bool",
        "observe the centre of mass and the physics",
    ),
    Argument(
        "obs_history",
        0,
        int,
        "episode",
        "int in [0, 8]",
        "past steps' joint and IMU readings observed",
    ),
    Argument(
        "start_phase_range", 0.05, float, "episode", "[0, 1]", "share of a cycle the start is in"
    ),
    Argument("reset_noise_scale", 0.02, float, "episode", "[0, pi/2]", "rad of joint noise"),
    Argument("fall_distance", 0.2, float, "episode", "(0, 4]", "m of drop that is a fall"),
    Argument(
        "phase_rate_range",
        None,
        tuple[float, float] | None,
        "gait",
        "None or (low, high)",
        "keyframes per step: the policy sets the cadence",
    ),
    Argument(
        "timestep",
        PHYSICS_TIMESTEP,
        float,
        "physics",
        "0.1 s / (5 k), 0.5-5 ms",
        "physics step, s (1/300)",
    ),
    Argument("roll_limit", None, float | None, "episode", "None or (0, 3600]", "deg of roll swept"),
    Argument(
        "gait_modulation",
        None,
        Mapping[str, float] | None,
        "gait",
        "None or {parameter: (0, 0.02]}",
        "m of gait offset per unit action",
    ),
    Argument(
        "modulation_sections",
        None,
        int | None,
        "gait",
        "int in [1, min(20, n_joints)]",
        "body sections modulated (4)",
    ),
    Argument("squeeze_slope", 0.0, float, "gait", "[0, 1]", "m of squeeze per m of thinner pole"),
    Argument("render_mode", None, str | None, "render", "None or a metadata mode", "Gymnasium's"),
    Argument("width", 640, int, "render", "int in [1, 4096]", "pixels"),
    Argument("height", 480, int, "render", "int in [1, 4096]", "pixels"),
    Argument("camera_name", TRACK_CAMERA, str, "render", '"track", "side", "top"', "the camera"),
    Argument(
        "tuned_gait",
        None,
        str | None,
        "gait",
        "an acl_env.tuned_gaits key",
        "a tuned gait: its squeeze and gait_kwargs",
    ),
    Argument(
        "actuator_model",
        DEFAULT_MODEL,
        str,
        "actuator",
        "a key of acl_env.actuators.ACTUATOR_MODELS",
        "the joints' actuators",
    ),
    *_actuator_arguments(),
    Argument(
        "grip_target",
        None,
        float | None,
        "grip",
        "[-500, 500]",
        "N: the compliant grip's force target per section (elastic actuators)",
    ),
    Argument("grip_gain", None, float | None, "grip", "[0, 0.01]", "m/(N s) (1e-4)"),
    Argument("grip_leak", None, float | None, "grip", "[0.01, 100]", "s (1)"),
    Argument(
        "grip_action_scale",
        None,
        float | None,
        "grip",
        "[0, 500]",
        "N of grip target per unit action (0)",
    ),
)
DEFAULTS: dict[str, Any] = {a.name: a.default for a in ARGUMENTS}


def signature() -> inspect.Signature:
    """The constructor's signature: ``self`` and :data:`ARGUMENTS`, keyword-only."""
    parameter, keyword = inspect.Parameter, inspect.Parameter.KEYWORD_ONLY
    params = [parameter("self", parameter.POSITIONAL_OR_KEYWORD)]
    params += [
        parameter(a.name, keyword, default=a.default, annotation=a.annotation) for a in ARGUMENTS
    ]
    return inspect.Signature(params, return_annotation=None)


def markdown_table() -> str:
    """:data:`ARGUMENTS` as a markdown table (the docs')."""
    rows = ["| argument | default | accepted | meaning | config |", "|---|---|---|---|---|"]
    for a in ARGUMENTS:
        rows.append(
            f"| `{a.name}` | `{a.default!r}` | {a.accepted} | {a.meaning} | `{a.concern}` |"
        )
    return "\n".join(rows)


__all__ = ["ARGUMENTS", "DEFAULTS", "Argument", "markdown_table", "signature"]
