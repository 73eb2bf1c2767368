"""The evaluation protocol: roll out a controller, measure each episode, summarise over episodes.

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

``touched_arc_deg``: after every step, each active snake-pole contact is expressed in the frame of
its module's link (x along the module's axis) and binned by its angle about that axis into
``ARC_BINS`` bins; a module's touched arc is the shortest arc that covers every bin it touched in
the episode (360 minus the largest untouched gap), and the metric is the largest over modules.
360 means no spot on the skin stayed clear of the pole, i.e. no place for a sensor.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import gymnasium
import numpy as np

from acl_env.constants import POLE_GEOM, link_name, shell_name
from acl_env.io import jsonable as jsonable  # re-exported: the one home is acl_env.io

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
ARC_BINS = 36  # 10-degree bins about each module's axis
CI_NOTE = "two-sided 95 % confidence interval of the mean, Student's t distribution"

Policy = Callable[[np.ndarray], np.ndarray]
# Called after reset (action None, the reset info) and after every step.
StepCallback = Callable[[gymnasium.Env, np.ndarray, "np.ndarray | None", dict[str, Any]], None]


# --- statistics ----------------------------------------------------------------------------------


@functools.lru_cache(maxsize=256)
def student_t_quantile(p: float, dof: int) -> float:
    """Quantile of Student's t distribution without SciPy: bisection on the integrated pdf."""
    if not 0.5 <= p < 1.0 or dof < 1:
        raise ValueError("need 0.5 <= p < 1 and dof >= 1")
    log_norm = math.lgamma((dof + 1) / 2) - math.lgamma(dof / 2) - 0.5 * math.log(dof * math.pi)

    def cdf(x: float) -> float:
        t = np.linspace(0.0, x, 4001)
        pdf = np.exp(log_norm - 0.5 * (dof + 1) * np.log1p(t * t / dof))
        return 0.5 + float(np.trapezoid(pdf, t))

    lo, hi = 0.0, 1.0
    while cdf(hi) < p:
        lo, hi = hi, 2.0 * hi
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if cdf(mid) < p else (lo, mid)
    return 0.5 * (lo + hi)


def mean_ci95(values: Iterable[float]) -> dict[str, Any]:
    """Mean and two-sided 95 % confidence interval from the t distribution (NaNs dropped).

    One value has no interval: its half-width is NaN, not 0.
    """
    x = np.asarray([v for v in values if not math.isnan(v)], dtype=float)
    n = len(x)
    if n == 0:
        return {"mean": math.nan, "ci95": [math.nan, math.nan], "half_width": math.nan, "n": 0}
    mean = float(x.mean())
    half = math.nan
    if n > 1:
        half = student_t_quantile(0.975, n - 1) * float(x.std(ddof=1)) / math.sqrt(n)
    return {"mean": mean, "ci95": [mean - half, mean + half], "half_width": half, "n": n}


# --- contacts ------------------------------------------------------------------------------------


