"""When a climbing episode ends early: the snake fell, or the physics became unstable."""

from __future__ import annotations

import mujoco
import numpy as np


def unstable(data: mujoco.MjData, warnings_before: int, time_before: float) -> bool:
    """A MuJoCo warning was raised during the step, MuJoCo reset the diverged state (its time
    went back to 0), or the state is not finite."""
    diverged = warning_count(data) > warnings_before or data.time <= time_before
    finite = bool(np.all(np.isfinite(data.qpos)) and np.all(np.isfinite(data.qvel)))
    return diverged or not finite


def warning_count(data: mujoco.MjData) -> int:
    """All MuJoCo warnings raised so far on ``data``."""
    return int(data.warning.number.sum())


def fell(
    com_height: float,
    com_start: float,
    fall_distance: float,
    touched_pole: bool,
    touched_floor: bool,
) -> bool:
    """The centre of mass dropped ``fall_distance`` below its start, a shell touched the floor,
    or no shell touched the pole during the step."""
    return bool(com_height < com_start - fall_distance or touched_floor or not touched_pole)
