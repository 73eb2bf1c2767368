"""Is the tuned gait's grip already where it should be? Fixed per-section squeeze patterns.

``python experiments/residual_limits/grip_patterns.py [--seeds 3] [--scale 0.003] [--tuned-gaits
FILE] [--json PATH]``: the tuned open-loop ACL gait (``acl`` of the shipped tuned gaits,
:mod:`acl_env.tuned_gaits`, or of ``--tuned-gaits``) with a constant gait-modulation
action (:mod:`acl_env.envs.modulation`): the squeeze offset by ``+-scale`` in some of the four body
sections (head first), the authority the grip ablation's policy had. Two cycles per reset seed at
default conditions, under the reward weights the gait was tuned for. Prints each pattern's climb per
gait cycle, slip and energy per metre and reward per gait cycle, as ratios to the tuned gait. A
pattern above 1 in reward would be a grip the tuner's family (one squeeze for the whole body)
cannot express and a policy could learn by holding it.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import gymnasium
import numpy as np
from tqdm import tqdm

from acl_env import ACL_CLIMB_ID, tuned_gaits
from acl_env.evaluation import run_episode
from acl_env.io import console_script
from acl_env.scripts import make_parser, write_output

# Section offsets in units of --scale, head first: one section, the whole body, ends against
# middle, front against back.
PATTERNS: tuple[tuple[int, int, int, int], ...] = (
    (0, 0, 0, 0),
    (1, 0, 0, 0),
    (0, 0, 0, 1),
    (1, 1, 1, 1),
    (-1, -1, -1, -1),
    (1, -1, -1, 1),
    (-1, 1, 1, -1),
    (1, 1, -1, -1),
    (-1, -1, 1, 1),
    (0, -1, -1, 0),
    (-1, 0, 0, -1),
)
COLUMNS = ("climb_per_gait_cycle_m", "slip_per_m", "energy_per_m", "reward_per_gait_cycle")


def constant(action: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """The policy that always plays ``action``."""
    return lambda obs: action


def main(argv: list[str] | None = None) -> dict[str, dict[str, float]]:
    parser = make_parser(__doc__)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--scale", type=float, default=0.003, help="squeeze offset (m)")
    parser.add_argument(
        "--tuned-gaits",
        type=Path,
        help="tuned-gaits file whose 'acl' gait is played (default: the shipped tuned gaits)",
    )
    args = parser.parse_args(argv)
    if args.seeds < 1:
        parser.error("--seeds must be at least 1")
    try:
        tuned = tuned_gaits.entry("acl", args.tuned_gaits)
    except tuned_gaits.TunedGaitsError as error:
        parser.error(f"argument --tuned-gaits: {error}")
    env = gymnasium.make(
        ACL_CLIMB_ID,
        **tuned["env_kwargs"],
        reward_weights=tuned["reward_weights"],
        gait_modulation={"squeeze": args.scale},
    )
    n_joints = env.unwrapped.n_joints
    table: dict[str, dict[str, float]] = {}
    for pattern in tqdm(PATTERNS, leave=False):
        action = np.zeros(env.action_space.shape, dtype=np.float32)
        action[n_joints:] = pattern
        hold = constant(action)
        runs = [run_episode(env, hold, seed).metrics() for seed in range(args.seeds)]
        row = {column: float(np.mean([r[column] for r in runs])) for column in COLUMNS}
        row["falls"] = float(sum(r["falls"] for r in runs))
        table[str(pattern)] = row
    env.close()
    base = table[str(PATTERNS[0])]
    print(f"tuned gait, squeeze offsets of {1000 * args.scale:.1f} mm per section (head first);")
    print(f"ratios to the tuned gait, {args.seeds} seeds x 2 cycles")
    print("| sections | climb / gait cycle | slip / m | energy / m | reward / gait cycle | falls |")
    print("|---|---|---|---|---|---|")
    for name, row in table.items():
        ratios = " | ".join(f"{row[c] / base[c]:.3f}" for c in COLUMNS)
        print(f"| {name} | {ratios} | {row['falls']:.0f} |")
    write_output(args.json, table)
    return table


if __name__ == "__main__":
    console_script(main)()
