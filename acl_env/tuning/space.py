"""The tuner's search space: the gait parameters searched and their ranges, the untuned gait, the
conditions a study may fix, and the checks of command-line overrides of both."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from acl_env.actuators import all_options
from acl_env.envs.grip import GRIP_LEAK
from acl_env.gait.gaits import (
    DEFAULT_AMP_PITCH,
    DEFAULT_PITCH,
    DEFAULT_POLE_RADIUS,
    DEFAULT_SQUEEZE,
    SEA_MODULE_DIAMETER,
    helix_radius,
)
from acl_env.io import parse_kv_pairs
from acl_env.tuned_gaits import GRIP_KWARGS

# Searched parameters that are env arguments (the squeeze, and with --grip the compliant grip's
# law, searched on the env's own gait); the rest are gait_kwargs.
ENV_PARAMS = ("squeeze", *GRIP_KWARGS)
# Env arguments --condition may fix for a whole study (the physical conditions of the held-out
# evaluation and the benchmark grid: the pole, friction, and the actuator models' options, such
# as the servo's kp or the SEA's spring_stiffness and control_latency); the env checks them.
CONDITIONS = ("pole_radius", "friction", *all_options())


class UsageError(ValueError):
    """Bad command-line input: reported as one line naming the argument, exit status 2."""

    def __init__(self, argument: str, message: str) -> None:
        super().__init__(f"argument {argument}: {message}")


@dataclass(frozen=True)
class ParamRange:
    """A searched parameter's bounds; ``integer`` ones are suggested as whole numbers."""

    low: float
    high: float
    integer: bool = False


# Default search space. The hard limits of the gait (checked by check_space, the gait raises
# otherwise) are A_p, A_r >= 0, A_r below the helix radius, pitch >= one module diameter and, for
# this tuner, whole wave numbers; inside them the ranges are chosen as follows (the clipping
# shares are those of 400 random gaits of this space with Omega, k_r up to 4: half of them clip
# more than 10 % of their joint angles and are disqualified without a rollout):
# - squeeze -0.4 to 1.6 cm: from a loose helix (-0.4 cm climbs 0.141 m/cycle at default waves, the
#   grip giving way) to twice the default 0.8 cm (1.2 cm costs 1549 J/m against 1176: the energy
#   grows with the squeeze; measured with the v0 physics). The helix radius 10.04 cm - squeeze
#   stays far above A_r. The tuned non-rolling gait sits at 1.57 cm; with its waves, 1.9 cm scores
#   less (and clips 13 %) and 2.3 cm rolls (3 seeds, v1), and a 140-trial study with squeeze up
#   to 3 cm found nothing better (best reward 0.0006 against 0.0212).
# - amp_pitch 0-5 cm: 0 is the rolling helix; the best non-rolling gaits measured so far use 3-4
#   cm (clipping 4-8 % of their joint angles); above 3.6 cm three gaits in four clip over 10 %.
# - spatial_freq, radial_freq 1-3, whole numbers: a whole number of waves per turn repeats the
#   wave on every turn, so adjacent turns stay exactly one pitch apart (z(t + 2 pi) - z(t) =
#   pitch) and the pitch bound below keeps them from colliding all along the body. Omega >= 1:
#   the wave's direction sets the direction of travel (Omega = -2 slides down). At 4 waves per
#   turn 70 % of the gaits clip over 10 % (21-34 % at 1-2).
# - amp_radial 0-2.5 cm: 0 is the paper's Eq. 2; at 2 cm with A_p 4 cm the non-rolling gait
#   already falls.
# - pitch 7-16 cm: at least 7 cm leaves 2 cm between turns of the 5.08 cm modules (the gait
#   refuses less than one module diameter); at 16 cm the 1.34 m body still makes two turns.
SEARCH_SPACE: dict[str, ParamRange] = {
    "squeeze": ParamRange(-0.004, 0.016),
    "amp_pitch": ParamRange(0.0, 0.05),
    "spatial_freq": ParamRange(1, 3, integer=True),
    "amp_radial": ParamRange(0.0, 0.025),
    "radial_freq": ParamRange(1, 3, integer=True),
    "pitch": ParamRange(0.07, 0.16),
}
# The untuned gait (the env's and ACLGait's defaults): trial 0 of every new study.
DEFAULT_PARAMS: dict[str, float] = {
    "squeeze": DEFAULT_SQUEEZE,
    "amp_pitch": DEFAULT_AMP_PITCH,
    "spatial_freq": 2,
    "amp_radial": 0.0,
    "radial_freq": 2,
    "pitch": DEFAULT_PITCH,
}


# The compliant grip's search space: targets from slack (0 N) to twice the largest section's mean
# squeeze force on the open loop (about 170 N on ACLClimb-v3); gains up to 5e-4 m/(N s), beyond
# which the filtered loop goes unstable (3e-4 at 150 N already falls, docs/grip.md); leaks from
# 0.1 s (the squeeze back within two steps) to 5 s (nearly integral).
GRIP_SPACE: dict[str, ParamRange] = {
    "grip_target": ParamRange(0.0, 350.0),
    "grip_gain": ParamRange(0.0, 5e-4),
    "grip_leak": ParamRange(0.1, 5.0),
}
# Trial 0 of a grip study: no gain, i.e. the open loop itself, measured in the same study.
GRIP_DEFAULT_PARAMS: dict[str, float] = {
    "grip_target": 0.0,
    "grip_gain": 0.0,
    "grip_leak": GRIP_LEAK,
}


