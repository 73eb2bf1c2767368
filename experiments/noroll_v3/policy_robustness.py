"""Is the policy no worse than open loop across the randomisation range? Pole radius x friction.

``python experiments/noroll_v3/policy_robustness.py [--policy DIR] [--episodes 5] [--held-out |
--pole-radii R ...] [--env-kwargs KEY:VALUE ...] [--json PATH] [--plot PATH] [--tuned-gaits FILE]
[--tuned-key KEY]`` evaluates the controllers of ``acl-evaluate`` (:mod:`acl_env.evaluation`:
the policy, open-loop ACL, at the policy's cadence, rolling helix, tuned gait from
``--tuned-gaits``, entry ``--tuned-key``; same seeds for all) at the corners and centre of the
training ranges of pole radius and friction, with ``--held-out`` under conditions outside the
training ranges (``HELD_OUT``), or with ``--pole-radii`` on each of those poles (a sweep, say
towards the thin held-out pole), and prints the climb per gait cycle, slip per metre, largest
touched arc, falls and (in the JSON) episodes ended by rolling, mean episode length and the share of
its base gait's joint commands that the joint limit clips in that cell (``gait.saturation``) of
each. ``--env-kwargs`` applies to every cell (``roll_limit:None`` lets episodes run on past the roll
limit, to see what the body does there). ``--plot`` draws a pole sweep: climb per gait cycle, the
share of episodes that fell or rolled and the clipped share, per controller.
"""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import numpy as np

from acl_env import cli, tuned_gaits
from acl_env.evaluation import summarize
from acl_env.evaluation.baselines import (
    DEFAULT_POLICY,
    DEFAULT_TUNED_GAITS,
    build_controllers,
)
from acl_env.evaluation.runner import evaluate, make_pool
from acl_env.io import console_script
from acl_env.scripts import add_trust_pickles, make_parser, save_figure, use_agg, write_output
from acl_env.training.checks import check_env_kwargs
from acl_env.training.policy import read_policy_folder

POLE_RADII = (0.065, 0.075, 0.09)
FRICTIONS = (0.7, 1.0, 1.2)
# --held-out: one condition at a time outside the training ranges of ppo.yml's domain
# randomisation (pole radius 0.065-0.09 m, friction 0.7-1.2, kp 15-30 N m/rad, mass 0.9-1.1x):
# 1 cm beyond each end of the radius range, 0.2-0.3 beyond the friction range, 20 % beyond kp and
# mass. Thinner and thicker poles, slicker and grippier skins, softer and stiffer springs, a
# lighter robot and one carrying a payload. Everything else at the env's defaults.
HELD_OUT: tuple[tuple[str, dict], ...] = (
    ("pole radius 0.055 m", {"pole_radius": 0.055}),
    ("pole radius 0.10 m", {"pole_radius": 0.10}),
    ("friction 0.5", {"friction": 0.5}),
    ("friction 1.5", {"friction": 1.5}),
    ("kp 12 N m/rad", {"kp": 12.0}),
    ("kp 36 N m/rad", {"kp": 36.0}),
    ("mass 0.8x", {"domain_randomization": {"mass_scale": [0.8, 0.8]}}),
    ("mass 1.2x", {"domain_randomization": {"mass_scale": [1.2, 1.2]}}),
)
CLIMB_FLOOR_CM = -5.0  # the sweep plot's climb axis starts here (a fall reads as metres down)
COLUMNS = ("climb_per_gait_cycle_m", "slip_per_m", "touched_arc_deg")


def grid_conditions() -> list[tuple[str, dict]]:
    """The corners and centre of the training ranges of pole radius and friction."""
    return [
        (
            f"pole {radius:.3f} m, friction {friction:.1f}",
            {"pole_radius": radius, "friction": friction},
        )
        for radius, friction in itertools.product(POLE_RADII, FRICTIONS)
    ]


