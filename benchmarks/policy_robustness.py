"""Is the policy no worse than open loop across the randomisation range? Pole radius x friction.

``python benchmarks/policy_robustness.py [--policy DIR] [--episodes 5] [--held-out] [--json PATH]
[--tuned-gaits FILE] [--tuned-key KEY]`` evaluates the controllers of ``train/evaluate.py``
(:mod:`acl_env.training.evaluate`: the policy, open-loop ACL, at the policy's cadence, rolling
helix, tuned gait from ``--tuned-gaits``, entry ``--tuned-key``; same seeds for all) at the
corners and centre of the training ranges of pole radius and friction, or with ``--held-out`` under
conditions outside the training ranges (``HELD_OUT``), and prints the climb per gait cycle, slip
per metre, largest touched arc, falls and (in the JSON) episodes ended by rolling and mean
episode length of each.
"""

from __future__ import annotations

import itertools
from pathlib import Path

from acl_env.evaluation import summarize
from acl_env.training import cli
from acl_env.training.evaluate import (
    DEFAULT_POLICY,
    DEFAULT_TUNED_GAITS,
    TunedGaitsError,
    build_controllers,
    evaluate,
    make_pool,
)
from acl_env.training.policy import read_policy_folder
from acl_env.training.runs import write_json

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


def main(argv: list[str] | None = None) -> list[dict]:
    parser = cli.ArgumentParser(prog="policy_robustness.py", description=__doc__.splitlines()[0])
    parser.add_argument("--policy", type=cli.existing_dir, default=DEFAULT_POLICY)
    parser.add_argument("--episodes", type=cli.int_at_least(1), default=5)
    parser.add_argument("--workers", type=cli.int_at_least(1), default=2)
    parser.add_argument(
        "--tuned-gaits", type=Path, default=DEFAULT_TUNED_GAITS, help="the tuned open-loop gaits"
    )
    parser.add_argument(
        "--tuned-key", default=None, help="entry of --tuned-gaits (default: acl or acl_noroll)"
    )
    parser.add_argument(
        "--held-out", action="store_true", help="conditions outside the training ranges"
    )
    parser.add_argument(
        "--json", type=cli.output_file(".json"), help="write the rows to this JSON file"
    )
    args = parser.parse_args(argv)
    conditions = list(HELD_OUT) if args.held_out else grid_conditions()
    try:
        folder = read_policy_folder(args.policy)
    except ValueError as error:
        parser.error(f"argument --policy: {error}")
    try:  # a tuned-gaits file that is not one: refused before any episode
        _, notes = build_controllers(folder, {}, None, args.tuned_gaits, args.tuned_key)
    except TunedGaitsError as error:
        parser.error(f"argument --tuned-gaits: {error}")
    if args.tuned_key is not None and any(n.startswith("open_loop_tuned: skipped") for n in notes):
        parser.error(f"argument --tuned-key: no {args.tuned_key!r} in {args.tuned_gaits}")
    seeds = list(range(args.episodes))
    rows = []
    pool = make_pool(args.workers)  # one set of workers for every cell
    for label, overrides in conditions:
        controllers, notes = build_controllers(
            folder, overrides, None, args.tuned_gaits, args.tuned_key
        )
        results = evaluate(controllers, seeds, progress=False, pool=pool)
        row: dict = {"condition": label, "overrides": overrides}
        for name, episodes in results.items():
            summary = summarize(episodes)
            row[name] = {column: summary[column]["mean"] for column in COLUMNS}
            row[name]["falls"] = summary["falls"]["count"]
            row[name]["rolled"] = summary["rolled"]
            row[name]["mean_steps"] = sum(e.steps for e in episodes) / len(episodes)
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
    if args.json:
        write_json(args.json, rows)
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
    main()
