"""Open-loop climbing: climb, slip and touched arc of ACL, rolling helix and non-rolling ACL.

``python benchmarks/open_loop.py [--seeds 5] [--json PATH]``: zero-action rollouts of two cycles
at default settings, one per reset seed (:func:`acl_env.evaluation.run_episode`); prints the mean
and standard deviation per gait of the climb and slip per cycle, and the largest touched arc of
any module (:mod:`acl_env.evaluation`).
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from tqdm import tqdm

from acl_env import ACL_CLIMB_ID, ROLLING_HELIX_CLIMB_ID, cli
from acl_env.evaluation import run_episode, zero_policy
from acl_env.io import console_script
from acl_env.scripts import make_parser, write_output

GAITS: dict[str, tuple[str, dict[str, Any]]] = {
    "ACL (1 roll/cycle)": (ACL_CLIMB_ID, {}),
    "rolling helix": (ROLLING_HELIX_CLIMB_ID, {}),
    "ACL, non-rolling": (ACL_CLIMB_ID, {"gait_kwargs": {"rolls_per_cycle": 0}}),
}
COLUMNS = ("climb_per_cycle_m", "slip_per_cycle_m", "touched_arc_deg")


def main(argv: list[str] | None = None) -> dict[str, dict[str, float]]:
    parser = make_parser(__doc__)
    # a standard deviation needs two
    parser.add_argument("--seeds", type=cli.int_at_least(2), default=5, help="episodes per gait")
    args = parser.parse_args(argv)
    table = {}
    for name, (env_id, kwargs) in GAITS.items():
        env = gymnasium.make(env_id, **kwargs)
        runs = [
            run_episode(env, zero_policy(env), seed).metrics()
            for seed in tqdm(range(args.seeds), desc=name, leave=False)
        ]
        env.close()
        row: dict[str, float] = {}
        for column in COLUMNS:
            values = [r[column] for r in runs]
            row[column] = float(np.mean(values))
            row[f"{column}_std"] = float(np.std(values, ddof=1))
        row |= {"falls": int(sum(r["falls"] for r in runs)), "n": args.seeds}
        table[name] = row
    print("| gait | climb per cycle (m) | slip per cycle (m) | touched arc (deg) | falls |")
    print("|---|---|---|---|---|")
    for name, row in table.items():
        print(
            f"| {name} | {row['climb_per_cycle_m']:.3f} ± {row['climb_per_cycle_m_std']:.3f} "
            f"| {row['slip_per_cycle_m']:.3f} ± {row['slip_per_cycle_m_std']:.3f} "
            f"| {row['touched_arc_deg']:.0f} ± {row['touched_arc_deg_std']:.0f} "
            f"| {row['falls']}/{row['n']} |"
        )
    write_output(args.json, table)
    return table


if __name__ == "__main__":
    console_script(main)()
