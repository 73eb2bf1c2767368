"""The robust residual's ablation, arm by arm: a table and a heat map of success per cell.

Each arm's ``acl-benchmark`` records of the same cells, side by side.

``python experiments/robust_ablation/ablation_table.py ARM=RECORD ... [--json PATH] [--plot PNG]``

Each record holds one arm's policy (one change to the robust recipe, one training seed) and its
task's analytic controllers on the same cells and reset seeds; an arm given several records (the
same ``ARM=`` again) is summarised over its training seeds. Per arm: the share of successful
episodes over the cells and over the held-out ones (mean over seeds, and each seed's), the cells
where a seed falls more often than the best analytic controller, and the climb and slip per
metre at the nominal condition (mean over seeds).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from acl_env.benchmark.summary import controllers_of, limits
from acl_env.io import guarded_output, read_json
from acl_env.pretrained import is_pretrained, read_metadata
from acl_env.scripts import make_parser, write_output


def arm_row(record: dict[str, Any]) -> dict[str, Any]:
    """One arm's scores from its record (its single policy against its analytic controllers)."""
    (policy,), _ = controllers_of(record)
    cells = record["cells"]
    rates = {key: cell["controllers"][policy]["success_rate"] for key, cell in cells.items()}
    held = [rates[key] for key, cell in cells.items() if cell["held_out"]]
    nominal = cells["nominal"]["controllers"][policy] if "nominal" in cells else None
    return {
        "training_seed": training_seed(record),
        "success_per_cell": rates,
        "success": float(np.mean(list(rates.values()))),
        "success_held_out": float(np.mean(held)) if held else None,
        "cells_falling_more_than_best_analytic": limits(record)[policy][
            "cells_falling_more_than_best_analytic"
        ],
        "nominal_climb_per_gait_cycle_m": nominal and nominal["climb_per_gait_cycle_m"]["mean"],
        "nominal_slip_per_m": nominal and nominal["slip_per_m"]["mean"],
    }


def training_seed(record: dict[str, Any]) -> int | None:
    """The training seed of the record's policy, from its exported folder's ``policy.json``
    (None where the folder is not here, or did not record one)."""
    folder = Path(record["settings"]["policies"][0])
    if not is_pretrained(folder):
        return None
    return (read_metadata(folder).get("training") or {}).get("seed")


SHORT = {
    "pole_radius": "pole",
    "friction": "mu",
    "spring_stiffness": "k",
    "control_latency": "delay",
}


def short(cell: str) -> str:
    """A cell's key as a tick label: short axis names, one condition per line."""
    for name, abbreviation in SHORT.items():
        cell = cell.replace(f"{name}=", f"{abbreviation} ")
    return cell.replace(",", "\n").replace("_", " ")


def arm_summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """One arm over its training seeds (:func:`arm_row` each, in the order given)."""

    def mean(key: str) -> float | None:
        values = [row[key] for row in rows]
        return None if None in values else float(np.mean(values))

    return {
        "seeds": len(rows),
        "success": mean("success"),
        "success_per_seed": [row["success"] for row in rows],
        "success_held_out": mean("success_held_out"),
        "cells_falling_per_seed": [row["cells_falling_more_than_best_analytic"] for row in rows],
        "nominal_climb_per_gait_cycle_m": mean("nominal_climb_per_gait_cycle_m"),
        "nominal_slip_per_m": mean("nominal_slip_per_m"),
        "per_seed": rows,
    }


def seed_label(row: dict[str, Any], index: int) -> str:
    """A row's training seed, or its place among the arm's records where the seed is unknown."""
    seed = row.get("training_seed")
    return f"#{index + 1}" if seed is None else f"seed {seed}"


def plot_arms(document: dict[str, Any], path: Path) -> None:
    """Success per arm and training seed (rows) and cell (columns), the rate in each square."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [
        (name if arm["seeds"] == 1 else f"{name}, {seed_label(row, i)}", row)
        for name, arm in document["arms"].items()
        for i, row in enumerate(arm["per_seed"])
    ]
    arms = [name for name, _ in rows]
    cells = list(rows[0][1]["success_per_cell"])
    grid = np.array([[row["success_per_cell"][c] for c in cells] for _, row in rows])
    fig, ax = plt.subplots(figsize=(1.0 + 0.75 * len(cells), 1.2 + 0.45 * len(arms)))
    ax.imshow(grid, vmin=0.0, vmax=1.0, cmap="viridis", aspect="auto")
    for (row, col), value in np.ndenumerate(grid):
        ax.text(col, row, f"{100 * value:.0f}", ha="center", va="center", fontsize=7,
                color="white" if value < 0.5 else "black")  # fmt: skip
    ax.set_xticks(range(len(cells)), [short(c) for c in cells], fontsize=6)
    ax.set_yticks(range(len(arms)), arms, fontsize=8)
    ax.set_title("robust residual ablation: success rate per cell (%)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__)
    parser.add_argument("arms", nargs="+", metavar="ARM=RECORD", help="an arm and its record")
    parser.add_argument("--plot", type=Path, help="the heat map of success per arm and cell")
    args = parser.parse_args(argv)
    records: dict[str, list[dict[str, Any]]] = {}
    for item in args.arms:
        name, _, path = item.partition("=")
        if not name or not path:
            parser.error(f"arms are ARM=RECORD, not {item!r}")
        records.setdefault(name, []).append(read_json(path))
    first = next(iter(records.values()))[0]
    for name, record in ((n, r) for n, rs in records.items() for r in rs):
        if list(record["cells"]) != list(first["cells"]):
            parser.error(f"{name}'s record has other cells than the first arm's")
        if record["settings"]["seeds"] != first["settings"]["seeds"]:
            parser.error(f"{name}'s record played other seeds than the first arm's")
    document = {"seeds": first["settings"]["seeds"], "arms": {}}
    for name, arm in records.items():
        document["arms"][name] = arm_summary([arm_row(record) for record in arm])
    write_output(args.json, document)  # the record first: a closed pipe loses nothing
    if args.plot is not None:
        plot_arms(document, args.plot)
        print(f"wrote {args.plot}")
    print(
        "arm (seeds): success (held out) | cells falling more than the best analytic, per seed | "
        "nominal climb, slip"
    )
    for name, row in document["arms"].items():
        held = row["success_held_out"]
        climb, slip = row["nominal_climb_per_gait_cycle_m"], row["nominal_slip_per_m"]
        falls = ", ".join(str(len(cells)) for cells in row["cells_falling_per_seed"])
        print(
            f"{name} ({row['seeds']}): {row['success']:.2f} "
            f"({'-' if held is None else f'{held:.2f}'}) | {falls} | "
            f"{'-' if climb is None else f'{100 * climb:.2f} cm'}, "
            f"{'-' if slip is None else f'{slip:.3f}'}"
        )
    return document


if __name__ == "__main__":
    with guarded_output():
        main()
