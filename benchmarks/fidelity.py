"""Physics fidelity against cost: open-loop climbing under candidate physics settings vs 1 ms.

``python benchmarks/fidelity.py [--seeds 3] [--cycles 2] [--settings NAME ...] [--workers 1]
[--actuator-model servo|sea] [--json PATH] [--figure PATH]``

``--actuator-model sea`` runs every condition on the series elastic actuators (``kp 10`` becomes
a 10 N m/rad spring); their command latency is whole physics steps at every setting compared.

Every panel condition (gait, pole, skin, springs, a fixed random residual) is rolled out for
``--cycles`` gait cycles per seed under every candidate setting (physics step, friction cone,
solver iterations and tolerance, line-search iterations, MuJoCo's ``refsafe`` clamp of contact
time constants) and compared with the same rollouts at a 1 ms step. Per cell: climb and slip per
cycle, energy per metre climbed, falls, MuJoCo warnings and the wall time of one ``env.step``.
A setting *passes* when, in every condition, the seed-mean climb is within 2 % of the
reference, slip and energy within 15 %, falls are the same and no warning was raised; the
cheapest passing setting is printed last. The cost of a step is measured apart: the thread CPU
time of open-loop ``env.step`` of the default ACL env, settings in turn in blocks of
``--cost-steps``, median of ``--cost-rounds`` (other processes on the machine do not count);
speed-up is against the v0 2 ms step.
"""

from __future__ import annotations

import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from tqdm import tqdm

from acl_env import ACL_CLIMB_ID, ROLLING_HELIX_CLIMB_ID, actuators
from acl_env.constants import FIDELITY_TOLERANCES, PHYSICS_TIMESTEP
from acl_env.envs import termination
from acl_env.evaluation import run_episode
from acl_env.io import console_script
from acl_env.model import apply_physics_options
from acl_env.scripts import make_parser, save_figure, timed_steps, use_agg, write_outputs


@dataclass(frozen=True)
class Condition:
    """One open-loop rollout: env id, env arguments, and the std of a fixed random action."""

    env_id: str
    kwargs: dict[str, Any] = field(default_factory=dict)
    action_std: float = 0.0


@dataclass(frozen=True)
class Setting:
    """Physics settings: the env's ``timestep`` and overrides applied after it is built
    (``MjOption`` fields ``cone``, ``iterations``, ``tolerance``, ``ls_iterations``,
    ``impratio``; ``refsafe=False`` disables MuJoCo's clamp of contact time constants to >= 2
    timesteps; ``solimp`` sets every geom's impedance ``(d_min, d_max)``; ``contact_timeconst``
    the shells' and pole's solref time constant)."""

    timestep: float
    options: dict[str, Any] = field(default_factory=dict)


CONDITIONS: dict[str, Condition] = {
    "ACL": Condition(ACL_CLIMB_ID),
    "rolling helix": Condition(ROLLING_HELIX_CLIMB_ID),
    "ACL non-rolling": Condition(
        ACL_CLIMB_ID,
        {"gait_kwargs": {"rolls_per_cycle": 0, "amp_pitch": 0.03, "amp_radial": 0.015}},
    ),
    "friction 0.4": Condition(ACL_CLIMB_ID, {"friction": 0.4}),
    "pole 0.1 m": Condition(ACL_CLIMB_ID, {"pole_radius": 0.1}),
    "kp 10": Condition(ACL_CLIMB_ID, {"kp": 10.0}),
    # 0.15 x residual_scale 0.2 = 0.03 rad of joint noise, the PPO config's exploration level.
    "ACL + random residual": Condition(ACL_CLIMB_ID, action_std=0.15),
}
REFERENCE = "1 ms"
BASELINE = "2 ms (v0)"
SETTINGS: dict[str, Setting] = {
    REFERENCE: Setting(0.001),
    BASELINE: Setting(0.002),
    "2.5 ms": Setting(0.0025),
    "2.9 ms": Setting(0.1 / 35),
    "3.3 ms (v1)": Setting(1 / 300),
    "4 ms": Setting(0.004),
    "5 ms": Setting(0.005),
    "4 ms tol 1e-6": Setting(0.004, {"tolerance": 1e-6}),
    "4 ms pyramidal": Setting(0.004, {"cone": "pyramidal"}),
    # MuJoCo clamps the contacts' 5 ms time constant to 2 steps (8 ms at 4 ms); without the clamp
    # the friction rows overshoot every step (h b = 1.7) and slip doubles.
    "4 ms refsafe off": Setting(0.004, {"refsafe": False}),
    # impratio x (clamped / scene time constant): the creep R f / b of a sticking friction row
    # of the unclamped contact (R_friction = R_normal / impratio, b = 2 / (d_max t_c)).
    "3.3 ms impratio 13.3": Setting(1 / 300, {"impratio": 40 / 3}),
    "4 ms impratio 16": Setting(0.004, {"impratio": 16.0}),
    # Stiffer impedance (d_min, d_max): less creep and penetration of the softened contact.
    "3.3 ms solimp .93/.96": Setting(1 / 300, {"solimp": (0.93, 0.96)}),
    "4 ms solimp .95/.97": Setting(0.004, {"solimp": (0.95, 0.97)}),
    # Not a candidate: how much of the 4 ms error is the clamped (8 ms) contact itself.
    "1 ms, 8 ms contact": Setting(0.001, {"contact_timeconst": 0.008}),
}
TOLERANCES = {
    "climb": FIDELITY_TOLERANCES["climb_per_cycle_m"],
    "slip": FIDELITY_TOLERANCES["slip_per_cycle_m"],
    "energy": FIDELITY_TOLERANCES["energy_per_m"],
}
RESIDUAL_SEED = 12345  # the random residual sequence is the same under every setting