class PoleContacts:
    """The active snake-pole contacts of an env's current state, per module.

    ``env`` is any (wrapped) ``ACLClimbEnv``; the ids are looked up once. Calling the object
    returns ``(module, local, world)``: the module index (0 = head) of each contact, the contact
    point in that module's link frame (x along the module's axis) and in the world frame.
    """

    def __init__(self, env: gymnasium.Env) -> None:
        base = env.unwrapped
        self.model, self.data = base.model, base.data
        n_modules = int(base.n_joints) + 1
        self.n_modules = n_modules
        self.pole = self.model.geom(POLE_GEOM).id
        self.module_of_geom = np.full(self.model.ngeom, -1)
        for k in range(n_modules):
            self.module_of_geom[self.model.geom(shell_name(k)).id] = k
        self.bodies = np.array([self.model.body(link_name(k)).id for k in range(n_modules)])

    def __call__(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        data, ncon = self.data, self.data.ncon
        geoms = data.contact.geom[:ncon]
        other = np.where(geoms[:, 0] == self.pole, geoms[:, 1], geoms[:, 0])
        on_pole = (
            (geoms == self.pole).any(axis=1)
            & (self.module_of_geom[other] >= 0)
            & (data.contact.efc_address[:ncon] >= 0)  # excluded contacts exert nothing
        )
        module = self.module_of_geom[other[on_pole]]
        world = data.contact.pos[:ncon][on_pole].copy()
        local = np.einsum("kji,kj->ki", self.rotations(module), world - self.positions(module))
        return module, local, world

    def rotations(self, modules: np.ndarray) -> np.ndarray:
        """World rotation matrices of the modules' link frames, shape ``(len(modules), 3, 3)``."""
        return self.data.xmat[self.bodies[modules]].reshape(-1, 3, 3)

    def positions(self, modules: np.ndarray) -> np.ndarray:
        """World positions of the modules' link frames, shape ``(len(modules), 3)``."""
        return self.data.xpos[self.bodies[modules]]


def arc_bins(local: np.ndarray, bins: int = ARC_BINS) -> np.ndarray:
    """Bin of each point's angle about the module axis (x): ``atan2(z, y)`` in ``bins`` bins."""
    angle = np.arctan2(local[:, 2], local[:, 1]) % (2.0 * np.pi)
    return np.minimum((angle * bins / (2.0 * np.pi)).astype(int), bins - 1)


def covering_arc_deg(touched: np.ndarray) -> np.ndarray:
    """Per row of touched bins (modules x bins, bool): the shortest arc covering every touched
    bin, in degrees: 0 if none, 360 minus the largest circular run of untouched bins otherwise."""
    touched = np.atleast_2d(np.asarray(touched, dtype=bool))
    bins = touched.shape[1]
    arcs = np.zeros(len(touched))
    for row, mask in enumerate(touched):
        if not mask.any():
            continue
        gap = run = 0
        for clear in np.concatenate([~mask, ~mask]):  # twice round: gaps across bin 0
            run = run + 1 if clear else 0
            gap = max(gap, run)
        arcs[row] = 360.0 * (bins - min(gap, bins)) / bins
    return arcs


# --- one episode ---------------------------------------------------------------------------------


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


# --- open-loop policies --------------------------------------------------------------------------


def zero_policy(env: gymnasium.Env) -> Policy:
    """The open-loop gait: a zero residual (and, with the cadence option, the gait's cadence)."""
    zero = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)
    return lambda obs: zero


def cadence_action(phase_rate: float, phase_rate_range: Sequence[float]) -> float:
    """The cadence action that plays ``phase_rate`` keyframes per step (the env's mapping
    ``1 + a (high - 1)`` for ``a >= 0``, ``1 + a (1 - low)`` below, inverted)."""
    low, high = phase_rate_range
    if not low <= phase_rate <= high:
        raise ValueError(f"phase_rate {phase_rate} is outside phase_rate_range {phase_rate_range}")
    if phase_rate >= 1.0:
        return (phase_rate - 1.0) / (high - 1.0) if high > 1.0 else 0.0
    return (phase_rate - 1.0) / (1.0 - low)


def constant_cadence_policy(env: gymnasium.Env, phase_rate: float) -> Policy:
    """The open-loop gait (zero residual) played at ``phase_rate`` keyframes per step; the env
    must have the cadence option (``phase_rate_range``)."""
    config = getattr(env.unwrapped, "config", None)  # an ACLClimbEnv's (envs/config.py)
    rate_range = None if config is None else config.gait.phase_rate_range
    if rate_range is None:
        raise ValueError("a constant cadence needs an env with phase_rate_range set")
    action = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)
    action[-1] = cadence_action(phase_rate, rate_range)
    return lambda obs: action


# --- over episodes -------------------------------------------------------------------------------


def summarize(episodes: Sequence[Episode]) -> dict[str, Any]:
    """Mean and t-based 95 % CI per metric (``values`` per episode, in seed order)."""
    per_episode = [e.metrics() for e in episodes]
    summary: dict[str, Any] = {}
    for metric in METRICS:
        values = [m[metric] for m in per_episode]
        summary[metric] = {**mean_ci95(values), "values": values}
    summary["falls"]["count"] = sum(e.fell for e in episodes)
    summary["unstable"] = sum(e.unstable for e in episodes)
    summary["rolled"] = sum(e.rolled for e in episodes)
    summary["mean_phase_rate"] = float(
        sum(e.keyframes for e in episodes) / max(1, sum(e.steps for e in episodes))
    )
    summary["episodes"] = len(episodes)
    summary["seeds"] = [e.seed for e in episodes]
    return summary


# Metrics compared episode by episode in :func:`paired_differences`.
PAIRED_METRICS = ("climb_per_gait_cycle_m", "slip_per_m", "energy_per_m", "reward_per_gait_cycle")


