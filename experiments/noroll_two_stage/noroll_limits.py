"""Where the non-rolling gait's grip gives way: open-loop sweeps around the tuned gait.

``python experiments/noroll_two_stage/noroll_limits.py [--seeds 3] [--json PATH]``: zero-action
episodes (two cycles, one per reset seed, :func:`acl_env.evaluation.run_episode`) of
``acl_env/ACLClimbNoRoll-v2`` with one or two of its gait parameters changed from its registered
values (``NOROLL_V2_KWARGS``, the gait v3 replaced once a rerun of its study found larger waves
climbing further): larger axial waves (A_p), a tighter helix (squeeze), a longer pitch, a third wave
(Omega = 3). Prints climb and slip per gait cycle, the largest touched arc and the falls or
roll-limit ends of each. The question it answers: does inching further per cycle only need larger
waves, or does the grip fail first?
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from tqdm import tqdm

from acl_env import ACL_CLIMB_NOROLL_V2_ID, NOROLL_V2_KWARGS, cli
from acl_env.evaluation import run_episode, zero_policy
from acl_env.io import console_script
from acl_env.scripts import make_parser, write_output

TUNED_GAIT: dict[str, Any] = dict(NOROLL_V2_KWARGS["gait_kwargs"])
TUNED_SQUEEZE = float(NOROLL_V2_KWARGS["squeeze"])
# label -> (gait_kwargs changes, squeeze or None for the tuned one)
VARIANTS: dict[str, tuple[dict[str, Any], float | None]] = {
    "tuned (A_p 2.9 cm, squeeze 1.6 cm)": ({}, None),
    "A_p 3.3 cm": ({"amp_pitch": 0.033}, None),
    "A_p 3.7 cm": ({"amp_pitch": 0.037}, None),
    "A_p 3.7 cm, squeeze 2.0 cm": ({"amp_pitch": 0.037}, 0.020),
    "A_p 3.7 cm, squeeze 2.5 cm": ({"amp_pitch": 0.037}, 0.025),
    "A_p 3.7 cm, A_r 1.5 cm": ({"amp_pitch": 0.037, "amp_radial": 0.015}, None),
    "A_p 4 cm, pitch 12 cm": ({"amp_pitch": 0.04, "pitch": 0.12}, None),
    "Omega 3": ({"spatial_freq": 3}, None),
    "Omega 3, A_p 2.2 cm": ({"spatial_freq": 3, "amp_pitch": 0.022}, None),
}


def main(argv: list[str] | None = None) -> dict[str, dict[str, float]]:
    parser = make_parser(__doc__)
    parser.add_argument("--seeds", type=cli.int_at_least(1), default=3, help="episodes per variant")
    args = parser.parse_args(argv)
    table: dict[str, dict[str, float]] = {}
    for label, (changes, squeeze) in VARIANTS.items():
        kwargs: dict[str, Any] = {"gait_kwargs": {**TUNED_GAIT, **changes}}
        kwargs["squeeze"] = TUNED_SQUEEZE if squeeze is None else squeeze
        env = gymnasium.make(ACL_CLIMB_NOROLL_V2_ID, **kwargs)
        ended = 0
        runs = []
        for seed in tqdm(range(args.seeds), desc=label, leave=False):
            episode = run_episode(env, zero_policy(env), seed)
            runs.append(episode.metrics())
            ended += int(episode.steps < env.unwrapped.steps_per_cycle * 2)
        env.close()
        climb = [r["climb_per_gait_cycle_m"] for r in runs]
        slip = [r["slip_per_cycle_m"] for r in runs]  # no cadence: nominal = gait cycles
        table[label] = {
            "climb_per_gait_cycle_cm": 100 * float(np.mean(climb)),
            "slip_per_gait_cycle_cm": 100 * float(np.mean(slip)),
            "touched_arc_deg": float(np.max([r["touched_arc_deg"] for r in runs])),
            "ended_early": ended,
            "n": args.seeds,
        }
    print(
        "| open loop | climb / gait cycle (cm) | slip / gait cycle (cm) "
        "| largest touched arc (deg) | ended early (fell or rolled) |"
    )
    print("|---|---|---|---|---|")
    for label, row in table.items():
        print(
            f"| {label} | {row['climb_per_gait_cycle_cm']:.1f} "
            f"| {row['slip_per_gait_cycle_cm']:.1f} | {row['touched_arc_deg']:.0f} "
            f"| {row['ended_early']}/{row['n']} |"
        )
    write_output(args.json, table)
    return table


if __name__ == "__main__":
    console_script(main)()
