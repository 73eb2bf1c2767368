"""The evaluation protocol: roll out a controller and measure each episode.

Numpy and Gymnasium only, like Stable-Baselines3's ``common/evaluation.py``: a *policy* here is any
callable from observation to action (a trained network is wrapped by
:func:`acl_env.training.policy.load_policy`). One rollout function, :func:`run_episode`, serves
``acl-evaluate``, the benchmarks, ``python -m acl_env`` and the paper tables; it takes a
per-step hook for what a caller wants beyond the metrics (frames, joint angles, contacts).

Per-episode metrics (the JSON names are an interface: other tools read them), with ``climb`` and
``slip`` the sums of ``info["climb"]`` and ``info["slip"]``, ``cycles = steps / steps_per_cycle``
(nominal) and ``gait_cycles = sum(info["phase_rate"]) / steps_per_cycle`` (executed):

| name | definition |
|---|---|
| ``climb_per_cycle_m`` | climb / cycles |
| ``climb_per_gait_cycle_m`` | climb / gait_cycles |
| ``climb_speed_cm_s`` | 100 climb / (steps dt) |
| ``slip_per_cycle_m`` | slip / cycles |
| ``slip_per_m`` | slip / climb (undefined for climb <= 0) |
| ``energy_per_m`` | sum of ``info["energy"]`` / climb, J/m (undefined for climb <= 0) |
| ``mean_abs_torque_nm`` | mean of abs(actuator force) over joints and steps (end of each step) |
| ``torque_limit_fraction`` | share of those joint-steps at the actuator's force limit |
| ``touched_arc_deg`` | largest arc of any module's circumference that touched the pole |
| ``reward_per_gait_cycle`` | env reward summed over the episode / gait_cycles |
| ``falls`` | 1 if the episode ended with ``info["fell"]`` |
| ``action_change`` | mean over steps 2.. of mean abs(a_t - a_{t-1}) over the action's entries |

``action_change`` tells a residual smooth over the gait cycle (near 0; an open loop reads 0) from
one that flips at the control rate (flipping between the ends of the range reads 2), which can
climb on the soft contact's creep (``experiments/noroll_climb_gait/action_smoothing.py``).

``touched_arc_deg`` is defined in :mod:`acl_env.evaluation.contacts`. Around this module: the
95 % intervals (:mod:`~acl_env.evaluation.intervals`), the summary over episodes and the paired
differences (:mod:`~acl_env.evaluation.summary`), the tables (:mod:`~acl_env.evaluation.tables`)
and the open-loop controllers (:mod:`~acl_env.evaluation.open_loop`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import gymnasium
import numpy as np

from acl_env.evaluation.contacts import ARC_BINS, PoleContacts, arc_bins, covering_arc_deg

METRICS = (
    "climb_per_cycle_m",
    "climb_per_gait_cycle_m",
    "climb_speed_cm_s",
    "slip_per_cycle_m",
    "slip_per_m",
    "energy_per_m",
    "mean_abs_torque_nm",
    "torque_limit_fraction",
    "touched_arc_deg",
    "reward_per_gait_cycle",
    "falls",
    "action_change",
)

Policy = Callable[[np.ndarray], np.ndarray]
# Called after reset (action None, the reset info) and after every step.
StepCallback = Callable[[gymnasium.Env, np.ndarray, "np.ndarray | None", dict[str, Any]], None]


@dataclass
class Episode:
    """Sums over one episode, with what the metrics need beyond ``info``."""

    seed: int
    steps: int = 0
    climb: float = 0.0
    slip: float = 0.0
    energy: float = 0.0
    reward: float = 0.0
    keyframes: float = 0.0  # sum of info["phase_rate"]: gait keyframes advanced
    fell: bool = False
    unstable: bool = False
    rolled: bool = False  # ended by the env's roll_limit (the non-rolling task)
    dt: float = math.nan
    steps_per_cycle: int = 0
    abs_torque_sum: float = 0.0
    joint_steps: int = 0
    limit_joint_steps: int = 0
    action_change_sum: float = 0.0  # sum over steps 2.. of mean abs(a_t - a_{t-1})
    touched_bins: np.ndarray = field(default_factory=lambda: np.zeros((0, ARC_BINS), dtype=bool))
    com_height: np.ndarray = field(default_factory=lambda: np.zeros(0))  # after reset, each step

    @property
    def touched_arcs_deg(self) -> np.ndarray:
        """Each module's touched arc (degrees), head first."""
        return covering_arc_deg(self.touched_bins)

    @property
    def mean_phase_rate(self) -> float:
        """Gait keyframes advanced per step."""
        return self.keyframes / self.steps if self.steps else math.nan

    def metrics(self) -> dict[str, float]:
        """The per-episode values of :data:`METRICS` (NaN where undefined)."""
        cycles = self.steps / self.steps_per_cycle
        gait_cycles = self.keyframes / self.steps_per_cycle

        def per(value: float, amount: float) -> float:
            return value / amount if amount > 0.0 else math.nan

        return {
            "climb_per_cycle_m": per(self.climb, cycles),
            "climb_per_gait_cycle_m": per(self.climb, gait_cycles),
            "climb_speed_cm_s": per(100.0 * self.climb, self.steps * self.dt),
            "slip_per_cycle_m": per(self.slip, cycles),
            "slip_per_m": per(self.slip, self.climb),
            "energy_per_m": per(self.energy, self.climb),
            "mean_abs_torque_nm": per(self.abs_torque_sum, self.joint_steps),
            "torque_limit_fraction": per(self.limit_joint_steps, self.joint_steps),
            "touched_arc_deg": float(self.touched_arcs_deg.max(initial=0.0)),
            "reward_per_gait_cycle": per(self.reward, gait_cycles),
            "falls": float(self.fell),
            "action_change": per(self.action_change_sum, self.steps - 1),
        }