def radius_conditions(radii: list[float]) -> list[tuple[str, dict]]:
    """One condition per pole radius (m), everything else at the env's defaults."""
    return [(f"pole radius {radius:g} m", {"pole_radius": radius}) for radius in radii]


def plot_sweep(rows: list[dict], path: Path) -> None:
    """Climb per gait cycle (cm), the share of episodes that fell or rolled past ``roll_limit``
    and the share of the base gait's joint commands clipped at the joint limit, against the pole
    radius, one line per controller (rows of a ``--pole-radii`` sweep, in order)."""
    plt = use_agg()
    radii = [100.0 * row["overrides"]["pole_radius"] for row in rows]
    names = [key for key in rows[0] if key not in ("condition", "overrides")]
    fig, (top, middle, bottom) = plt.subplots(3, 1, figsize=(6.4, 7.6), sharex=True)
    for name in names:
        climb = np.array([100.0 * row[name]["climb_per_gait_cycle_m"] for row in rows])
        ended = np.array([row[name]["fell_or_rolled"] / row[name]["episodes"] for row in rows])
        clipped = [row[name].get("gait_clipped_share") for row in rows]
        # A fall reads as metres of "climb" per cycle: clip the axis, not the story.
        shown = np.maximum(climb, CLIMB_FLOOR_CM)
        (line,) = top.plot(radii, shown, label=name)
        colour = line.get_color()
        whole = ended == 0
        top.plot(np.array(radii)[whole], shown[whole], "o", color=colour)
        top.plot(np.array(radii)[~whole], shown[~whole], "o", mfc="none", color=colour)
        middle.plot(radii, ended, marker="o", color=colour, label=name)
        if all(c is not None for c in clipped):
            bottom.plot(radii, clipped, marker="o", color=colour, label=name)
    top.axhline(0.0, color="0.6", lw=0.8)
    top.set_ylabel(f"climb per gait cycle (cm)\nhollow: some ended early; floor {CLIMB_FLOOR_CM:g}")
    middle.set_ylabel("share of episodes\nfallen or rolled")
    middle.set_ylim(-0.05, 1.05)
    bottom.set_ylabel("share of base gait's\njoint commands clipped")
    bottom.set_xlabel("pole radius (cm)")
    middle.legend(fontsize=7, loc="center right")
    save_figure(fig, path, 120, tight=True)


