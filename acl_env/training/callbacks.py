"""Stable-Baselines3 callbacks of the trainer; the zoo can name them in ``ppo.yml``::

    callback: acl_env.training.callbacks.InfoTermsCallback

- :class:`InfoTermsCallback` logs the env's reward terms and climbing charts to TensorBoard.
- :class:`SafeStopCallback` makes an interrupted run save exactly what was trained: it snapshots
  the step count and VecNormalize statistics when a rollout starts (right after the previous
  gradient update completed) and stops a rollout at its next step once a stop is requested; the
  trainer then rolls back to that snapshot. The policy only changes inside ``train()``, which a
  stop never cuts: the trainer's signal handler only sets a flag.
- :class:`RolloutCheckpointCallback` saves checkpoints at the same consistent points.
- :class:`TimingCallback` measures where the wall time goes (rollouts, updates).
"""

from __future__ import annotations

import copy
import time
from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.running_mean_std import RunningMeanStd

from acl_env.training.config import import_dotted


class InfoTermsCallback(BaseCallback):
    """Log per-step means of the env's ``info`` terms once per rollout, and episode climb.

    ``reward/<term>`` for every ``info["reward_<term>"]``; ``charts/climb``, ``charts/slip`` and
    ``charts/energy`` per step; ``charts/episode_climb`` and ``charts/falls`` per finished episode.
    """

    def __init__(self, verbose: int = 0) -> None:
        super().__init__(verbose)
        self._sums: dict[str, float] = defaultdict(float)
        self._count = 0
        self._episode_climb: np.ndarray | None = None
        self._finished_climbs: list[float] = []
        self._falls = 0

    def _on_training_start(self) -> None:
        self._episode_climb = np.zeros(self.training_env.num_envs)

    def _on_step(self) -> bool:
        assert self._episode_climb is not None
        infos, dones = self.locals["infos"], self.locals["dones"]
        for i, (info, done) in enumerate(zip(infos, dones, strict=True)):
            for key, value in info.items():
                if key.startswith("reward_"):
                    self._sums[f"reward/{key.removeprefix('reward_')}"] += float(value)
                elif key in ("climb", "slip", "energy"):
                    self._sums[f"charts/{key}"] += float(value)
            self._episode_climb[i] += float(info.get("climb", 0.0))
            if done:
                self._finished_climbs.append(float(self._episode_climb[i]))
                self._falls += int(bool(info.get("fell", False)))
                self._episode_climb[i] = 0.0
        self._count += len(infos)
        return True

    def _on_rollout_end(self) -> None:
        for key, total in self._sums.items():
            self.logger.record(key, total / max(self._count, 1))
        if self._finished_climbs:
            self.logger.record("charts/episode_climb", float(np.mean(self._finished_climbs)))
            self.logger.record("charts/falls", self._falls)
        self._sums.clear()
        self._count = 0
        self._finished_climbs.clear()
        self._falls = 0


@dataclass
class Snapshot:
    """What a rollout changes before its update: the step count and the normaliser statistics."""

    num_timesteps: int
    obs_rms: RunningMeanStd | dict[str, RunningMeanStd] | None
    ret_rms: RunningMeanStd | None


class SafeStopCallback(BaseCallback):
    """Stop training at a step where the model is consistent, and know how to roll back to it.

    :meth:`request_stop` (called from a signal handler) only sets a flag. The next rollout step
    returns False, which ends ``learn()``; the gradient update in progress, if any, completes
    first. :meth:`rollback` then restores the step count and VecNormalize statistics of the
    rollout's start, which belong to the last completed update.
    """

    def __init__(self, verbose: int = 0) -> None:
        super().__init__(verbose)
        self.stop_signal: int | None = None
        self.stopped_early = False  # True once a rollout was cut short
        self.training_ended = False  # True once learn() left its loop (stopped or done)
        self.snapshot: Snapshot | None = None

    def request_stop(self, signum: int) -> None:
        """Ask training to stop at the next consistent point (the first signal is the cause)."""
        if self.stop_signal is None:
            self.stop_signal = signum

    def _on_training_start(self) -> None:
        self._take_snapshot()

    def _on_rollout_start(self) -> None:
        self._take_snapshot()

    def _take_snapshot(self) -> None:
        vec_normalize = self.model.get_vec_normalize_env()
        self.snapshot = Snapshot(
            num_timesteps=self.model.num_timesteps,
            obs_rms=copy.deepcopy(vec_normalize.obs_rms) if vec_normalize is not None else None,
            ret_rms=copy.deepcopy(vec_normalize.ret_rms) if vec_normalize is not None else None,
        )

    def _on_step(self) -> bool:
        if self.stop_signal is not None:
            self.stopped_early = True
            return False
        return True

    def _on_training_end(self) -> None:
        self.training_ended = True

    def rollback(self) -> int:
        """Restore the last snapshot; return how many env steps were discarded (none before
        training started)."""
        if self.snapshot is None:
            return 0
        discarded = self.model.num_timesteps - self.snapshot.num_timesteps
        self.model.num_timesteps = self.snapshot.num_timesteps
        vec_normalize = self.model.get_vec_normalize_env()
        if vec_normalize is not None:
            vec_normalize.obs_rms = copy.deepcopy(self.snapshot.obs_rms)
            vec_normalize.ret_rms = copy.deepcopy(self.snapshot.ret_rms)
        return discarded


