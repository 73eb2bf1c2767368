"""Is the policy no worse than open loop across the randomisation range? Pole radius x friction.

``python benchmarks/policy_robustness.py [--policy DIR] [--episodes 5] [--json PATH]`` evaluates
the controllers of ``train/evaluate.py`` (:mod:`acl_env.training.evaluate`: the policy, open-loop
ACL, at the policy's cadence, rolling helix, tuned gait; same seeds for all) at the corners and
centre of the training ranges of pole radius and friction, and prints the climb per cycle, slip
per cycle and falls of each.
"""

from __future__ import annotations

import argparse
import itertools
import json
from pathlib import Path

from acl_env.evaluation import summarize
from acl_env.training.evaluate import (
    DEFAULT_POLICY,
    DEFAULT_TUNED_GAITS,
    build_controllers,
    evaluate,
    make_pool,
)
from acl_env.training.policy import read_policy_folder

POLE_RADII = (0.065, 0.075, 0.09)
FRICTIONS = (0.7, 1.0, 1.2)
COLUMNS = ("climb_per_cycle_m", "slip_per_cycle_m")


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policy", default=str(DEFAULT_POLICY))
    parser.add_argument("--episodes", type=int, default=5)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json", help="write the rows to this JSON file")
    args = parser.parse_args(argv)
    folder = read_policy_folder(args.policy)
    seeds = list(range(args.episodes))
    rows = []
    pool = make_pool(args.workers)  # one set of workers for every cell
    for radius, friction in itertools.product(POLE_RADII, FRICTIONS):
        overrides = {"pole_radius": radius, "friction": friction}
        controllers, notes = build_controllers(folder, overrides, None, DEFAULT_TUNED_GAITS)
        results = evaluate(controllers, seeds, progress=False, pool=pool)
        row: dict = {"pole_radius": radius, "friction": friction}
        for name, episodes in results.items():
            summary = summarize(episodes)
            row[name] = {column: summary[column]["mean"] for column in COLUMNS}
            row[name]["falls"] = summary["falls"]["count"]
        if not rows:
            names = list(results)
            print("\n".join(note for note in notes if "skipped" in note))
            print("| pole radius (m) | friction | " + " | ".join(names) + " |")
            print("|---" * (2 + len(names)) + "|")
        rows.append(row)
        print(_format(row, names), flush=True)
    if pool is not None:
        pool.shutdown()
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2) + "\n")
    return rows


def _format(row: dict, names: list[str]) -> str:
    cells = [f"| {row['pole_radius']:.3f} | {row['friction']:.1f}"]
    for name in names:
        r = row[name]
        cells.append(f"{r['climb_per_cycle_m']:.3f} / {r['slip_per_cycle_m']:.3f} / {r['falls']}")
    return " | ".join(cells) + " |"


if __name__ == "__main__":
    main()
