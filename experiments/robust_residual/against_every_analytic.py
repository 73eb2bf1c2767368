"""The robust residuals of both task versions against every analytic controller of both, cell by
cell: two ``acl-benchmark`` records of the robust grid merged into one.

``python experiments/robust_residual/against_every_analytic.py V1.json V2.json [--json PATH]``

Each record judges its policy against its own task's analytic controllers; the two tasks share
the physics, the grid and the reset seeds, and differ only in their gait and grip. Merged, each
policy meets the robust gait of both versions (``acl_sea_robust`` and ``acl_sea_robust_climb``)
and the grips tuned on them. The controllers both records play (the paper's gait, the rolling
helix) must agree episode by episode: that checks the two records played the same conditions.
"""

from __future__ import annotations

from typing import Any

from acl_env.benchmark.summary import controllers_of, limits, ratios_where_held
from acl_env.io import guarded_output, read_json
from acl_env.scripts import make_parser, write_output

SCORES = ("climb_per_gait_cycle_m", "slip_per_m", "energy_per_m")


def merge(records: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """One record of every controller of ``records`` (name -> record): each analytic controller
    named ``<name>:<controller>`` unless every record plays it alike, each policy as it is."""
    first, *others = records.values()
    for name, record in records.items():
        if record["settings"]["seeds"] != first["settings"]["seeds"]:
            raise ValueError(f"{name} played other seeds")
        if list(record["cells"]) != list(first["cells"]):
            raise ValueError(f"{name} has other cells")
    shared = set.intersection(*(set(controllers_of(r)[1]) for r in records.values()))
    shared = {c for c in shared if all(alike(first, r, c) for r in others)}
    kept = shared | {p for r in records.values() for p in controllers_of(r)[0]}  # names as they are
    cells: dict[str, Any] = {}
    for key, cell in first["cells"].items():
        merged: dict[str, Any] = {}
        for name, record in records.items():
            for controller, result in record["cells"][key]["controllers"].items():
                merged[controller if controller in kept else f"{name}:{controller}"] = result
        cells[key] = {**cell, "controllers": merged}
    return {"cells": cells}


def alike(one: dict[str, Any], other: dict[str, Any], controller: str) -> bool:
    """Whether ``controller`` played the same episodes in both records (every cell)."""
    return all(
        one["cells"][k]["controllers"][controller] == other["cells"][k]["controllers"][controller]
        for k in one["cells"]
    )


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__)
    parser.add_argument("v1", help="acl-benchmark record of ACLClimbRobust-v1's policy")
    parser.add_argument("v2", help="acl-benchmark record of ACLClimbRobust-v2's policy")
    args = parser.parse_args(argv)
    merged = merge({"v1": read_json(args.v1), "v2": read_json(args.v2)})
    policies, analytic = controllers_of(merged)
    if len(policies) != 2:
        parser.error("each record must hold one policy: the recipe's seed 0 of its version")
    result = {
        "analytic": analytic,
        "limits": limits(merged),
        "v2_over_v1": ratios_where_held(merged, policies[1:], policies[0], SCORES),
    }
    write_output(args.json, result)  # the record first: a closed pipe loses nothing
    for policy, found in result["limits"].items():
        falls = found["cells_falling_more_than_best_analytic"]
        print(
            f"{policy}: falls more often than the best of {len(analytic)} analytic controllers in "
            f"{len(falls)} cells ({', '.join(falls) or 'none'}); holds reliably in "
            f"{found['held_out_reliable_cells_held']} of {found['held_out_reliable_cells']} "
            "held-out cells where one of them does"
        )
    for score, ratio in result["v2_over_v1"].items():
        print(
            f"v2 over v1, {score}: median {ratio['median']:.3f}, higher in {ratio['higher']} of "
            f"{ratio['cells']} cells where neither falls"
        )
    return result


if __name__ == "__main__":
    with guarded_output():
        main()
