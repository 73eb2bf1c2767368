"""A recipe's training seeds against other controllers of the robust grid, cell by cell.

``python experiments/robust_residual/seeds_against.py SEEDS.json OTHER.json [--json PATH]``

``SEEDS.json`` is an ``acl-benchmark`` record of one recipe's seeds (ACLClimbRobust-v3's five);
``OTHER.json`` another record on the same grid and reset seeds (ACLClimbRobust-v1's, whose plain
critic's residual it is judged against). Against each controller of the first record and each
policy of the other (named ``other:<name>``), per score: the median over cells of the seeds'
mean over the controller's, and in how many cells it is higher, over the cells where no seed and
not the controller falls in any episode.
"""

from __future__ import annotations

from typing import Any

from acl_env.benchmark.summary import controllers_of, ratios_where_held
from acl_env.io import guarded_output, read_json
from acl_env.scripts import make_parser, write_output

SCORES = ("climb_per_gait_cycle_m", "slip_per_m", "energy_per_m")


def merge(seeds: dict[str, Any], other: dict[str, Any]) -> dict[str, Any]:
    """``seeds``' cells with ``other``'s policies added as ``other:<name>``: the same grid and
    reset seeds, or ``ValueError``."""
    if other["settings"]["seeds"] != seeds["settings"]["seeds"]:
        raise ValueError("the records played other reset seeds")
    if list(other["cells"]) != list(seeds["cells"]):
        raise ValueError("the records have other cells")
    policies = controllers_of(other)[0]
    cells = {}
    for key, cell in seeds["cells"].items():
        theirs = {f"other:{n}": other["cells"][key]["controllers"][n] for n in policies}
        cells[key] = {**cell, "controllers": {**cell["controllers"], **theirs}}
    return {"cells": cells}


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__)
    parser.add_argument("seeds", help="acl-benchmark record of one recipe's training seeds")
    parser.add_argument("other", help="acl-benchmark record of another task on the same grid")
    args = parser.parse_args(argv)
    mine, other = read_json(args.seeds), read_json(args.other)
    try:
        merged = merge(mine, other)
    except ValueError as error:
        parser.error(f"argument other: {error}")
    seeds = controllers_of(mine)[0]
    names = list(merged["cells"]["nominal"]["controllers"])
    result = {
        "seeds": seeds,
        "against": {
            name: ratios_where_held(merged, seeds, name, SCORES)
            for name in names
            if name not in seeds
        },
    }
    write_output(args.json, result)  # the record first: a closed pipe loses nothing
    for name, scores in result["against"].items():
        shown = ", ".join(
            f"{score} {found['median']:.2f}x (higher in {found['higher']} of {found['cells']})"
            for score, found in scores.items()
        )
        print(f"seeds over {name}: {shown}")
    return result


if __name__ == "__main__":
    with guarded_output():
        main()