def actuator_kwargs(kwargs: dict[str, Any], actuator_model: str) -> dict[str, Any]:
    """A condition's env kwargs on ``actuator_model``: its stiffness (the servo's ``kp``, stated
    by the conditions) passed as the model's own stiffness option (the SEA's spring)."""
    stiffness = actuators.actuator_model("servo").stiffness
    out = {k: v for k, v in kwargs.items() if k != stiffness}
    if stiffness in kwargs:
        out[actuators.actuator_model(actuator_model).stiffness] = kwargs[stiffness]
    return {**out, "actuator_model": actuator_model}


def rollout(
    condition: Condition, setting: Setting, seed: int, cycles: int, actuator_model: str = "servo"
) -> dict[str, float]:
    """Climb and slip per cycle, energy per metre, fall, warnings and step cost of one episode."""
    env = gym.make(
        condition.env_id,
        timestep=setting.timestep,
        cycles_per_episode=cycles,
        **actuator_kwargs(condition.kwargs, actuator_model),
    )
    base = env.unwrapped
    apply_physics_options(base.model, setting.options)
    steps = base.steps_per_cycle * cycles
    rng = np.random.default_rng(RESIDUAL_SEED + seed)
    actions = condition.action_std * rng.standard_normal((steps, *env.action_space.shape))
    actions = iter(np.clip(actions, -1.0, 1.0).astype(np.float32))
    warnings = [0, 0]  # raised so far, count before the step

    def policy(obs: np.ndarray) -> np.ndarray:
        warnings[1] = termination.warning_count(base.data)
        return next(actions)

    def hook(env: gym.Env, obs: np.ndarray, action: np.ndarray | None, info: dict) -> None:
        if action is None:  # after the reset: warnings raised while ramping in
            warnings[0] = termination.warning_count(base.data)
            return
        warnings[0] += max(0, termination.warning_count(base.data) - warnings[1])

    episode = run_episode(env, policy, seed, callback=hook)
    env.close()
    metrics = episode.metrics()
    return {
        "climb": metrics["climb_per_cycle_m"],
        "slip": metrics["slip_per_cycle_m"],
        "energy_per_m": metrics["energy_per_m"],
        "fell": metrics["falls"],
        "warnings": float(warnings[0] + episode.unstable),
    }


def step_costs(
    settings: list[str], steps: int, rounds: int, actuator_model: str = "servo"
) -> dict[str, float]:
    """CPU time (ms) of one open-loop ``env.step`` of the default ACL env per setting: blocks of
    ``steps`` steps, settings in turn, median over ``rounds`` (thread CPU time, so other
    processes on the machine do not count)."""
    envs = {}
    for name in settings:
        setting = SETTINGS[name]
        kwargs = actuator_kwargs({}, actuator_model)
        env = gym.make(ACL_CLIMB_ID, timestep=setting.timestep, **kwargs).unwrapped
        apply_physics_options(env.model, setting.options)
        env.reset(seed=0)
        envs[name] = env
    costs: dict[str, list[float]] = {name: [] for name in settings}
    for _ in tqdm(range(rounds), desc="step cost", leave=False):
        for name, env in envs.items():
            elapsed = timed_steps(env, steps, time.thread_time, reset_seed=0)
            costs[name].append(1e3 * elapsed / steps)
    return {name: float(np.median(c)) for name, c in costs.items()}


