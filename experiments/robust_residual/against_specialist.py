"""The robust residual against the shipped specialist at the nominal condition: both tasks'
``acl-evaluate`` records on the same reset seeds, paired episode by episode.

``python experiments/robust_residual/against_specialist.py ROBUST.json SPECIALIST.json``

``acl-compare`` pairs two recipes of one task; these are two tasks (``ACLClimbRobust-v1`` and
``ACLClimb-v3``) on the same physics, the nominal pole, friction and springs, but with different
base gaits, so the same seed starts each from its own gait's pose.
"""

from __future__ import annotations

import sys

import numpy as np

from acl_env.evaluation.intervals import mean_ci95
from acl_env.io import read_json

METRICS = ("climb_per_gait_cycle_m", "slip_per_m", "energy_per_m", "climb_speed_cm_s")


def main(argv: list[str]) -> None:
    robust, specialist = (read_json(path)["controllers"]["policy"] for path in argv)
    assert robust["seeds"] == specialist["seeds"], "the records ran on other seeds"
    print(f"{len(robust['seeds'])} episodes, robust / specialist (mean ± 95 % CI of the pair)")
    for metric in METRICS:
        a, b = (np.array(r[metric]["values"], dtype=float) for r in (robust, specialist))
        ratio = mean_ci95(a / b)
        print(
            f"  {metric:24s} {a.mean():9.4f} / {b.mean():9.4f}: "
            f"ratio {ratio['mean']:.3f} ± {ratio['half_width']:.3f}"
        )


if __name__ == "__main__":
    main(sys.argv[1:])