def paired_differences(
    summaries: dict[str, dict[str, Any]],
    reference: str = "policy",
    metrics: Sequence[str] = PAIRED_METRICS,
) -> dict[str, dict[str, dict[str, Any]]]:
    """``reference`` minus each other controller, episode by episode on the same reset seeds:
    ``{controller: {metric: mean_ci95(differences)}}`` (:func:`summarize`'s ``values``).

    Both sides of a pair share the seed, so the pole, skin and springs drawn for it: the paired
    interval is the one that says whether one controller beats the other, and it is often much
    narrower than the two controllers' own intervals side by side. Episodes where either value is
    undefined (no climb: slip per metre) are left out of that metric's pairs (``n`` says how many
    remain). Controllers run on other seeds raise ``ValueError``.
    """
    ref = summaries[reference]
    out: dict[str, dict[str, dict[str, Any]]] = {}
    for name, summary in summaries.items():
        if name == reference:
            continue
        if summary["seeds"] != ref["seeds"]:
            raise ValueError(
                f"{name} ran on seeds {summary['seeds']}, {reference} on {ref['seeds']}"
            )
        out[name] = {}
        for metric in metrics:
            pairs = zip(ref[metric]["values"], summary[metric]["values"], strict=True)
            out[name][metric] = mean_ci95(
                a - b for a, b in pairs if a is not None and b is not None
            )
    return out


def format_paired(differences: dict[str, dict[str, dict[str, Any]]], reference: str) -> str:
    """One line per controller: the paired differences of :func:`paired_differences`."""
    lines = [f"{reference} minus each controller, paired over the same seeds (mean ± 95 % CI):"]
    for name, metrics in differences.items():
        cells = []
        for metric, label, fmt in TABLE_ROWS:
            if metric in metrics:
                d = metrics[metric]
                cells.append(f"{label} {d['mean']:+{fmt}} ± {d['half_width']:{fmt}}")
        lines.append(f"  {name}: " + "; ".join(cells))
    return "\n".join(lines)


# Columns of :func:`format_table`: metric, label, format.
TABLE_ROWS = (
    ("climb_per_cycle_m", "climb per nominal cycle (m)", ".4f"),
    ("climb_per_gait_cycle_m", "climb per gait cycle (m)", ".4f"),
    ("climb_speed_cm_s", "climb speed (cm/s)", ".3f"),
    ("slip_per_cycle_m", "slip per nominal cycle (m)", ".4f"),
    ("slip_per_m", "slip per metre climbed", ".3f"),
    ("energy_per_m", "energy (J/m)", ".0f"),
    ("mean_abs_torque_nm", "mean abs torque (N m)", ".3f"),
    ("torque_limit_fraction", "share at torque limit", ".4f"),
    ("touched_arc_deg", "touched arc (deg)", ".0f"),
    ("reward_per_gait_cycle", "reward per gait cycle", ".4f"),
    ("action_change", "action change per step", ".3f"),
)


def format_table(summaries: dict[str, dict[str, Any]], markdown: bool = False) -> str:
    """One column per controller, mean ± 95 % CI half-width per metric: aligned plain text, or a
    Markdown table (``markdown``) for the README."""
    names = list(summaries)
    rows = [["metric", *names]]
    for metric, label, fmt in TABLE_ROWS:
        row = [label]
        for name in names:
            s = summaries[name].get(metric)  # an older evaluation's JSON may lack a metric
            row.append("n/a" if s is None else f"{s['mean']:{fmt}} ± {s['half_width']:{fmt}}")
        rows.append(row)
    values = summaries.values()
    rows.append(["falls", *(f"{s['falls']['count']}/{s['episodes']}" for s in values)])
    rows.append(["gait keyframes per step", *(f"{s['mean_phase_rate']:.3f}" for s in values)])
    n = next(iter(summaries.values()))["episodes"] if summaries else 0
    caption = f"mean ± 95 % CI half-width (Student's t, {n} episodes)"
    if markdown:
        lines = ["| " + " | ".join(row) + " |" for row in rows]
        lines.insert(1, "|---" * len(rows[0]) + "|")
        return "\n".join([*lines, "", caption])
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    lines = []
    for row in rows:
        cells = [row[0].ljust(widths[0])] + [
            c.rjust(w) for c, w in zip(row[1:], widths[1:], strict=True)
        ]
        lines.append("  ".join(cells))
    lines.insert(1, "-" * len(lines[0]))
    return "\n".join([*lines, caption])
