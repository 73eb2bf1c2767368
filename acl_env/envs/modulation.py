"""Gait modulation actions: per-section offsets of the gait's own parameters.

The PMTG idea (Iscen et al. 2018) applied to the ACL gait's shape rather than its cadence. Action
entry ``a[p, s]`` in [-1, 1] offsets gait parameter ``p`` (the squeeze or a wave amplitude) by
``a[p, s] * scale_p`` in body section ``s``. Along the body the offset is piecewise linear between
the sections' centres, and it reaches the joint targets through the gait's own kinematics
(Eq. 1-5):

    target_j(k) += sum_p  [q_j(k; p + offset_p(j)) - q_j(k; p)]

with ``q(k; p)`` the gait's keyframe table for parameter value ``p``, interpolated between tables
computed on a grid of offsets. A squeeze offset of ``+1 mm`` in the tail section therefore bends
the tail joints the way a helix 1 mm tighter would, at every phase:
the grip can be set where and when it is needed, which a joint residual can only do joint by
joint (docs/residual_rl.md#gait-modulation).
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping
from functools import lru_cache
from typing import Any

import numpy as np

from acl_env.gait.gaits import Gait
from acl_env.validation import check_int, check_mapping, check_positive

# Parameter -> largest offset per unit action (m) the env accepts. The squeeze enters the gait as
# its radius (radius = pole + module radius - squeeze, so d/dsqueeze = -d/dradius); the others
# are ACLGait's own arguments (Eq. 1: A_p, the axial wave; the radial wave A_r).
MODULATED_PARAMETERS: dict[str, float] = {"squeeze": 0.02, "amp_pitch": 0.02, "amp_radial": 0.02}
SECTIONS_RANGE = (1, 20)
DEFAULT_SECTIONS = 4  # head, two middle sections, tail (fewer when there are fewer joints)
# Offset grid per parameter, -scale .. +scale. The joint angles are far from linear in the
# parameters (a 1 mm tighter helix shifts the curvature wave's phase along the body: up to
# 0.16 rad at the tail; a linear model of it is 40 % off at 2 mm), so the env interpolates
# between tables computed exactly; 9 points keep the interpolation within ~0.005 rad.
GRID = 9
# The offset tables are computed at the pole radius rounded to this (m) and cached: a pole
# drawn by domain randomisation then costs no new tables (the base gait itself stays exact).
TABLE_RADIUS_QUANTUM = 1e-3


def table_radius(pole_radius: float) -> float:
    """The pole radius the offset tables are computed at: rounded to 1 mm."""
    return round(pole_radius / TABLE_RADIUS_QUANTUM) * TABLE_RADIUS_QUANTUM


def check_modulation(value: Mapping[str, Any] | None) -> dict[str, float]:
    """Validated ``{parameter: scale (m per unit action)}``; empty when off."""
    if value is None:
        return {}
    value = check_mapping("gait_modulation", value, MODULATED_PARAMETERS)
    return {
        key: check_positive(f"gait_modulation[{key!r}]", scale, MODULATED_PARAMETERS[key])
        for key, scale in value.items()
    }


def check_sections(value: int, n_joints: int) -> int:
    """Validated number of body sections (at most one per joint)."""
    hi = min(SECTIONS_RANGE[1], n_joints)
    return check_int("modulation_sections", value, SECTIONS_RANGE[0], hi)


def section_weights(n_joints: int, n_sections: int) -> np.ndarray:
    """``(n_joints, n_sections)`` hat functions: joint ``j``'s share of each section's offset.

    The sections' centres are spread evenly from the head joint to the tail joint; between two
    centres the offset is interpolated linearly, so neighbouring sections blend without a step.
    One section is a uniform offset.
    """
    if n_sections == 1:
        return np.ones((n_joints, 1))
    centres = np.linspace(0.0, n_joints - 1.0, n_sections)
    joints = np.arange(n_joints, dtype=float)
    eye = np.eye(n_sections)
    return np.stack([np.interp(joints, centres, eye[s]) for s in range(n_sections)], axis=1)


@lru_cache(maxsize=32)
def offset_tables(
    gait_class: type[Gait],
    items: tuple[tuple[str, Any], ...],
    modulation: tuple[tuple[str, float], ...],
) -> np.ndarray:
    """``(P, GRID, steps_per_cycle, n_joints)``: keyframe table with parameter ``p`` offset by
    grid value ``g`` (``GRID`` points from ``-scale_p`` to ``+scale_p``), less the base table.

    ``items`` are the gait's keyword arguments, ``modulation`` the ``(parameter, scale)`` pairs
    (sorted pairs: cacheable). ``squeeze`` offsets the radius the other way (radius = pole +
    module radius - squeeze); an offset stops where the gait stops being defined (a wave
    amplitude at 0: its wave vanishes; see ``_bounds``). Read-only.
    """
    base = dict(items)
    base_table = gait_class(**base).cycle()
    grid = np.linspace(-1.0, 1.0, GRID)
    out = []
    for name, scale in modulation:
        key, sign = ("radius", -1.0) if name == "squeeze" else (name, 1.0)
        value = float(base[key]) if key in base else _default(gait_class, key)
        rows = []
        low, high = _bounds(key, value, base)
        for g in grid:
            shifted = min(max(value + sign * scale * g, low), high)
            if shifted == value:  # the grid's centre (or a bound at the base value): no change
                rows.append(np.zeros_like(base_table))
            else:
                rows.append(gait_class(**{**base, key: shifted}).cycle() - base_table)
        out.append(np.stack(rows))
    tables = np.stack(out)
    tables.setflags(write=False)
    return tables


def interpolate_offsets(tables: np.ndarray, k: int, offsets: np.ndarray) -> np.ndarray:
    """Joint target change (rad) at keyframe ``k`` for per-joint offsets ``(P, n_joints)`` in
    units of each parameter's scale (in [-1, 1]): linear between :func:`offset_tables`' grid
    points, summed over parameters."""
    n_params, n_grid = tables.shape[:2]
    # np.minimum/np.maximum: np.clip's result without its dispatch (every firmware tick)
    u = (np.minimum(np.maximum(offsets, -1.0), 1.0) + 1.0) * (0.5 * (n_grid - 1))
    lo = np.minimum(u.astype(np.intp), n_grid - 2)
    w = u - lo
    p = np.arange(n_params)[:, None]
    j = np.arange(tables.shape[3])[None, :]
    rows = tables[:, :, k]  # (P, GRID, n)
    value = (1.0 - w) * rows[p, lo, j] + w * rows[p, lo + 1, j]
    return value.sum(axis=0)


def keyframe_change(tables: np.ndarray, keyframe: float, offsets: np.ndarray) -> np.ndarray:
    """:func:`interpolate_offsets` at a fractional ``keyframe``: linear between the two keyframes
    around it (the gait's phase between table rows when the cadence is modulated)."""
    k, steps = int(keyframe), tables.shape[2]
    frac = keyframe - k
    change = interpolate_offsets(tables, k, offsets)
    if frac != 0.0:
        nxt = interpolate_offsets(tables, (k + 1) % steps, offsets)
        change = (1.0 - frac) * change + frac * nxt
    return change


def _bounds(key: str, value: float, base: Mapping[str, Any]) -> tuple[float, float]:
    """Where an offset parameter stops: inside the range where the gait is defined (ACLGait:
    amplitudes >= 0, the radial one below the radius) with a margin, so that an offset never
    makes the gait raise. The radius keeps at least half its base value."""
    radius = float(base.get("radius", np.inf))
    if key == "radius":
        radial = float(base.get("amp_radial", 0.0))
        return min(value, max(0.5 * value, 1.05 * radial + 1e-4)), np.inf
    if key == "amp_radial":
        return 0.0, max(value, 0.95 * radius)
    return 0.0, np.inf


def _default(gait_class: type[Gait], key: str) -> float:
    parameter = inspect.signature(gait_class).parameters.get(key)
    if parameter is None:
        raise ValueError(f"gait_modulation: {gait_class.__name__} has no parameter {key!r}")
    return float(parameter.default)
