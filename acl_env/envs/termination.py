"""When a climbing episode ends early: the snake fell, the physics became unstable, or (with a
``roll_limit``) the body rolled on the pole."""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from acl_env.constants import link_name, shell_name
from acl_env.gait.kinematics import link_roll_angles


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
    or no shell touched the pole during the step. A plain ``bool`` (the contact flags may be
    NumPy's, which ``json`` refuses)."""
    return bool(com_height < com_start - fall_distance or touched_floor or not touched_pole)


class BodyRoll:
    """Each module's roll about its own axis relative to the pole surface, read from MuJoCo.

    The angle of :func:`acl_env.gait.kinematics.link_roll_angles` (the gait's roll diagnostic),
    from the links' simulated frames (``xmat``) and shell centres (``geom_xpos``): what the body
    does, not what the gait commands. Holds views of the data's buffers, made once.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, n_modules: int) -> None:
        self._bodies = _span([model.body(link_name(k)).id for k in range(n_modules)])
        self._shells = _span([model.geom(shell_name(k)).id for k in range(n_modules)])
        self._xmat, self._geom_xpos = data.xmat, data.geom_xpos

    def angles(self) -> np.ndarray:
        """Roll of every module (head first), rad in ``(-pi, pi]``."""
        frames = self._xmat[self._bodies].reshape(-1, 3, 3)
        return link_roll_angles(frames, self._geom_xpos[self._shells])


def _span(ids: list[int]) -> slice | np.ndarray:
    """Consecutive ids (the builder numbers the modules so) as a slice, whose rows a view reads
    without copying; any others as an index array."""
    if ids == list(range(ids[0], ids[0] + len(ids))):
        return slice(ids[0], ids[0] + len(ids))
    return np.array(ids)


@dataclass
class RollSpan:
    """Per module, the roll unwrapped since the episode started and the range it swept (rad).

    Plain arrays (no MuJoCo views), so a copy of the env carries them. Sampled once per env step:
    unwrapping needs less than half a turn per step (a rolling gait turns ~1.6 deg per step).
    """

    start: np.ndarray
    unwrapped: np.ndarray
    low: np.ndarray
    high: np.ndarray

    @classmethod
    def begin(cls, angles: np.ndarray) -> RollSpan:
        return cls(angles.copy(), angles.copy(), angles.copy(), angles.copy())

    def update(self, angles: np.ndarray) -> float:
        """Add a sample; return the growth of the mean span over modules (rad, >= 0)."""
        # sum / n: np.mean's own arithmetic, without its per-call overhead
        n = len(self.high)
        before = float((self.high - self.low).sum()) / n
        step = (angles - self.unwrapped + np.pi) % (2.0 * np.pi) - np.pi
        self.unwrapped += step
        np.minimum(self.low, self.unwrapped, out=self.low)
        np.maximum(self.high, self.unwrapped, out=self.high)
        return float((self.high - self.low).sum()) / n - before

    @property
    def span_deg(self) -> np.ndarray:
        """Each module's swept roll range (max - min since the start), degrees."""
        return np.degrees(self.high - self.low)

    @property
    def body_rolls(self) -> float:
        """Net turns of the body about its own axis since the start (mean over modules)."""
        return float((self.unwrapped - self.start).sum() / len(self.start) / (2.0 * np.pi))


def rolled(span_deg: float, roll_limit: float | None) -> bool:
    """A module's swept roll range exceeds ``roll_limit`` degrees (never when it is None)."""
    return bool(roll_limit is not None and span_deg > roll_limit)
