"""Is the policy no worse than open loop across the randomisation range? Pole radius x friction.

``python benchmarks/policy_robustness.py [--policy DIR] [--episodes 5] [--json PATH]`` runs
``train/evaluate.py`` (same seeds for every controller) at the corners and centre of the training
ranges of pole radius and friction and prints climb and slip per cycle and falls per controller.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import itertools
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "train"))
import evaluate  # train/ is a script folder, not a package

POLE_RADII = (0.065, 0.075, 0.09)
FRICTIONS = (0.7, 1.0, 1.2)
CONTROLLERS = ("policy", "open_loop_acl", "open_loop_rolling_helix")


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policy", default=str(evaluate.DEFAULT_POLICY))
    parser.add_argument("--episodes", type=int, default=5)
    parser.add_argument("--json", help="write the rows to this JSON file")
    args = parser.parse_args(argv)
    rows = []
    for radius, friction in itertools.product(POLE_RADII, FRICTIONS):
        with contextlib.redirect_stdout(io.StringIO()):  # evaluate prints its own table
            doc = evaluate.main(
                [
                    "--policy",
                    args.policy,
                    "--episodes",
                    str(args.episodes),
                    "--no-progress-bar",
                    "--env-kwargs",
                    f"pole_radius:{radius}",
                    f"friction:{friction}",
                ]
            )
        row = {"pole_radius": radius, "friction": friction}
        for name in CONTROLLERS:
            summary = doc["controllers"][name]
            row[name] = {
                "climb_per_cycle_m": summary["climb_per_cycle_m"]["mean"],
                "slip_per_cycle_m": summary["slip_per_cycle_m"]["mean"],
                "falls": summary["falls"]["count"],
            }
        rows.append(row)
        print(_format(row), flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2) + "\n")
    return rows


def _format(row: dict) -> str:
    cells = [f"| {row['pole_radius']:.3f} | {row['friction']:.1f}"]
    for name in CONTROLLERS:
        r = row[name]
        cells.append(f"{r['climb_per_cycle_m']:.3f} / {r['slip_per_cycle_m']:.3f} / {r['falls']}")
    return " | ".join(cells) + " |"


if __name__ == "__main__":
    print("| pole radius (m) | friction | policy | open-loop ACL | open-loop rolling helix |")
    print("|---|---|---|---|---|")
    main()