def start_points(keys: Sequence[str], space: Mapping[str, ParamRange]) -> list[dict[str, float]]:
    """The search-space points of shipped tuned gaits (``acl_env.tuned_gaits`` keys): a study
    can start from a gait tuned on other physics or for another objective (``--start-from``).
    A key that is not shipped, or a gait outside ``space``, raises :class:`UsageError`."""
    from acl_env import tuned_gaits  # the package's shipped data

    points = []
    for key in keys:
        try:
            shape = tuned_gaits.gait_shape(key)
        except tuned_gaits.TunedGaitsError as exc:
            raise UsageError("--start-from", str(exc)) from None
        values = {"squeeze": shape.get("squeeze"), **(shape.get("gait_kwargs") or {})}
        point = {name: values.get(name) for name in space}
        outside = [
            name
            for name, value in point.items()
            if value is None or not space[name].low <= value <= space[name].high
        ]
        if outside:
            raise UsageError("--start-from", f"{key!r} is outside the search space in {outside}")
        points.append({k: float(v) if not space[k].integer else int(v) for k, v in point.items()})
    return points


def check_space(space: Mapping[str, ParamRange], pole_radius: float = DEFAULT_POLE_RADIUS) -> None:
    """Raise :class:`UsageError` (``--space``) if a range leaves the gait's validity."""
    for name, r in space.items():
        if name not in SEARCH_SPACE:
            raise UsageError("--space", f"unknown parameter {name!r}; known: {list(SEARCH_SPACE)}")
        if not (math.isfinite(r.low) and math.isfinite(r.high)) or r.low > r.high:
            raise UsageError("--space", f"{name} needs finite low <= high, got {r.low}:{r.high}")
        if r.integer and (r.low != round(r.low) or r.high != round(r.high)):
            raise UsageError(
                "--space",
                f"{name} takes whole numbers (a whole number of waves per turn keeps adjacent "
                f"turns one pitch apart), got {r.low}:{r.high}",
            )
    for name in ("amp_pitch", "amp_radial"):
        if space[name].low < 0.0:
            raise UsageError("--space", f"{name} must be >= 0, got low {space[name].low}")
    if space["pitch"].low < SEA_MODULE_DIAMETER:
        raise UsageError(
            "--space",
            f"pitch must be at least one module diameter ({SEA_MODULE_DIAMETER} m) so that "
            f"adjacent turns do not collide, got low {space['pitch'].low}",
        )
    radius = helix_radius(pole_radius, space["squeeze"].high)
    if space["amp_radial"].high >= radius:
        raise UsageError(
            "--space",
            f"amp_radial must stay below the helix radius ({radius:.4f} m at squeeze "
            f"{space['squeeze'].high}), got high {space['amp_radial'].high}",
        )


def parse_space(
    items: Sequence[str], pole_radius: float = DEFAULT_POLE_RADIUS
) -> dict[str, ParamRange]:
    """``NAME:LOW:HIGH`` overrides of :data:`SEARCH_SPACE`, checked against the gait's validity
    on a pole of ``pole_radius``."""
    space = dict(SEARCH_SPACE)
    for item in items:
        parts = item.split(":")
        if len(parts) != 3:
            raise UsageError("--space", f"expected NAME:LOW:HIGH, got {item!r}")
        name, low, high = parts
        if name not in SEARCH_SPACE:
            raise UsageError("--space", f"unknown parameter {name!r}; known: {list(SEARCH_SPACE)}")
        try:
            bounds = float(low), float(high)
        except ValueError:
            raise UsageError("--space", f"{name} bounds must be numbers, got {item!r}") from None
        space[name] = ParamRange(*bounds, integer=SEARCH_SPACE[name].integer)
    check_space(space, pole_radius)
    return space


def parse_pairs(items: Sequence[str], option: str) -> dict[str, Any]:
    """``key:value`` items of ``option`` (:func:`acl_env.io.parse_kv_pairs`); a malformed item or
    a key given twice raises :class:`UsageError` naming ``option``."""
    try:
        return parse_kv_pairs(items, option)
    except ValueError as exc:
        raise UsageError(option, str(exc).removeprefix(f"{option}: ")) from None


def finite_number(value: Any, option: str, name: str) -> float:
    """``value`` as a finite float; anything else (a word, a bool, 1e309, a 400-digit integer)
    raises :class:`UsageError` naming ``option`` and ``name``."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise UsageError(option, f"{name} must be a number, got {value!r}")
    try:
        number = float(value)
    except OverflowError:
        number = math.inf
    if not math.isfinite(number):
        text = str(value)
        shown = f"{text[:12]}... ({len(text)} digits)" if len(text) > 24 else text
        raise UsageError(option, f"{name} must be a finite number, got {shown}")
    return number


def parse_condition(items: Sequence[str]) -> dict[str, float | list[float]]:
    """``--condition NAME:VALUE ...`` as ``{name: value}``, names from :data:`CONDITIONS`; a
    value may be a list (``friction:[0.7,1.2]``): the study then plays the grid of them all."""
    condition = parse_pairs(items, "--condition")
    for name, value in condition.items():
        if name not in CONDITIONS:
            raise UsageError("--condition", f"unknown {name!r}; known: {list(CONDITIONS)}")
        values = list(value) if isinstance(value, list | tuple) else [value]
        if not values:
            raise UsageError("--condition", f"{name} takes a number or a list, got {value!r}")
        values = [finite_number(v, "--condition", name) for v in values]
        if len(set(values)) != len(values):
            raise UsageError("--condition", f"{name} repeats a value: {value!r}")
        condition[name] = values if len(values) > 1 else values[0]
    return condition
