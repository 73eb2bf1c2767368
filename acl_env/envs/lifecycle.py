"""The env's lifecycle as Gymnasium users expect it: reset before step, nothing after close.

:class:`LifecycleMixin`, listed first among the env's bases, guards ``reset``, ``step`` (through
:meth:`LifecycleMixin._checked_action`), ``render`` and ``close``:

- ``step()`` or ``render()`` before the first ``reset()`` raises :class:`ResetNeeded`;
- ``reset()``, ``step()`` or ``render()`` after ``close()`` raises :class:`EnvClosed`; a second
  ``close()`` does nothing;
- ``reset(seed=...)`` takes ``None`` or an integer >= 0 (a NumPy one too; never a bool): another
  kind is a ``TypeError``, a negative one a ``ValueError``, both naming ``seed``; ``options`` is
  ``None`` or a dict (the env reads no option);
- an action is an array (or nested list) of real numbers of the action space's shape: another
  dtype (bool, complex, object, strings) or a ragged list is a ``TypeError``, a wrong shape or a
  NaN/inf a ``ValueError``, all naming ``action``; values outside [-1, 1] are clipped;
- ``render()`` with ``render_mode=None`` warns and returns ``None`` (Gymnasium's convention);
- ``render_mode="human"`` needs a window: without one (:func:`no_display_reason`) the env refuses
  it at construction and at every render with a ``ValueError`` naming ``DISPLAY`` and
  ``MUJOCO_GL``, before GLFW is touched (GLFW aborts the whole process instead of raising).

Stepping on after an episode ended (``terminated`` or ``truncated``) is allowed, as in
Gymnasium's MuJoCo envs: the physics continues and the flags stay set; reset to start anew.
Both error classes are ``RuntimeError``s as well as Gymnasium's own (``ResetNeeded``,
``ClosedEnvironmentError``), so either ``except`` catches them.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from numbers import Integral
from typing import Any

import gymnasium
import numpy as np

from acl_env.validation import shown

# Instance attributes; the class defaults describe a fresh env. The closed flag stays out of a
# copy (envs/pickling.py): a copy is a new env with its own simulation and renderer.
RESET_FLAG, CLOSED_FLAG = "_lifecycle_reset", "_lifecycle_closed"


class ResetNeeded(gymnasium.error.ResetNeeded, RuntimeError):
    """``step()`` or ``render()`` called before ``reset()``."""


class EnvClosed(gymnasium.error.ClosedEnvironmentError, RuntimeError):
    """A call on an env after its ``close()``."""


def no_display_reason(environ: Mapping[str, str] | None = None, platform: str | None = None) -> str:
    """Why MuJoCo's interactive viewer cannot open here, or ``""`` when it may: ``MUJOCO_GL``
    set to an offscreen backend (``egl``, ``osmesa``) rules windows out anywhere; on Linux a
    display server must be named by ``DISPLAY`` (X11) or ``WAYLAND_DISPLAY``."""
    environ = os.environ if environ is None else environ
    platform = sys.platform if platform is None else platform
    backend = environ.get("MUJOCO_GL", "").strip().lower()
    if backend in ("egl", "osmesa"):
        return f"MUJOCO_GL={backend} selects offscreen rendering, which has no window"
    if platform.startswith("linux") and not (
        environ.get("DISPLAY") or environ.get("WAYLAND_DISPLAY")
    ):
        return "no display: neither DISPLAY nor WAYLAND_DISPLAY is set"
    return ""


def check_display(render_mode: object) -> None:
    """Refuse ``render_mode="human"`` where no window can open, naming the variables to set."""
    reason = no_display_reason() if render_mode == "human" else ""
    if reason:
        raise ValueError(
            f"render_mode='human' needs a window, and here {reason}. Set DISPLAY (or "
            "WAYLAND_DISPLAY) to a display server and leave MUJOCO_GL unset or 'glfw', or render "
            "offscreen with render_mode='rgb_array' (MUJOCO_GL=egl, or osmesa without a GPU)"
        )


def check_seed(seed: object) -> int | None:
    """``seed`` for ``reset``: ``None`` or an integer >= 0 (as a Python ``int``)."""
    if seed is None:
        return None
    if isinstance(seed, bool | np.bool_) or not isinstance(seed, Integral):
        raise TypeError(
            f"seed must be None or an int >= 0, got {shown(seed)} ({type(seed).__name__})"
        )
    if seed < 0:
        raise ValueError(f"seed must be None or an int >= 0, got {shown(seed)}")
    return int(seed)


def check_action(action: object, shape: tuple[int, ...]) -> np.ndarray:
    """``action`` as a float64 array of ``shape``, every entry finite (not yet clipped)."""
    try:
        array = np.asarray(action)
    except (TypeError, ValueError):  # a ragged list, an object NumPy cannot make an array of
        raise TypeError(f"action must be {_real_array(shape)}, got {shown(action)}") from None
    if array.dtype.kind not in "iuf":
        raise TypeError(
            f"action must be {_real_array(shape)}, got dtype {array.dtype}: {shown(action)}"
        )
    if array.shape != shape:
        raise ValueError(f"action must have shape {shape}, got {array.shape}")
    array = np.asarray(array, dtype=np.float64)
    if not np.isfinite(array).all():
        raise ValueError(f"action must be finite, got {array}")
    return array


def _real_array(shape: tuple[int, ...]) -> str:
    """What an action must be, for the error messages (built only when one is raised: ``step``
    checks every action)."""
    return f"an array of real numbers of shape {shape}"


class LifecycleMixin:
    """Guards of ``reset``/``step``/``render``/``close`` (the module's rules), for a
    ``MujocoEnv``: list it first, ``class Env(LifecycleMixin, ..., MujocoEnv, EzPickle)``, and
    start ``step`` with ``action = self._checked_action(action)``."""

    _lifecycle_reset: bool = False
    _lifecycle_closed: bool = False
    render_mode: str | None
    action_space: gymnasium.spaces.Box

    def _check_open(self, call: str) -> None:
        if self._lifecycle_closed:
            raise EnvClosed(f"{call}() after close(): this env is closed; make a new one")

    def _checked_action(self, action: object) -> np.ndarray:
        """The lifecycle checks of ``step``, then the action checked (:func:`check_action`)."""
        self._check_open("step")
        if not self._lifecycle_reset:
            raise ResetNeeded("step() before reset(): call env.reset() to start an episode")
        return check_action(action, self.action_space.shape)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        self._check_open("reset")
        seed = check_seed(seed)
        if options is not None and not isinstance(options, Mapping):
            raise TypeError(f"options must be None or a dict, got {shown(options)}")
        self._lifecycle_reset = True  # a "human" reset renders its first frame
        try:
            return super().reset(seed=seed, options=options)  # type: ignore[misc]
        except BaseException:
            self._lifecycle_reset = False
            raise

    def render(self) -> Any:
        self._check_open("render")
        if not self._lifecycle_reset:
            raise ResetNeeded("render() before reset(): call env.reset() first")
        if self.render_mode is None:
            gymnasium.logger.warn(
                "render() with render_mode=None renders nothing: pass render_mode to the env"
            )
            return None
        check_display(self.render_mode)
        return super().render()  # type: ignore[misc]

    def close(self) -> None:
        if self._lifecycle_closed:
            return
        self._lifecycle_closed = True
        super().close()  # type: ignore[misc]


__all__ = [
    "CLOSED_FLAG",
    "RESET_FLAG",
    "EnvClosed",
    "LifecycleMixin",
    "ResetNeeded",
    "check_action",
    "check_display",
    "check_seed",
    "no_display_reason",
]