def _cell(args: tuple[str, str, int, int, str]) -> tuple[str, str, int, dict[str, float]]:
    condition, setting, seed, cycles, model = args
    result = rollout(CONDITIONS[condition], SETTINGS[setting], seed, cycles, model)
    return condition, setting, seed, result


def summarize(
    runs: dict[tuple[str, str], list[dict[str, float]]],
    settings: list[str],
    costs: dict[str, float],
) -> dict[str, Any]:
    """Seed means per cell, relative errors against the reference, pass/fail per setting."""
    cells: dict[str, dict[str, dict[str, float]]] = {}
    for (condition, setting), rows in runs.items():
        mean = {key: float(np.mean([r[key] for r in rows])) for key in rows[0]}
        mean["falls"] = float(sum(r["fell"] for r in rows))
        mean["warnings"] = float(sum(r["warnings"] for r in rows))
        cells.setdefault(setting, {})[condition] = mean
    out: dict[str, Any] = {}
    for setting in settings:
        rows = cells[setting]
        errors = {metric: {} for metric in TOLERANCES}
        passed = True
        for condition, row in rows.items():
            ref = cells[REFERENCE][condition]
            for metric, key in (("climb", "climb"), ("slip", "slip"), ("energy", "energy_per_m")):
                err = row[key] / ref[key] - 1.0
                errors[metric][condition] = err
                passed &= bool(abs(err) <= TOLERANCES[metric])
            passed &= row["falls"] == ref["falls"] and row["warnings"] == 0
        out[setting] = {
            "timestep": SETTINGS[setting].timestep,
            "options": SETTINGS[setting].options,
            "step_ms": costs[setting],
            "speedup_vs_2ms": costs[BASELINE] / costs[setting],
            "worst": {m: max(e.values(), key=abs) for m, e in errors.items()},
            "errors": errors,
            "falls": sum(r["falls"] for r in rows.values()),
            "warnings": sum(r["warnings"] for r in rows.values()),
            "passes": passed,
            "cells": rows,
        }
    return out


