"""How far can the non-rolling open loop climb per cycle near its tuned gait? Three sweeps.

``python experiments/noroll_ceiling/noroll_ceiling.py [--env ID] [--seeds 20] [--sweeps waves
friction rocking] [--policy-eval EVAL.json] [--json PATH] [--plot PATH]``

Zero-action episodes (episode ``i`` resets with seed ``i``, the default condition) of the
non-rolling env's registered gait with one thing changed at a time. Every episode plays its two
cycles: the roll limit is lifted while it runs and judged afterwards, since an episode cut short
by it measures its climb over a transient (rocking cells then show 11-16 cm per gait cycle that
their whole cycles never reach):

* **waves**: the axial wave A_p, the radial wave A_r, or both, scaled by 0.8-1.2. Does a larger
  stroke climb further per cycle, or does the body roll or fall first?
* **friction**: the pole's friction from 0.5 to 5 (the model's bound). If the grip were what
  limits the climb, a stickier pole would raise it towards what the stroke promises.
* **rocking**: a roll that returns each cycle, ``phi_0 = rock_amp sin(2 pi phase + rock_phase)``
  (the gait's ``rock_amp``, ``rock_phase``; docs/gait.md#roll-offset), 5-30 deg at eight
  phases. The task lets each module touch up to 90 deg of its skin and the gait uses 60: can a
  partial roll, the rolling gait's mechanism, spend the rest on climbing?

Printed and in the JSON, per cell: climb per gait cycle (mean and 95 % CI,
:func:`acl_env.evaluation.mean_ci95`), the largest touched arc (the task's judge, at most 90
deg), the largest swept body roll (``info["roll_span_deg"]``, which the env's ``roll_limit``
bounds), the episodes whose roll swept past the env's limit and the falls. A cell *holds* when
no episode fell, touched more than 90 deg or rolled past the limit. The summary names the best
cell that held, as a multiple
of the registered gait measured in the same run, beside the project's 1.5x target. With
``--policy-eval`` (an ``acl-evaluate --json`` file) the plot also marks that policy's climb.
``experiments/noroll_two_stage/noroll_limits.py`` is the older, point-wise sweep of v2's gait.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from tqdm import tqdm

from acl_env import ACL_CLIMB_NOROLL_ID, cli
from acl_env.evaluation import mean_ci95, run_episode, zero_policy
from acl_env.evaluation.records import controller_summary, read_record
from acl_env.io import console_script
from acl_env.scripts import make_parser, save_figure, use_agg, write_outputs

TARGET_RATIO = 1.5  # the project's target: the policy's climb over the tuned non-rolling open loop
ARC_LIMIT_DEG = 90.0  # the non-rolling task's limit: the touched arc allowed on every module
WAVE_SCALES = (0.8, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15, 1.2)
WAVES = {"A_p": ("amp_pitch",), "A_r": ("amp_radial",), "A_p and A_r": ("amp_pitch", "amp_radial")}
FRICTIONS = (0.5, 0.7, 1.0, 1.5, 2.0, 3.0, 5.0)
ROCK_AMPS_DEG = (5.0, 10.0, 20.0, 30.0)
ROCK_PHASES_DEG = (0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0)
SWEEPS = ("waves", "friction", "rocking")


def cells(gait_kwargs: dict[str, Any], sweeps: Sequence[str]) -> list[dict[str, Any]]:
    """The sweep's cells: ``sweep``, ``series``, ``x`` and the env kwargs that make each."""
    out: list[dict[str, Any]] = [
        {"sweep": "registered", "series": "registered gait", "x": 1.0, "env_kwargs": {}}
    ]
    if "waves" in sweeps:
        for series, keys in WAVES.items():
            for scale in WAVE_SCALES:
                if scale == 1.0:
                    continue  # the registered gait
                changed = {key: gait_kwargs[key] * scale for key in keys}
                kwargs = {"gait_kwargs": {**gait_kwargs, **changed}}
                out.append({"sweep": "waves", "series": series, "x": scale, "env_kwargs": kwargs})
    if "friction" in sweeps:
        for friction in FRICTIONS:
            kwargs = {"friction": friction}
            out.append(
                {"sweep": "friction", "series": "friction", "x": friction, "env_kwargs": kwargs}
            )
    if "rocking" in sweeps:
        for amp in ROCK_AMPS_DEG:
            for phase in ROCK_PHASES_DEG:
                rock = {"rock_amp": math.radians(amp), "rock_phase": math.radians(phase)}
                kwargs = {"gait_kwargs": {**gait_kwargs, **rock}}
                series = f"rock {amp:g} deg"
                out.append({"sweep": "rocking", "series": series, "x": phase, "env_kwargs": kwargs})
    return out


