"""The gait and cadence options of ``ACLClimbEnv`` (:class:`GaitConfig`): the base gait, its
keyword arguments and squeeze on each pole, the residual's scale, the cadence action's range and
the modulated gait parameters; their checks and accepted ranges.

The upper bounds and why: ``steps_per_cycle <= 2200`` (10x the paper's cadence): the gait's
keyframe table is computed in one batch, about 0.1 MB per keyframe (250 MB at 2200), which also
bounds the ACL gait's ``n_samples`` to [100, 1000]. ``residual_scale <= pi``: targets are clipped
to +-pi/2, so a larger residual changes nothing. ``phase_rate_range``: ``high <= steps_per_cycle
/ 2``, beyond which the phase aliases. ``squeeze`` spans about an order of magnitude around the
SEA snake's own, and must stay below pole + module radius on every pole an episode can draw.
``gait_kwargs`` must not set ``n_joints``, ``steps_per_cycle`` (the env's), ``module_length`` or
``module_diameter`` (the model's).
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from acl_env import tuned_gaits
from acl_env.constants import DEFAULT_POLE_RADIUS, JOINT_LIMIT, SEA_MODULE_RADIUS
from acl_env.envs.modulation import (
    DEFAULT_SECTIONS,
    check_modulation,
    check_sections,
    section_weights,
)
from acl_env.gait import ACLGait, Gait, RollingHelixGait
from acl_env.gait.gaits import DEFAULT_SQUEEZE, helix_radius
from acl_env.validation import (
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


@lru_cache(maxsize=16)
def cached_gait(name: str, items: tuple[tuple[str, Any], ...]) -> Gait:
    """Gait objects are immutable; their keyframe tables are worth sharing across resets."""
    gait = GAITS[name](**dict(items))
    gait.cycle()
    return gait


STEPS_PER_CYCLE_RANGE = (2, 2200)
SQUEEZE_RANGE = (-0.05, 0.05)  # m
RESIDUAL_SCALE_MAX = math.pi  # rad
GAIT_SAMPLES_RANGE = (100, 1000)  # the ACL gait's n_samples
# The env's own settings: a gait_kwargs entry for them would disagree with the model.
GAIT_KWARGS_REFUSED = ("n_joints", "steps_per_cycle", "module_length", "module_diameter")


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


@dataclass(frozen=True)
class GaitConfig:
    """The base gait and the cadence: the gait (and the tuned entry it came from), its keyword
    arguments and squeeze, the residual's scale, the cadence action's range, and the modulated
    parameters with their body sections (``section_weights``: their hat functions)."""

    base_gait: str
    tuned_gait: str | None
    gait_kwargs: dict[str, Any]
    squeeze: float
    squeeze_slope: float
    steps_per_cycle: int
    residual_scale: float
    phase_rate_range: tuple[float, float] | None
    gait_modulation: dict[str, float]
    modulation_sections: int
    section_weights: np.ndarray

    @property
    def modulated(self) -> tuple[str, ...]:
        """The modulated gait parameters, in the action's order."""
        return tuple(self.gait_modulation)

    @property
    def gait_class(self) -> type[Gait] | None:
        return GAITS[self.base_gait]

    def squeeze_at(self, pole_radius: float) -> float:
        """The squeeze (m) the helix is commanded with on a pole of ``pole_radius``."""
        return squeeze_at(self.squeeze, self.squeeze_slope, pole_radius)

    def kwargs_at(self, pole_radius: float, n_joints: int) -> dict[str, Any]:
        """The gait's keyword arguments on a pole of ``pole_radius``."""
        squeeze = self.squeeze_at(pole_radius)
        return gait_kwargs_at(
            pole_radius, squeeze, self.gait_kwargs, n_joints, self.steps_per_cycle
        )

    @classmethod
    def checked(cls, raw: Mapping[str, Any], n_joints: int, poles: Sequence[float]) -> GaitConfig:
        """The gait arguments of ``raw`` checked; the gait must exist on every pole of ``poles``
        (those an episode can draw)."""
        base_gait = check_choice("base_gait", raw["base_gait"], tuple(GAITS))
        squeeze, gait_kwargs, tuned = raw["squeeze"], raw["gait_kwargs"], raw["tuned_gait"]
        if tuned is not None:
            # A shipped tuned gait by key (acl_env.tuned_gaits): its squeeze and gait_kwargs.
            check_string("tuned_gait", tuned)
            if base_gait != "acl":
                raise ValueError(f"tuned_gait needs base_gait 'acl', got {base_gait!r}")
            shape = tuned_gaits.resolve(
                {"tuned_gait": tuned, "squeeze": squeeze, "gait_kwargs": gait_kwargs}
            )
            squeeze, gait_kwargs = shape["squeeze"], shape["gait_kwargs"]
        squeeze = DEFAULT_SQUEEZE if squeeze is None else squeeze
        steps = check_int("steps_per_cycle", raw["steps_per_cycle"], *STEPS_PER_CYCLE_RANGE)
        scale = raw["residual_scale"]
        default_scale = JOINT_LIMIT if base_gait == "none" else 0.2
        scale = check_positive(
            "residual_scale", default_scale if scale is None else scale, RESIDUAL_SCALE_MAX
        )
        modulation = check_modulation(raw["gait_modulation"])
        sections = raw["modulation_sections"]
        sections = check_sections(
            min(DEFAULT_SECTIONS, n_joints) if sections is None else sections, n_joints
        )
        if modulation and GAITS[base_gait] is None:
            raise ValueError("gait_modulation needs a base gait to modulate, got base_gait='none'")
        config = cls(
            base_gait=base_gait,
            tuned_gait=tuned,
            gait_kwargs=_gait_kwargs(gait_kwargs, base_gait),
            squeeze=check_range("squeeze", squeeze, *SQUEEZE_RANGE),
            squeeze_slope=check_range("squeeze_slope", raw["squeeze_slope"], 0.0, 1.0),
            steps_per_cycle=steps,
            residual_scale=scale,
            phase_rate_range=_phase_rate_range(raw["phase_rate_range"], steps),
            gait_modulation=modulation,
            modulation_sections=sections,
            section_weights=section_weights(n_joints, sections),
        )
        config.check_poles(poles, n_joints)
        return config

    def check_poles(self, poles: Sequence[float], n_joints: int) -> None:
        """The gait must exist for every pole the episodes can draw (its radius follows it)."""
        for radius in sorted(set(poles)):
            squeeze_there = self.squeeze_at(radius)
            if helix_radius(radius, squeeze_there) <= 0.0 and "radius" not in self.gait_kwargs:
                raise ValueError(
                    f"squeeze={squeeze_there} leaves no helix radius for a pole of {radius} m "
                    f"(squeeze must be below pole radius + {SEA_MODULE_RADIUS} m)"
                )
            start_gait = self.gait_class or ACLGait
            try:
                start_gait(**self.kwargs_at(radius, n_joints))  # raises naming the bad entry
            except (TypeError, ValueError) as error:
                if not self.gait_kwargs:
                    raise
                kind = ValueError if isinstance(error, ValueError) else TypeError
                shown_kwargs = shown(self.gait_kwargs)
                raise kind(f"gait_kwargs={shown_kwargs} on a {radius} m pole: {error}") from None


__all__ = [
    "GAITS",
    "GAIT_KWARGS_REFUSED",
    "GAIT_SAMPLES_RANGE",
    "RESIDUAL_SCALE_MAX",
    "SQUEEZE_RANGE",
    "STEPS_PER_CYCLE_RANGE",
    "GaitConfig",
    "cached_gait",
    "gait_kwargs_at",
    "squeeze_at",
]
