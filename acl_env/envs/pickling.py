"""Copies of a MuJoCo env mid-episode: ``pickle`` and ``copy.deepcopy`` continue exactly where the
original was.

A Gymnasium ``MujocoEnv`` holds MuJoCo memory (its model, data, renderer and array views into
them), which a copy must not duplicate: the views would point into the pickled duplicates instead
of the copy's own simulation. The copy is therefore a fresh env built from the constructor's
arguments (``EzPickle``), given the original's episode state (every attribute that holds no MuJoCo
memory) and the original's simulation copied into its own model and data.
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
from gymnasium.utils import EzPickle

from acl_env.envs.lifecycle import CLOSED_FLAG

# Not in a copy's episode state: the simulation travels as MjData (with its model), the renderer
# is the fresh env's, the constructor's arguments are EzPickle's; a copy of a closed env is open
# (its own simulation and renderer, envs/lifecycle.py).
NOT_COPIED = (
    "model",
    "data",
    "mujoco_renderer",
    "_ezpickle_args",
    "_ezpickle_kwargs",
    CLOSED_FLAG,
)


class MujocoPickleMixin:
    """``__getstate__``/``__setstate__`` for a ``MujocoEnv`` that is also an ``EzPickle``: list it
    before both, ``class Env(MujocoPickleMixin, MujocoEnv, EzPickle)``."""

    model: mujoco.MjModel
    data: mujoco.MjData

    def __getstate__(self) -> dict[str, Any]:
        """The constructor's arguments (EzPickle) plus the episode: the simulation data and the
        model as this episode left it (randomisation included), and the env's counters and RNG.

        A copy taken mid-episode (pickle, ``copy.deepcopy``) continues exactly where the original
        was: the same actions give the same observations, rewards, infos and later resets.
        """
        episode = {
            k: v for k, v in self.__dict__.items() if k not in NOT_COPIED and not mujoco_owned(v)
        }
        return {**EzPickle.__getstate__(self), "episode": episode, "data": self.data}

    def __setstate__(self, state: dict[str, Any]) -> None:
        state = dict(state)
        episode, data = state.pop("episode", None), state.pop("data", None)
        EzPickle.__setstate__(self, state)  # a fresh env from the constructor's arguments
        if episode is None or data is None:
            return
        self.__dict__.update(episode)
        # Copied into the fresh env's own model and data, so that its views into them (and its
        # renderer's) stay valid. MjData pickles with its model.
        copy_model(self.model, data.model)
        mujoco.mj_copyData(self.data, self.model, data)


def mujoco_owned(value: object, depth: int = 2) -> bool:
    """Whether ``value`` is or holds (``depth`` levels down its attributes) MuJoCo memory: an
    MjModel, an MjData, a struct or an array view of them. A copy keeps the fresh env's own such
    objects, bound to its own model and data, instead of pickled duplicates."""
    if type(value).__module__.startswith("mujoco"):
        return True
    if isinstance(value, np.ndarray):
        while isinstance(value, np.ndarray):
            value = value.base
        return value is not None  # a view whose memory MuJoCo owns
    if depth == 0 or isinstance(value, str | bytes | int | float | np.random.Generator):
        return False
    children = getattr(value, "__dict__", {}).values()
    if isinstance(value, dict):
        children = value.values()
    elif isinstance(value, list | tuple):
        children = value
    return any(mujoco_owned(child, depth - 1) for child in children)


def copy_model(dest: mujoco.MjModel, src: mujoco.MjModel) -> None:
    """Every array and physics option of ``src`` into ``dest``, a model of the same structure
    (MuJoCo has ``mj_copyData`` but no in-place model copy)."""
    for name in dir(src):
        value = getattr(src, name)
        if isinstance(value, np.ndarray) and not name.startswith("_"):
            getattr(dest, name)[...] = value
    for name in dir(src.opt):
        if not name.startswith("_"):
            value = getattr(src.opt, name)
            if isinstance(value, np.ndarray):
                getattr(dest.opt, name)[...] = value
            else:
                setattr(dest.opt, name, value)


__all__ = ["NOT_COPIED", "MujocoPickleMixin", "copy_model", "mujoco_owned"]