def run_cell(
    env_id: str, env_kwargs: dict[str, Any], seeds: int, roll_limit: float
) -> dict[str, Any]:
    """The open loop's whole episodes on seeds ``0 .. seeds-1`` (no roll limit), summarised;
    ``rolled`` counts those whose swept roll passed ``roll_limit``."""
    env = gymnasium.make(env_id, **{**env_kwargs, "roll_limit": None})
    spans: list[float] = []

    def record(env: gymnasium.Env, obs: Any, action: Any, info: dict[str, Any]) -> None:
        if action is not None:
            spans[-1] = max(spans[-1], float(info["roll_span_deg"]))

    episodes = []
    for seed in range(seeds):
        spans.append(0.0)
        episodes.append(run_episode(env, zero_policy(env), seed, callback=record))
    env.close()
    metrics = [episode.metrics() for episode in episodes]
    climb = mean_ci95(m["climb_per_gait_cycle_m"] for m in metrics)
    return {
        "climb_per_gait_cycle_cm": 100.0 * climb["mean"],
        "climb_half_width_cm": 100.0 * climb["half_width"],
        "touched_arc_deg": float(max(m["touched_arc_deg"] for m in metrics)),
        "roll_span_deg": max(spans),
        "rolled": sum(span > roll_limit for span in spans),
        "falls": sum(episode.fell for episode in episodes),
        "n": seeds,
    }


def held(row: dict[str, Any]) -> bool:
    """No episode fell, touched more than 90 deg or rolled past the env's limit."""
    arc_ok = row["touched_arc_deg"] <= ARC_LIMIT_DEG
    return arc_ok and row["rolled"] == 0 and row["falls"] == 0


def summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """The registered gait's climb, the best cell that held, and the project's target."""
    registered = rows[0]["climb_per_gait_cycle_cm"]
    held_rows = [row for row in rows if held(row)]
    best = max(held_rows, key=lambda r: r["climb_per_gait_cycle_cm"], default=None)
    keys = ("sweep", "series", "x", "climb_per_gait_cycle_cm")
    return {
        "registered_cm": registered,
        "target_cm": TARGET_RATIO * registered,
        "best_held": None if best is None else {k: best[k] for k in keys},
        "best_held_ratio": math.nan
        if best is None
        else best["climb_per_gait_cycle_cm"] / registered,
    }


def policy_climb_cm(path: Path) -> float:
    """The policy's mean climb per gait cycle (cm) in an ``acl-evaluate --json`` file."""
    policy = controller_summary(read_record(path), "policy")
    return 100.0 * float(policy["climb_per_gait_cycle_m"]["mean"])