def print_tables(summary: dict[str, Any]) -> None:
    ref = summary[REFERENCE]["cells"]
    print("\nReference (1 ms), seed means: climb / slip per cycle (m), energy (J/m), falls")
    for condition, row in ref.items():
        print(
            f"  {condition:22s} {row['climb']:.4f} / {row['slip']:.4f}  "
            f"{row['energy_per_m']:7.1f}  {row['falls']:.0f}"
        )
    print(
        "\n| setting | step (ms) | speed-up vs 2 ms | worst climb | worst slip | worst energy "
        "| falls | warnings | passes |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for name, s in summary.items():
        w = s["worst"]
        print(
            f"| {name} | {s['step_ms']:.2f} | {s['speedup_vs_2ms']:.2f}x "
            f"| {100 * w['climb']:+.1f} % | {100 * w['slip']:+.1f} % "
            f"| {100 * w['energy']:+.1f} % | {s['falls']:.0f} "
            f"| {s['warnings']:.0f} | {'yes' if s['passes'] else 'no'} |"
        )
    print("\nSlip error per condition (%):")
    conditions = list(ref)
    print(f"  {'setting':20s} " + " ".join(f"{c[:12]:>12s}" for c in conditions))
    for name, s in summary.items():
        slips = (100 * s["errors"]["slip"][c] for c in conditions)
        print(f"  {name:20s} " + " ".join(f"{e:+12.1f}" for e in slips))


def plot(summary: dict[str, Any], path: Path) -> None:
    """Worst relative error (climb, slip, energy) against speed-up, one point per setting and
    metric; filled markers pass every row, hollow ones do not."""
    plt = use_agg()
    fig, ax = plt.subplots(figsize=(8.0, 6.0))  # the legend below the axes takes 1 in
    styles = {"climb": ("o", "C0"), "slip": ("s", "C1"), "energy": ("^", "C2")}
    settings = [(name, s) for name, s in summary.items() if name != REFERENCE]
    for metric, (marker, color) in styles.items():
        for passed in (True, False):
            points = [
                (s["speedup_vs_2ms"], max(100 * abs(s["worst"][metric]), 0.1))
                for _, s in settings
                if s["passes"] == passed
            ]
            if points:
                x, y = zip(*points, strict=True)
                ax.scatter(
                    x,
                    y,
                    marker=marker,
                    color=color if passed else "none",
                    edgecolors=color,
                    label=f"worst |{metric} error|" + ("" if passed else " (fails a row)"),
                )
        ax.axhline(100 * TOLERANCES[metric], ls=":", lw=0.8, color=color)
    for i, (name, s) in enumerate(settings):
        ax.annotate(
            name,
            (s["speedup_vs_2ms"], max(100 * abs(s["worst"]["slip"]), 0.1)),
            fontsize=7,
            xytext=(4, 6 if i % 2 else -9),
            textcoords="offset points",
        )
    ax.set_yscale("log")
    ax.set_xlabel("speed-up of env.step over the v0 2 ms step (CPU time)")
    ax.set_ylabel("worst error over the 7 conditions vs 1 ms (%)")
    ax.set_title("Open-loop fidelity against cost (dotted: 2 % climb, 15 % slip and energy)")
    # Below the axes, where it covers no point, in a size readable at the docs' 690 px width
    ax.legend(fontsize=10, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncols=2)
    save_figure(fig, path, 130, tight=True)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__, plot=True, plot_names=("--figure", "--plot"))
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--cycles", type=int, default=2)
    parser.add_argument(
        "--settings", nargs="+", choices=list(SETTINGS), help="candidates (default: all)"
    )
    parser.add_argument(
        "--workers", type=int, default=1, help="processes (2 only on an otherwise idle machine)"
    )
    parser.add_argument("--cost-steps", type=int, default=100, help="steps per cost block")
    parser.add_argument("--cost-rounds", type=int, default=7, help="cost rounds (median)")
    parser.add_argument(
        "--actuator-model", choices=("servo", "sea"), default="servo", help="joint actuators"
    )
    args = parser.parse_args(argv)
    settings = list(dict.fromkeys([REFERENCE, BASELINE, *(args.settings or SETTINGS)]))
    tasks = [
        (condition, setting, seed, args.cycles, args.actuator_model)
        for seed in range(args.seeds)
        for condition in CONDITIONS
        for setting in settings
    ]
    runs: dict[tuple[str, str], list[dict[str, float]]] = {}
    with ProcessPoolExecutor(args.workers) if args.workers > 1 else _Serial() as pool:
        for condition, setting, _, result in tqdm(
            pool.map(_cell, tasks), total=len(tasks), desc="fidelity"
        ):
            runs.setdefault((condition, setting), []).append(result)
    costs = step_costs(settings, args.cost_steps, args.cost_rounds, args.actuator_model)
    summary = summarize(runs, settings, costs)
    print_tables(summary)
    passing = [name for name, s in summary.items() if s["passes"] and name != REFERENCE]
    if passing:
        best = min(passing, key=lambda name: summary[name]["step_ms"])
        w = summary[best]["worst"]
        print(
            f"\nCheapest passing setting: {best} ({summary[best]['speedup_vs_2ms']:.2f}x the 2 ms "
            f"step; worst climb {100 * w['climb']:+.1f} %, slip {100 * w['slip']:+.1f} %, "
            f"energy {100 * w['energy']:+.1f} %)"
        )
    else:
        print("\nNo candidate passes every row.")
    default = [
        n for n, s in summary.items() if s["timestep"] == PHYSICS_TIMESTEP and not s["options"]
    ]
    if default:
        print(f"The env's default physics step ({1e3 * PHYSICS_TIMESTEP:g} ms) is {default[0]!r}.")
    write_outputs(args, summary, plot)
    return summary


class _Serial:
    """In-process stand-in for a process pool (one worker)."""

    def __enter__(self) -> _Serial:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def map(self, fn: Any, items: list[Any]) -> Any:
        return map(fn, items)


if __name__ == "__main__":
    console_script(main)()
