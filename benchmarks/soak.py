"""Soak test of the climbing envs: many random-action steps under domain randomisation.

Run by hand, not in CI: ``python benchmarks/soak.py [--steps 100000] [--seed 0] [--json PATH]``.
Episodes rotate over four envs (both gaits, with and without the ``phase_rate_range`` cadence
option, all with ``domain_randomization=True``), each reset from a fresh seed, each step a
uniform random action. It counts steps, resets, falls, instabilities, MuJoCo warnings (by kind,
from ``MjData.warning``), exceptions, steps with a non-finite observation, reward or ``info``
value, steps whose ``info`` is not JSON-serialisable, and the resident memory at the start, at
every tenth of the run and at the end. A healthy run has no exception, no non-finite value and
flat memory. MuJoCo appends its warnings to ``MUJOCO_LOG.TXT`` in the working folder.
"""

from __future__ import annotations

import json
import math
import resource
import time
import traceback
from typing import Any

import gymnasium as gym
import mujoco
import numpy as np
from tqdm import tqdm

from acl_env import ACL_CLIMB_ID, ROLLING_HELIX_CLIMB_ID
from acl_env.io import console_script
from acl_env.scripts import make_parser, write_output

CONFIGS: list[tuple[str, dict[str, Any]]] = [
    (ACL_CLIMB_ID, {}),
    (ROLLING_HELIX_CLIMB_ID, {}),
    (ACL_CLIMB_ID, {"phase_rate_range": (0.5, 1.5)}),
    (ROLLING_HELIX_CLIMB_ID, {"phase_rate_range": (0.5, 1.5)}),
]
LABELS = ["acl", "rolling_helix", "acl+cadence", "rolling_helix+cadence"]
WARNING_NAMES = {
    int(getattr(mujoco.mjtWarning, name)): name.removeprefix("mjWARN_")
    for name in dir(mujoco.mjtWarning)
    if name.startswith("mjWARN_")
}


def rss_mb() -> float:
    """Resident memory of this process now (MB), from /proc (Linux); peak RSS elsewhere."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def warning_counts(env: gym.Env) -> np.ndarray:
    """MuJoCo's per-kind warning counters of the env's data (zeroed by every reset)."""
    return np.array([w.number for w in env.unwrapped.data.warning], dtype=np.int64)


def finite_info(info: dict[str, Any]) -> bool:
    return all(math.isfinite(v) for v in info.values() if isinstance(v, float | np.floating))


class SoakRun:
    """The soak's envs, its one random stream (reset seeds and actions, in that order of use),
    the env in play and the tallies of what went wrong."""

    def __init__(self, seed: int) -> None:
        self.envs = [
            gym.make(env_id, domain_randomization=True, **kwargs) for env_id, kwargs in CONFIGS
        ]
        self.rng = np.random.default_rng(seed)
        self.counts = {
            "steps": 0,
            "resets": 0,
            "episodes_truncated": 0,
            "falls": 0,
            "instabilities": 0,
            "mujoco_warnings": 0,
            "exceptions": 0,
            "non_finite_steps": 0,
            "info_not_json": 0,
        }
        self.warnings_by_kind = dict.fromkeys(WARNING_NAMES.values(), 0)
        self.errors: list[str] = []
        self.per_config_steps = [0] * len(self.envs)
        self.index = 0
        self.env, self.seen = self.reset(self.index)

    def reset(self, index: int) -> tuple[gym.Env, np.ndarray]:
        """Reset env ``index`` from a fresh seed; it and its warning counters."""
        env = self.envs[index]
        self.counts["resets"] += 1
        env.reset(seed=int(self.rng.integers(2**31)))
        return env, warning_counts(env)

    def record_exception(self) -> None:
        """Count the exception being handled, and keep its traceback (the first ten)."""
        self.counts["exceptions"] += 1
        if len(self.errors) < 10:
            self.errors.append(traceback.format_exc(limit=3))

    def step(self) -> None:
        """One uniform random action, tallied; the next env's episode when this one ends."""
        env = self.env
        action = self.rng.uniform(-1.0, 1.0, env.action_space.shape).astype(np.float32)
        try:
            obs, reward, terminated, truncated, info = env.step(action)
        except Exception:  # counted and reported: the env promises never to raise here
            self.record_exception()
            terminated, truncated, info = True, False, {}
            obs, reward = np.zeros(1), 0.0
        self.counts["steps"] += 1
        self.per_config_steps[self.index] += 1
        self.count_warnings()
        counts = self.counts
        if not (np.all(np.isfinite(obs)) and math.isfinite(float(reward)) and finite_info(info)):
            counts["non_finite_steps"] += 1
        try:
            json.dumps(info)
        except TypeError:
            counts["info_not_json"] += 1
        counts["falls"] += bool(info.get("fell", False))
        counts["instabilities"] += bool(info.get("unstable", False))
        counts["episodes_truncated"] += bool(truncated and not terminated)
        if terminated or truncated:
            self.index = (self.index + 1) % len(self.envs)
            try:
                self.env, self.seen = self.reset(self.index)
            except Exception:
                self.record_exception()
                self.env, self.seen = self.reset(self.index)

    def count_warnings(self) -> None:
        """Add the MuJoCo warnings of the last step, by kind."""
        now = warning_counts(self.env)
        # MuJoCo's own reset on divergence keeps counting from the old counters.
        new = np.maximum(now - self.seen, 0)
        self.seen = now
        self.counts["mujoco_warnings"] += int(new.sum())
        for kind, number in enumerate(new):
            if number:
                self.warnings_by_kind[WARNING_NAMES.get(kind, str(kind))] += int(number)


def soak(steps: int, seed: int, progress: bool = True) -> dict[str, Any]:
    """Run ``steps`` random-action steps; the counts and memory figures as a dict."""
    run = SoakRun(seed)
    rss_start = rss_mb()
    rss_trace = [rss_start]
    start = time.perf_counter()
    bar = tqdm(total=steps, desc="soak", unit="step", disable=not progress, mininterval=1.0)
    for done in range(1, steps + 1):
        run.step()
        if done % max(1, steps // 10) == 0:
            rss_trace.append(rss_mb())
        bar.update(1)
    bar.close()
    elapsed = time.perf_counter() - start
    for env in run.envs:
        env.close()
    return {
        **run.counts,
        "steps_per_config": dict(zip(LABELS, run.per_config_steps, strict=True)),
        "warnings_by_kind": {k: v for k, v in run.warnings_by_kind.items() if v},
        "rss_start_mb": rss_start,
        "rss_end_mb": rss_mb(),
        "rss_peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "rss_trace_mb": rss_trace,
        "wall_s": elapsed,
        "steps_per_s": run.counts["steps"] / elapsed,
        "seed": seed,
        "errors": run.errors,
    }


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__, seed=0)
    parser.add_argument("--steps", type=int, default=100_000, help="random-action env steps")
    args = parser.parse_args(argv)
    if args.steps < 1:
        parser.error(f"--steps must be >= 1, got {args.steps}")
    figures = soak(args.steps, args.seed)
    for key, value in figures.items():
        if key == "errors":
            continue
        shown = f"{value:.1f}" if isinstance(value, float) else value
        if key == "rss_trace_mb":
            shown = " ".join(f"{v:.0f}" for v in value)
        print(f"{key:22s} {shown}")
    for error in figures["errors"]:
        print(error)
    write_output(args.json, figures)
    return figures


if __name__ == "__main__":
    console_script(main)()