def plot(document: dict[str, Any], path: Path) -> None:
    """One panel per sweep: climb per gait cycle, hollow where an episode rolled or fell."""
    plt = use_agg()
    rows, info = document["cells"], document["summary"]
    sweeps = [s for s in SWEEPS if any(row["sweep"] == s for row in rows)]
    fig, axes = plt.subplots(1, len(sweeps), figsize=(5.0 * len(sweeps), 4.2), squeeze=False)
    labels = {
        "waves": "wave amplitude / registered",
        "friction": "pole friction",
        "rocking": "rock_phase (deg)",
    }
    for ax, sweep in zip(axes[0], sweeps, strict=True):
        series = dict.fromkeys(row["series"] for row in rows if row["sweep"] == sweep)
        for name in series:
            points = [row for row in rows if row["series"] == name]
            if sweep == "waves":
                points = sorted([*points, {**rows[0], "x": 1.0}], key=lambda r: r["x"])
            x = np.array([row["x"] for row in points])
            y = np.array([row["climb_per_gait_cycle_cm"] for row in points])
            ok = np.array([held(row) for row in points])
            (line,) = ax.plot(x, y, "-", label=name, alpha=0.8)
            ax.plot(x[ok], y[ok], "o", color=line.get_color())
            ax.plot(x[~ok], y[~ok], "o", mfc="none", color=line.get_color())
        ax.axhline(info["registered_cm"], color="0.4", ls=":", label="registered gait")
        ax.axhline(info["target_cm"], color="tab:red", ls="--", label="1.5x target")
        if document.get("policy_cm") is not None:
            ax.axhline(
                document["policy_cm"], color="tab:green", ls="-.", label="policy (--policy-eval)"
            )
        ax.set_xlabel(labels[sweep])
        ax.set_ylabel("climb per gait cycle (cm)")
        # cells that collapse (tens of cm down) would flatten the rest: clip, marked in the title
        ax.set_ylim(-2.0, 1.2 * info["target_cm"])
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(
        "Non-rolling open loop near its tuned gait: climb over two whole cycles "
        "(hollow: an episode fell, rolled past the limit or touched > 90 deg; clipped below -2 cm)"
    )
    save_figure(fig, path, 120, tight=True)


def build_parser() -> cli.ArgumentParser:
    """The command line (the parent options of :mod:`acl_env.scripts` and the sweep's own)."""
    parser = make_parser(__doc__, plot=True, plot_suffixes=(".png",), progress=True)
    parser.add_argument("--env", default=ACL_CLIMB_NOROLL_ID, help="a non-rolling env id")
    parser.add_argument(
        "--seeds", type=cli.int_at_least(1), default=20, help="episodes per cell (evaluate's 20)"
    )
    parser.add_argument("--sweeps", nargs="+", choices=SWEEPS, default=list(SWEEPS))
    parser.add_argument("--policy-eval", type=Path, help="an acl-evaluate --json file to mark")
    return parser


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.policy_eval is not None and not args.policy_eval.is_file():
        parser.error(f"argument --policy-eval: no such file {str(args.policy_eval)!r}")
    probe = gymnasium.make(args.env)
    config = probe.unwrapped.config
    gait_kwargs, roll_limit = dict(config.gait.gait_kwargs), config.episode.roll_limit
    probe.close()
    if gait_kwargs.get("rolls_per_cycle", 1.0) != 0.0 or roll_limit is None:
        parser.error(
            f"argument --env: {args.env} is not a non-rolling env (rolls_per_cycle 0, a roll_limit)"
        )
    rows = []
    for cell in tqdm(cells(gait_kwargs, args.sweeps), desc="cells", disable=args.no_progress_bar):
        rows.append({**cell, **run_cell(args.env, cell["env_kwargs"], args.seeds, roll_limit)})
    document: dict[str, Any] = {
        "env": args.env,
        "seeds": args.seeds,
        "roll_limit_deg": roll_limit,
        "cells": rows,
    }
    document["summary"] = summary(rows)
    if args.policy_eval is not None:
        document["policy_cm"] = policy_climb_cm(args.policy_eval)
    print(
        "| sweep | series | x | climb / gait cycle (cm) | largest arc (deg) "
        "| largest roll swept (deg) | rolled past the limit | falls |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for row in rows:
        print(
            f"| {row['sweep']} | {row['series']} | {row['x']:g} "
            f"| {row['climb_per_gait_cycle_cm']:.2f} ± {row['climb_half_width_cm']:.2f} "
            f"| {row['touched_arc_deg']:.0f} | {row['roll_span_deg']:.0f} "
            f"| {row['rolled']}/{row['n']} | {row['falls']}/{row['n']} |"
        )
    info = document["summary"]
    best = info["best_held"]
    held_text = (
        "no cell held"
        if best is None
        else f"best cell that held: {best['series']} at {best['x']:g}, "
        f"{best['climb_per_gait_cycle_cm']:.2f} cm ({info['best_held_ratio']:.2f}x)"
    )
    print(
        f"registered gait {info['registered_cm']:.2f} cm per gait cycle; {held_text}; "
        f"the 1.5x target is {info['target_cm']:.2f} cm"
    )
    write_outputs(args, document, plot)
    return document


if __name__ == "__main__":
    console_script(main)()