class RolloutCheckpointCallback(BaseCallback):
    """Call ``save(num_timesteps)`` when a rollout starts and ``num_timesteps`` has crossed a
    multiple of ``save_freq`` env steps since the last save: every checkpoint holds the weights,
    statistics and step count of one completed update (SB3's CheckpointCallback saves mid-rollout).
    """

    def __init__(self, save_freq: int, save: Callable[[int], None], verbose: int = 0) -> None:
        super().__init__(verbose)
        if save_freq < 1:
            raise ValueError(f"save_freq must be >= 1 env step, got {save_freq}")
        self.save_freq = save_freq
        self._save = save
        self._last_bucket: int | None = None

    def _on_training_start(self) -> None:
        self._last_bucket = self.model.num_timesteps // self.save_freq

    def _on_rollout_start(self) -> None:
        bucket = self.model.num_timesteps // self.save_freq
        if self._last_bucket is not None and bucket > self._last_bucket:
            self._save(self.model.num_timesteps)
        self._last_bucket = bucket

    def _on_step(self) -> bool:
        return True


class TimingCallback(BaseCallback):
    """Wall time of rollouts (stepping, inference, buffer) and of everything between them
    (gradient update, logging, checkpoints), per segment."""

    def __init__(self, verbose: int = 0) -> None:
        super().__init__(verbose)
        self.rollout_s = 0.0
        self.between_s = 0.0
        self._rollout_start: float | None = None
        self._rollout_end: float | None = None

    @staticmethod
    def _since(start: float | None, now: float) -> float:
        """Seconds from ``start`` to ``now``; 0 when nothing was started."""
        return 0.0 if start is None else now - start

    def _on_rollout_start(self) -> None:
        now = time.perf_counter()
        self.between_s += self._since(self._rollout_end, now)
        self._rollout_start, self._rollout_end = now, None

    def _on_step(self) -> bool:
        return True

    def _on_rollout_end(self) -> None:
        now = time.perf_counter()
        self.rollout_s += self._since(self._rollout_start, now)
        self._rollout_start, self._rollout_end = None, now

    def _on_training_end(self) -> None:
        now = time.perf_counter()
        self.rollout_s += self._since(self._rollout_start, now)  # stopped inside a rollout
        self.between_s += self._since(self._rollout_end, now)
        self._rollout_start = self._rollout_end = None


def callbacks_from_config(value: Any) -> list[BaseCallback]:
    """Instantiate the zoo-style ``callback`` entry of a config: a dotted class path, a
    ``{path: kwargs}`` mapping, or a list of those (as ``rl_zoo3.utils.get_callback_list``)."""
    if value is None:
        return []
    callbacks = []
    for item in value if isinstance(value, list) else [value]:
        name, kwargs = next(iter(item.items())) if isinstance(item, dict) else (item, {})
        callbacks.append(import_dotted(name)(**(kwargs or {})))
    return callbacks


class CriticWarmupCallback(BaseCallback):
    """Train only the critic for the first ``steps`` env steps: the actor's gradients are zeroed.

    A residual policy starts as the open-loop gait (zero mean action). Its first PPO updates
    would otherwise follow advantages from an untrained value function; here the critic first
    learns the value of the gait played with the initial exploration noise. With zero gradients
    from the start, Adam's moments of the actor stay zero and its weights (and ``log_std``) do not
    move at all, so the KL of those updates is 0 and PPO's early stop never cuts the critic's
    epochs. From ``steps`` on, training is plain PPO. Name it in a config as
    ``{acl_env.training.callbacks.CriticWarmupCallback: {steps: 100000}}``.
    """

    def __init__(self, steps: int, verbose: int = 0) -> None:
        super().__init__(verbose)
        if int(steps) < 1:
            raise ValueError(f"CriticWarmupCallback: steps must be >= 1 env step, got {steps}")
        self.steps = int(steps)
        self._handles: list[Any] = []

    def actor_parameters(self) -> list[Any]:
        """The parameters only the actor uses: its MLP branch, action head and ``log_std``."""
        policy = self.model.policy
        if not policy.share_features_extractor or list(policy.features_extractor.parameters()):
            raise ValueError("CriticWarmupCallback: the features extractor must have no weights")
        params = [*policy.mlp_extractor.policy_net.parameters(), *policy.action_net.parameters()]
        return [*params, policy.log_std]

    @property
    def warming(self) -> bool:
        """Whether the update about to run is a critic-only one."""
        return self.model.num_timesteps <= self.steps

    def _mask(self, grad: Any) -> Any:
        return grad.mul(0.0) if self.warming else grad

    def _on_training_start(self) -> None:
        self._handles = [p.register_hook(self._mask) for p in self.actor_parameters()]

    def _on_rollout_end(self) -> None:
        self.logger.record("train/critic_warmup", int(self.warming))

    def _on_step(self) -> bool:
        return True

    def _on_training_end(self) -> None:
        for handle in self._handles:
            handle.remove()
        self._handles = []