def steps_per_cycle(env: gymnasium.Env) -> int:
    """Env steps per nominal gait cycle (the env's ``steps_per_cycle``)."""
    value = getattr(env.unwrapped, "steps_per_cycle", None)
    if value is None and env.spec is not None:
        value = env.spec.kwargs.get("steps_per_cycle")
    if value is None:
        raise AttributeError(f"{env.spec.id if env.spec else env} does not expose steps_per_cycle")
    return int(value)


def run_episode(
    env: gymnasium.Env,
    policy: Policy,
    seed: int,
    callback: StepCallback | None = None,
    max_steps: int | None = None,
) -> Episode:
    """Roll out one episode of ``policy`` from ``env.reset(seed=seed)`` and measure it.

    ``callback(env, obs, action, info)`` runs after the reset (``action`` None) and after every
    step. ``max_steps`` stops early (the episode is then measured over the steps it ran).
    """
    base = env.unwrapped
    obs, info = env.reset(seed=seed)
    contacts = PoleContacts(env)
    limit = np.abs(base.model.actuator_forcerange[:, 1]).copy()
    limit[base.model.actuator_forcelimited == 0] = np.inf  # an unlimited actuator never saturates
    episode = Episode(seed=seed, dt=float(base.dt), steps_per_cycle=steps_per_cycle(env))
    episode.touched_bins = np.zeros((contacts.n_modules, ARC_BINS), dtype=bool)
    heights = [float(info.get("com_height", math.nan))]
    if callback is not None:
        callback(env, obs, None, info)
    terminated = truncated = False
    last: np.ndarray | None = None
    while not (terminated or truncated) and (max_steps is None or episode.steps < max_steps):
        action = policy(obs)
        played = np.array(action, dtype=float)  # a copy: a policy may reuse its array
        if last is not None:
            episode.action_change_sum += float(np.abs(played - last).mean())
        last = played
        obs, reward, terminated, truncated, info = env.step(action)
        episode.steps += 1
        episode.reward += float(reward)
        episode.climb += float(info["climb"])
        episode.slip += float(info["slip"])
        episode.energy += float(info["energy"])
        episode.keyframes += float(info.get("phase_rate", 1.0))
        torque = np.abs(base.data.actuator_force)
        episode.abs_torque_sum += float(torque.sum())
        episode.joint_steps += torque.size
        episode.limit_joint_steps += int(np.count_nonzero(torque >= limit - 1e-9))
        module, local, _ = contacts()
        episode.touched_bins[module, arc_bins(local)] = True
        heights.append(float(info.get("com_height", math.nan)))
        if callback is not None:
            callback(env, obs, action, info)
    episode.fell = bool(terminated and info.get("fell", False))
    episode.unstable = bool(terminated and info.get("unstable", False))
    episode.rolled = bool(terminated and info.get("rolled", False))
    episode.com_height = np.asarray(heights)
    return episode


def action_recorder() -> tuple[list[np.ndarray], StepCallback]:
    """A list and a :func:`run_episode` callback that appends each action played (a copy)."""
    actions: list[np.ndarray] = []

    def record(env: gymnasium.Env, obs: np.ndarray, action: Any, info: dict[str, Any]) -> None:
        if action is not None:
            actions.append(np.array(action, dtype=float))

    return actions, record
