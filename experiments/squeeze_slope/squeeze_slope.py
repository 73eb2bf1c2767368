"""How far should the non-rolling gait's helix loosen on thinner poles? An open-loop sweep.

``python experiments/squeeze_slope/squeeze_slope.py [--slopes 0 0.5 0.7 0.85 1] [--pole-radii R ...]
[--episodes 5] [--env-kwargs KEY:VALUE ...] [--json PATH] [--plot PATH] [--workers 2]`` plays the
registered non-rolling gait (``acl_env/ACLClimbNoRoll-v3``) open loop, a zero action, with each
``squeeze_slope`` on each pole, the same reset seeds everywhere
(:func:`acl_env.evaluation.runner.run_controllers`). ``squeeze_slope`` k commands the helix ``k *
(0.075 - pole radius)`` looser than the squeeze tuned on the default 0.075 m pole (Eq. 1's r;
``ACLClimbEnv.squeeze_at``). Prints, per slope and pole, the climb per gait cycle of the episodes
that held the pole for both cycles, and how many fell or rolled past ``roll_limit``; then each
slope's mean climb over the training range's poles (a fall or roll counts as 0 cm). The slope to
register is chosen on the training range's poles alone (0.065 m and up), so that the held-out 0.055
m pole stays held out. ``--plot`` draws the climb against the pole radius per slope, with the
training range shaded.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from acl_env import ACL_CLIMB_NOROLL_ID
from acl_env.evaluation import Episode
from acl_env.evaluation.baselines import Controller
from acl_env.evaluation.runner import evaluate
from acl_env.io import console_script
from acl_env.scripts import make_parser, save_figure, seeds, use_agg, write_output
from acl_env.training.checks import check_env_kwargs

SLOPES = (0.0, 0.5, 0.7, 0.85, 1.0)
POLE_RADII = (0.055, 0.06, 0.065, 0.0675, 0.07, 0.0725, 0.075)
TRAINING_POLES = (0.065, 0.09)  # ppo.yml's domain randomisation of the pole radius (m)


def held(episode: Episode) -> bool:
    """Did the episode run its full length without a fall or a roll past the limit?"""
    return not (episode.fell or episode.rolled or episode.unstable)


def cell(episodes: list[Episode]) -> dict[str, Any]:
    """Climb per gait cycle (cm) of the held episodes, and what ended the others."""
    climbs = [100.0 * e.metrics()["climb_per_gait_cycle_m"] for e in episodes]
    kept = [c for c, e in zip(climbs, episodes, strict=True) if held(e)]
    return {
        "climb_cm_held": float(np.mean(kept)) if kept else math.nan,
        "climb_cm_scored": float(
            np.mean([c if held(e) else 0.0 for c, e in zip(climbs, episodes, strict=True)])
        ),
        "climb_cm": climbs,
        "fell": sum(e.fell for e in episodes),
        "rolled": sum(e.rolled for e in episodes),
        "touched_arc_deg": float(max(e.metrics()["touched_arc_deg"] for e in episodes)),
        "episodes": len(episodes),
    }


def plot(table: dict[str, dict[str, dict[str, Any]]], path: str | Path) -> None:
    """Climb per gait cycle (held episodes) against pole radius, one line per slope; a cross
    where an episode fell or rolled."""
    plt = use_agg()
    fig, ax = plt.subplots(figsize=(7.0, 4.2))
    ax.axvspan(*(100 * r for r in TRAINING_POLES), color="0.92", label="training range")
    for slope, cells in table.items():
        radii = [100 * float(r) for r in cells]
        climbs = [c["climb_cm_held"] for c in cells.values()]
        (line,) = ax.plot(radii, climbs, "o-", label=f"squeeze_slope {slope}")
        lost = [
            (x, 0.0) for x, c in zip(radii, cells.values(), strict=True) if c["fell"] + c["rolled"]
        ]
        if lost:
            ax.plot(*zip(*lost, strict=True), "x", color=line.get_color(), markersize=9)
    ax.set_xlabel("pole radius (cm)")
    ax.set_ylabel("climb per gait cycle (cm), held episodes")
    ax.set_title("Non-rolling gait open loop: squeeze loosened on thin poles (x: fell or rolled)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    save_figure(fig, path, 120, tight=True)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(
        __doc__, plot=True, plot_suffixes=(".png",), seed=0, episodes=5, workers=2,
        env_kwargs=True, progress=True,
    )  # fmt: skip
    parser.add_argument("--slopes", type=float, nargs="+", default=list(SLOPES))
    parser.add_argument("--pole-radii", type=float, nargs="+", default=list(POLE_RADII))
    args = parser.parse_args(argv)
    overrides: dict[str, Any] = args.env_kwargs
    for name in ("squeeze_slope", "pole_radius"):
        if name in overrides:
            parser.error(f"argument --env-kwargs: {name} is what the sweep varies")
    try:
        for slope in args.slopes:
            for radius in args.pole_radii:
                kwargs = {**overrides, "squeeze_slope": slope, "pole_radius": radius}
                check_env_kwargs(ACL_CLIMB_NOROLL_ID, kwargs).close()
    except (ValueError, TypeError) as error:
        parser.error(f"argument --slopes/--pole-radii/--env-kwargs: {str(error).splitlines()[0]}")
    controllers = [
        Controller(
            f"{slope}@{radius}",
            ACL_CLIMB_NOROLL_ID,
            {**overrides, "squeeze_slope": slope, "pole_radius": radius},
        )
        for slope in args.slopes
        for radius in args.pole_radii
    ]
    played = seeds(args)
    results = evaluate(controllers, played, args.workers, progress=not args.no_progress_bar)
    table = {
        str(slope): {str(r): cell(results[f"{slope}@{r}"]) for r in args.pole_radii}
        for slope in args.slopes
    }
    lo, hi = TRAINING_POLES
    print("climb per gait cycle (cm, episodes that held) / fell / rolled")
    print("slope  " + "  ".join(f"{100 * r:>12.3g}" for r in args.pole_radii) + "  training")
    training_means = {}
    for slope, cells in table.items():
        row = [f"{c['climb_cm_held']:5.2f}/{c['fell']}/{c['rolled']}" for c in cells.values()]
        inside = [c["climb_cm_scored"] for r, c in cells.items() if lo <= float(r) <= hi]
        training_means[slope] = float(np.mean(inside)) if inside else math.nan
        print(
            f"{slope:>5}  " + "  ".join(f"{x:>12}" for x in row) + f"  {training_means[slope]:.2f}"
        )
    best = max(
        training_means,
        key=lambda s: -math.inf if math.isnan(training_means[s]) else training_means[s],
    )
    print(f"best on the training range's poles (falls and rolls as 0 cm): squeeze_slope {best}")
    record = {
        "env_id": ACL_CLIMB_NOROLL_ID,
        "env_kwargs": overrides,
        "seeds": played,
        "training_poles": list(TRAINING_POLES),
        "cells": table,
        "training_mean_climb_cm": training_means,
        "best_on_training_poles": best,
    }
    write_output(args.json, record)
    if args.plot:
        plot(table, args.plot)
    return record


if __name__ == "__main__":
    console_script(main)()
