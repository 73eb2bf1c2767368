"""What the SEA costs the non-rolling gait: acl_noroll open loop on the servo and on the SEA with
one of its parts changed at a time.

``python experiments/sea_actuators/noroll_speed_limit.py [--seeds 6] [--json PATH]``

Zero-action episodes of two cycles on ``ACLClimbNoRoll-v3`` (the servo task's gait and reward) on
reset seeds 3, 4, ...: climb per gait cycle, the largest touched arc of any episode, how many
ended rolled (past the 90 deg limit), and the share of joint torques at the 7 N m limit.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from acl_env import ACL_CLIMB_NOROLL_ID
from acl_env.evaluation import run_episode, zero_policy
from acl_env.io import console_script
from acl_env.scripts import make_parser, write_output

VARIANTS: dict[str, dict[str, Any]] = {
    "servo": {},
    "SEA (defaults)": {"actuator_model": "sea"},
    "SEA, motor 20 rad/s": {"actuator_model": "sea", "motor_speed_limit": 20.0},
    "SEA, no latency": {"actuator_model": "sea", "control_latency": 0.0, "sensor_latency": 0.0},
    "SEA, spring 40 N m/rad": {"actuator_model": "sea", "spring_stiffness": 40.0},
    # The same gait played slower: 275 and 330 keyframes per cycle (climb still per gait cycle).
    "SEA, 1.25x slower": {"actuator_model": "sea", "steps_per_cycle": 275},
    "SEA, 1.5x slower": {"actuator_model": "sea", "steps_per_cycle": 330},
}


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__)
    parser.add_argument("--seeds", type=int, default=6, help="episodes per variant")
    args = parser.parse_args(argv)
    table = {}
    print("| variant | climb per gait cycle (cm) | largest arc (deg) | rolled | at 7 N m |")
    print("|---|---|---|---|---|")
    for name, kwargs in VARIANTS.items():
        env = gym.make(ACL_CLIMB_NOROLL_ID, **kwargs)
        episodes = [run_episode(env, zero_policy(env), seed) for seed in range(3, 3 + args.seeds)]
        env.close()
        metrics = [e.metrics() for e in episodes]
        row = {
            "climb_per_gait_cycle_m": float(np.mean([m["climb_per_cycle_m"] for m in metrics])),
            "touched_arc_deg": float(max(m["touched_arc_deg"] for m in metrics)),
            "rolled": int(sum(e.rolled for e in episodes)),
            "torque_limit_fraction": float(np.mean([m["torque_limit_fraction"] for m in metrics])),
        }
        table[name] = row
        print(
            f"| {name} | {100 * row['climb_per_gait_cycle_m']:.2f} | {row['touched_arc_deg']:.0f}"
            f" | {row['rolled']}/{args.seeds} | {100 * row['torque_limit_fraction']:.1f} % |"
        )
    write_output(args.json, table)
    return table


if __name__ == "__main__":
    console_script(main)()