def main(argv: list[str] | None = None) -> list[dict]:
    plot = "with --pole-radii: climb and episodes ended against the radius"
    parser = make_parser(__doc__, plot=plot, episodes=5, workers=2, env_kwargs=True)
    parser.add_argument("--policy", type=cli.existing_dir, default=DEFAULT_POLICY)
    add_trust_pickles(parser)
    parser.add_argument(
        "--tuned-gaits", type=Path, default=DEFAULT_TUNED_GAITS, help="the tuned open-loop gaits"
    )
    parser.add_argument(
        "--tuned-key", default=None, help="entry of --tuned-gaits (default: acl or acl_noroll)"
    )
    cells = parser.add_mutually_exclusive_group()
    cells.add_argument(
        "--held-out", action="store_true", help="conditions outside the training ranges"
    )
    radii = "one cell per pole radius (m), at default friction"
    cells.add_argument("--pole-radii", type=cli.positive_float, nargs="+", metavar="R", help=radii)
    args = parser.parse_args(argv)
    if args.plot is not None and args.pole_radii is None:
        parser.error("argument --plot: draws a --pole-radii sweep; give --pole-radii")
    shared: dict[str, Any] = args.env_kwargs
    if args.pole_radii is not None and "pole_radius" in shared:
        parser.error("argument --env-kwargs: pole_radius is what --pole-radii sweeps")
    if args.held_out:
        conditions = list(HELD_OUT)
    elif args.pole_radii is not None:
        conditions = radius_conditions(args.pole_radii)
    else:
        conditions = grid_conditions()
    try:
        folder = read_policy_folder(args.policy)
    except ValueError as error:
        parser.error(f"argument --policy: {error}")
    try:  # a tuned-gaits file that is not one: refused before any episode
        _, notes = build_controllers(
            folder, shared, None, args.tuned_gaits, args.tuned_key, args.trust_pickles
        )
    except tuned_gaits.TunedGaitsError as error:
        parser.error(f"argument --tuned-gaits: {error}")
    if args.tuned_key is not None and any(n.startswith("open_loop_tuned: skipped") for n in notes):
        parser.error(f"argument --tuned-key: no {args.tuned_key!r} in {args.tuned_gaits}")
    # Every env made once, so that a bad argument is refused before any episode: --env-kwargs
    # alone first (at the env's defaults), then each cell, whose gaits' clipped shares
    # (controller name -> share, one mapping per cell) are read there.
    clipped: list[dict[str, float]] = []
    built: list[tuple[list, list[str]]] = []  # each cell's controllers and notes, checked here
    for flag, label, overrides in [
        ("--env-kwargs", "", {}),
        *(("--pole-radii", f"{label}: ", overrides) for label, overrides in conditions),
    ]:
        shares = {}
        cell = build_controllers(
            folder,
            {**shared, **overrides},
            None,
            args.tuned_gaits,
            args.tuned_key,
            args.trust_pickles,
        )
        built.append(cell)
        for controller in cell[0]:
            try:
                env = check_env_kwargs(controller.env_id, controller.env_kwargs)
            except ValueError as error:
                parser.error(f"argument {flag}: {label}{controller.name}: {error}")
            gait = getattr(env.unwrapped, "gait", None)
            if gait is not None:
                shares[controller.name] = gait.saturation.sample_fraction
            env.close()
        clipped.append(shares)
    clipped, built = clipped[1:], built[1:]  # the cells only
    seeds = list(range(args.episodes))
    rows = []
    pool = make_pool(args.workers)  # one set of workers for every cell
    for (label, overrides), shares, (controllers, notes) in zip(
        conditions, clipped, built, strict=True
    ):
        results = evaluate(controllers, seeds, progress=False, pool=pool)
        row: dict = {"condition": label, "overrides": overrides}
        for name, episodes in results.items():
            summary = summarize(episodes)
            row[name] = {column: summary[column]["mean"] for column in COLUMNS}
            row[name]["falls"] = summary["falls"]["count"]
            row[name]["rolled"] = summary["rolled"]
            row[name]["mean_steps"] = sum(e.steps for e in episodes) / len(episodes)
            row[name]["episodes"] = len(episodes)
            row[name]["fell_or_rolled"] = sum(e.fell or e.rolled for e in episodes)
            row[name]["gait_clipped_share"] = shares.get(name)
        if not rows:
            names = list(results)
            print("\n".join(note for note in notes if "skipped" in note))
            print(
                "cells: climb per gait cycle (m) / slip per metre / largest touched arc / falls"
                " (and episodes ended by rolling past roll_limit, when any)"
            )
            print("| condition | " + " | ".join(names) + " |")
            print("|---" * (1 + len(names)) + "|")
        rows.append(row)
        print(_format(row, names), flush=True)
    if pool is not None:
        pool.shutdown()
    write_output(args.json, rows)
    if args.plot:
        plot_sweep(rows, args.plot)
    return rows


def _format(row: dict, names: list[str]) -> str:
    cells = [f"| {row['condition']}"]
    for name in names:
        r = row[name]
        rolled = f" ({r['rolled']} rolled)" if r.get("rolled") else ""
        cells.append(
            f"{r['climb_per_gait_cycle_m']:.3f} / {r['slip_per_m']:.2f} / "
            f"{r['touched_arc_deg']:.0f} / {r['falls']}{rolled}"
        )
    return " | ".join(cells) + " |"


if __name__ == "__main__":
    console_script(main)()
