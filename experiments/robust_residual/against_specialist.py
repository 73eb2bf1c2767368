"""The robust residual against the shipped specialist at the nominal condition: both tasks'
``acl-evaluate`` records on the same reset seeds, paired episode by episode.

``python experiments/robust_residual/against_specialist.py ROBUST.json SPECIALIST.json``
``[--json PATH]``

``acl-compare`` pairs two recipes of one task; these are two tasks (``ACLClimbRobust-v1`` and
``ACLClimb-v3``) on the same physics, the nominal pole, friction and springs, but with different
base gaits, so the same seed starts each from its own gait's pose.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from acl_env.evaluation.intervals import mean_ci95
from acl_env.io import guarded_output, read_json
from acl_env.scripts import make_parser, write_output

METRICS = ("climb_per_gait_cycle_m", "slip_per_m", "energy_per_m", "climb_speed_cm_s")


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__)
    parser.add_argument("robust", help="acl-evaluate record of the robust residual")
    parser.add_argument("specialist", help="acl-evaluate record of the specialist")
    args = parser.parse_args(argv)
    records = [read_json(path)["controllers"] for path in (args.robust, args.specialist)]
    if not all("policy" in r for r in records):
        parser.error("both records must evaluate a policy (acl-evaluate --policy ...)")
    robust, specialist = (r["policy"] for r in records)
    if robust["seeds"] != specialist["seeds"]:
        parser.error(f"{args.robust} and {args.specialist} ran on other seeds: nothing to pair")
    document: dict[str, Any] = {"seeds": robust["seeds"], "metrics": {}}
    for metric in METRICS:
        a, b = (np.array(r[metric]["values"], dtype=float) for r in (robust, specialist))
        ratio = mean_ci95(a / b)
        document["metrics"][metric] = {
            "robust": float(a.mean()),
            "specialist": float(b.mean()),
            "ratio": ratio["mean"],
            "ratio_half_width": ratio["half_width"],
        }
    write_output(args.json, document)  # the record first: a closed pipe loses nothing
    print(f"{len(robust['seeds'])} episodes, robust / specialist (ratio: mean ± 95 % CI)")
    for metric, row in document["metrics"].items():
        print(
            f"  {metric:24s} {row['robust']:9.4f} / {row['specialist']:9.4f}: "
            f"ratio {row['ratio']:.3f} ± {row['ratio_half_width']:.3f}"
        )
    return document


if __name__ == "__main__":
    with guarded_output():
        main()
