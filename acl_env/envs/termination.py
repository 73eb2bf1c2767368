"""When a climbing episode ends early: the snake fell, or the physics became unstable."""

from __future__ import annotations

import math

import mujoco


def warning_count(data: mujoco.MjData) -> int:
    """All MuJoCo warnings raised so far on ``data``."""
    return int(data.warning.number.sum())


class Stability:
    """Watches one ``MjData`` over a step: unstable when MuJoCo raised a warning, reset the
    diverged state (its time went back), or left a non-finite state.

    Holds views of the data's buffers, made once: the check runs on every env step.
    """

    def __init__(self, data: mujoco.MjData) -> None:
        self._data = data
        self._warnings = data.warning.number
        self._qpos, self._qvel = data.qpos, data.qvel
        self._before = (0, 0.0)

    def start(self) -> None:
        """Remember the warning count and time before the step."""
        self._before = (int(self._warnings.sum()), self._data.time)

    def unstable(self) -> bool:
        """Whether the physics became unstable since :meth:`start`."""
        warnings, time = self._before
        if int(self._warnings.sum()) > warnings or self._data.time <= time:
            return True
        # MuJoCo resets values beyond 1e10, so these sums are finite iff every entry is.
        return not math.isfinite(float(self._qpos.sum()) + float(self._qvel.sum()))


def fell(
    com_height: float,
    com_start: float,
    fall_distance: float,
    touched_pole: bool,
    touched_floor: bool,
) -> bool:
    """The centre of mass dropped ``fall_distance`` below its start, a shell touched the floor,
    or no shell touched the pole during the step."""
    return com_height < com_start - fall_distance or touched_floor or not touched_pole
