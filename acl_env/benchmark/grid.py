"""The condition grid of each task, as data: the axes a robot cannot choose (pole radius, skin
friction, spring or servo stiffness, command latency), the values each takes, and which of them
the shipped recipe's domain randomisation trains on.

The design is full factorial over every two axes at a time, the others at their nominal values
(the task's defaults): every single change and every pair of changes is a cell, and the cells
where two axes are off-nominal show how their effects combine. A cell is *held out* when any of
its values lies outside the training ranges. A grid may add *events*, cells of their own played at
the nominal condition: the pole turning slippery mid-episode (``friction_step``).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from acl_env import (
    ACL_CLIMB_BENCHMARK_ID,
    ACL_CLIMB_COMPLIANT_ID,
    ACL_CLIMB_COMPLIANT_ROBUST_ID,
    ACL_CLIMB_COMPLIANT_ROBUST_V2_ID,
    ACL_CLIMB_NOROLL_BENCHMARK_ID,
    ACL_CLIMB_NOROLL_COMPLIANT_ID,
    ACL_CLIMB_NOROLL_SEA_ID,
    ACL_CLIMB_ROBUST_ID,
    ACL_CLIMB_ROBUST_V2_ID,
    ACL_CLIMB_ROBUST_V3_ID,
    ACL_CLIMB_SEA_ID,
    current_id,
)
from acl_env.actuators.base import LATENCY_RANGE
from acl_env.actuators.sea import SPRING_STIFFNESS
from acl_env.constants import DEFAULT_FRICTION, DEFAULT_KP, DEFAULT_POLE_RADIUS


@dataclass(frozen=True)
class Axis:
    """One condition: the env keyword argument it sets, its values (the nominal one among
    them), and the range the recipe's domain randomisation draws it from (``None``: fixed at
    the nominal value in training)."""

    name: str
    values: tuple[float, ...]
    nominal: float
    training: tuple[float, float] | None
    unit: str = ""

    def __post_init__(self) -> None:
        if self.nominal not in self.values:
            raise ValueError(f"axis {self.name}: nominal {self.nominal} not among {self.values}")

    def trained(self, value: float) -> bool:
        """Whether training saw ``value`` (inside its randomisation range, or the fixed value)."""
        if self.training is None:
            return value == self.nominal
        low, high = self.training
        return low - 1e-12 <= value <= high + 1e-12


@dataclass(frozen=True)
class Cell:
    """One condition of the grid: the env keyword arguments that set it."""

    kwargs: dict[str, float]
    held_out: bool

    @property
    def key(self) -> str:
        """A stable name, e.g. ``friction=0.4,pole_radius=0.12`` (``nominal`` for none)."""
        return ",".join(f"{k}={v:g}" for k, v in sorted(self.kwargs.items())) or "nominal"


@dataclass(frozen=True)
class Grid:
    """The axes of one task and its cells (pairwise full factorial, :mod:`this module's
    <acl_env.benchmark.grid>` design); ``fixed``: kwargs every cell adds (a test's short
    episodes); ``events``: cells played after the grid's, at the nominal condition; ``only``:
    the keys of the cells to play, when not all (:meth:`select`)."""

    axes: tuple[Axis, ...]
    fixed: Mapping[str, Any] = field(default_factory=dict)
    events: tuple[Cell, ...] = ()
    only: tuple[str, ...] = ()

    def select(self, keys: Sequence[str]) -> Grid:
        """The grid playing only the cells named ``keys`` (:attr:`Cell.key`), in the grid's
        order; ``ValueError`` naming a key that is not a cell of it."""
        known = [cell.key for cell in replace(self, only=()).cells()]
        unknown = [key for key in keys if key not in known]
        if unknown:
            raise ValueError(
                f"no cell {unknown[0]!r} in the grid; its {len(known)} cells are named like "
                f"{', '.join(known[:2])}, {known[-1]}"
            )
        return replace(self, only=tuple(key for key in known if key in keys))

    def axis(self, name: str) -> Axis:
        """The axis of env keyword argument ``name``."""
        return next(a for a in self.axes if a.name == name)

    def cells(self) -> list[Cell]:
        """Every cell with at most two axes off their nominal values, nominal first, each
        once, in a stable order, then the events (those of :attr:`only`, when set)."""
        seen: dict[str, Cell] = {}
        for first, second in itertools.combinations(self.axes, 2):
            for a, b in itertools.product(first.values, second.values):
                changed = {
                    axis.name: value
                    for axis, value in ((first, a), (second, b))
                    if value != axis.nominal
                }
                held_out = any(not self.axis(k).trained(v) for k, v in changed.items())
                cell = Cell(changed, held_out)
                seen.setdefault(cell.key, cell)
        cells = sorted(seen.values(), key=lambda c: (len(c.kwargs), c.key)) + list(self.events)
        return [cell for cell in cells if cell.key in self.only] if self.only else cells

    def env_kwargs(self, cell: Cell) -> dict[str, Any]:
        """The keyword arguments that play ``cell``."""
        return {**self.fixed, **cell.kwargs}


# The recipe's randomisation ranges (acl_env/data/ppo.yml; tests/test_benchmark.py checks them).
TRAINING_POLE = (0.065, 0.09)
TRAINING_FRICTION = (0.7, 1.2)
POLE = Axis("pole_radius", (0.055, 0.075, 0.09, 0.12), DEFAULT_POLE_RADIUS, TRAINING_POLE, "m")
# Two of three off-nominal frictions below the training range: where the grip is tested.
FRICTION = Axis("friction", (0.4, 0.55, 0.7, 1.0), DEFAULT_FRICTION, TRAINING_FRICTION)
# The SEA: springs 0.6x to 1.4x; latency from none to the largest the env accepts (two control
# steps), the default 10 ms nominal.
SPRING = Axis(
    "spring_stiffness",
    (0.6 * SPRING_STIFFNESS, SPRING_STIFFNESS, 1.4 * SPRING_STIFFNESS),
    SPRING_STIFFNESS,
    (16.0, 24.0),
    "N m/rad",
)
LATENCY = Axis("control_latency", (0.0, 0.01, 0.1, LATENCY_RANGE[1]), 0.01, (0.0, 0.05), "s")
SEA_GRID = Grid((POLE, FRICTION, SPRING, LATENCY))
# The pole turning slippery at a random step of the episode (friction 1.0 -> 0.5), which no
# recipe trains on.
FRICTION_STEP = Cell({"friction_step": 0.5}, held_out=True)
# The robust task's recipe trains over the grid but its thickest pole: every other cell is a
# training cell there. Its grid adds the friction step.
ROBUST_SEA_GRID = Grid(
    (
        replace(POLE, training=(0.055, 0.1)),
        replace(FRICTION, training=(0.4, 1.2)),
        replace(SPRING, training=(12.0, 28.0)),
        replace(LATENCY, training=(0.0, 0.2)),
    ),
    events=(FRICTION_STEP,),
)
# The ideal servo has no latency option: its stiffness takes six values instead.
KP = Axis("kp", (10.0, 12.0, 15.0, DEFAULT_KP, 25.0, 30.0), DEFAULT_KP, (15.0, 30.0), "N m/rad")
SERVO_GRID = Grid((POLE, FRICTION, KP))

GRIDS: dict[str, Grid] = {
    ACL_CLIMB_SEA_ID: SEA_GRID,
    ACL_CLIMB_COMPLIANT_ID: SEA_GRID,
    ACL_CLIMB_NOROLL_SEA_ID: SEA_GRID,
    ACL_CLIMB_NOROLL_COMPLIANT_ID: SEA_GRID,
    ACL_CLIMB_ROBUST_ID: ROBUST_SEA_GRID,
    ACL_CLIMB_ROBUST_V2_ID: ROBUST_SEA_GRID,
    ACL_CLIMB_ROBUST_V3_ID: ROBUST_SEA_GRID,
    ACL_CLIMB_COMPLIANT_ROBUST_ID: ROBUST_SEA_GRID,
    ACL_CLIMB_COMPLIANT_ROBUST_V2_ID: ROBUST_SEA_GRID,
    ACL_CLIMB_BENCHMARK_ID: SERVO_GRID,
    ACL_CLIMB_NOROLL_BENCHMARK_ID: SERVO_GRID,
}


def grid_for(env_id: str) -> Grid:
    """The condition grid of task ``env_id``; ``KeyError`` naming the tasks that have one."""
    try:
        return GRIDS[current_id(env_id)]
    except KeyError:
        raise KeyError(
            f"no condition grid for {env_id!r} (tasks with one: {', '.join(GRIDS)})"
        ) from None
