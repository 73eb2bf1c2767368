"""Open-loop climbing: climb and slip per cycle of ACL, rolling helix and non-rolling ACL.

``python benchmarks/open_loop.py [--seeds 5] [--json PATH]``: zero-action rollouts of two cycles
at default settings, one per reset seed; prints mean and standard deviation per gait.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "train"))
import evaluate  # train/ is a script folder, not a package
from common import make_env

GAITS: dict[str, tuple[str, dict[str, Any]]] = {
    "ACL (1 roll/cycle)": ("acl_env/ACLClimb-v0", {}),
    "rolling helix": ("acl_env/RollingHelixClimb-v0", {}),
    "ACL, non-rolling": ("acl_env/ACLClimb-v0", {"gait_kwargs": {"rolls_per_cycle": 0}}),
}


def rollout(env_id: str, kwargs: dict[str, Any], seed: int) -> dict[str, float]:
    """Climb and slip per cycle (m) and the fall flag of one zero-action episode."""
    env = make_env(env_id, kwargs)
    metrics = evaluate.run_episode(env, evaluate.zero_actor(env), seed).metrics()
    return {
        "climb": metrics["climb_per_cycle_m"],
        "slip": metrics["slip_per_cycle_m"],
        "fell": metrics["falls"],
    }


def main(argv: list[str] | None = None) -> dict[str, dict[str, float]]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--json", help="write the table to this JSON file")
    args = parser.parse_args(argv)
    table = {}
    for name, (env_id, kwargs) in GAITS.items():
        runs = [
            rollout(env_id, kwargs, seed)
            for seed in tqdm(range(args.seeds), desc=name, leave=False)
        ]
        table[name] = {
            "climb_per_cycle_m": float(np.mean([r["climb"] for r in runs])),
            "climb_std_m": float(np.std([r["climb"] for r in runs], ddof=1)),
            "slip_per_cycle_m": float(np.mean([r["slip"] for r in runs])),
            "slip_std_m": float(np.std([r["slip"] for r in runs], ddof=1)),
            "falls": int(sum(r["fell"] for r in runs)),
            "n": args.seeds,
        }
    print("| gait | climb per cycle (m) | slip per cycle (m) | falls |")
    print("|---|---|---|---|")
    for name, row in table.items():
        print(
            f"| {name} | {row['climb_per_cycle_m']:.3f} ± {row['climb_std_m']:.3f} "
            f"| {row['slip_per_cycle_m']:.3f} ± {row['slip_std_m']:.3f} "
            f"| {row['falls']}/{row['n']} |"
        )
    if args.json:
        with open(args.json, "w") as f:
            json.dump(table, f, indent=2)
    return table


if __name__ == "__main__":
    main()
