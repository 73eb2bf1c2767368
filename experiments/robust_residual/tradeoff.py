"""What holding the whole grid costs at the nominal condition, controller by controller.

Every controller of several ``acl-benchmark`` records: its success over the cells they share,
against its climb and slip in their nominal cell.

``python experiments/robust_residual/tradeoff.py NAME=RECORD ... [--json PATH] [--plot PNG]``

Each record's policies and analytic controllers become points named ``NAME: label``. A
controller that two records play alike (the same name and the same episodes in every cell they
share: the paper's gait, the rolling helix) is kept once, under the first record's name. The
records must share their reset seeds and nominal cell.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from acl_env.benchmark.summary import controllers_of
from acl_env.io import guarded_output, read_json
from acl_env.scripts import make_parser, write_output


def points(records: dict[str, dict[str, Any]]) -> list[dict[str, Any]]:
    """One point per controller: success over the shared cells, nominal climb and slip."""
    first = next(iter(records.values()))
    shared = [k for k in first["cells"] if all(k in r["cells"] for r in records.values())]
    out: list[dict[str, Any]] = []
    kept: dict[str, list[dict[str, Any]]] = {}  # controller -> the records it was kept from
    for name, record in records.items():
        if record["settings"]["seeds"] != first["settings"]["seeds"]:
            raise ValueError(f"{name} played other seeds than the first record")
        policies, analytic = controllers_of(record)
        for controller in [*policies, *analytic]:
            results = [record["cells"][k]["controllers"][controller] for k in shared]
            if any(
                results == [other["cells"][k]["controllers"][controller] for k in shared]
                for other in kept.get(controller, [])
            ):  # the same episodes in every shared cell as one already kept
                continue
            kept.setdefault(controller, []).append(record)
            nominal = record["cells"]["nominal"]["controllers"][controller]
            climbs = nominal["climb_per_gait_cycle_m"]["values"]
            rates = [result["success_rate"] for result in results]
            out.append(
                {
                    "record": name,
                    "label": record["labels"].get(controller, controller),
                    "kind": kind(controller),
                    "success": float(np.mean(rates)),
                    "cells": len(shared),
                    "nominal_climb_per_gait_cycle_m": float(np.mean(climbs)),
                    "nominal_slip_per_m": nominal["slip_per_m"]["mean"],
                }
            )
    return out


KINDS = {"policy": ("o", "policies"), "grip": ("^", "compliant grips"), "open": ("s", "open loops")}


def kind(controller: str) -> str:
    """A controller's kind, from its record name: a policy, a compliant grip or an open loop."""
    if controller.startswith("policy:"):
        return "policy"
    return "grip" if controller.startswith("compliant") else "open"


def plot(document: dict[str, Any], path: Path) -> None:
    """Nominal climb (left) and slip (right) against success over the grid, a colour per record
    and a marker per kind; 0.97x the specialist's nominal climb and the best analytic
    controller's success drawn as lines (and 1.15x the specialist's slip)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pts, names = document["points"], list(document["records"])
    colours = dict(zip(names, plt.get_cmap("tab10").colors, strict=False))
    fig, axes = plt.subplots(1, 2, figsize=(11.0, 4.8), sharex=True)
    for ax, score, scale, label in (
        (axes[0], "nominal_climb_per_gait_cycle_m", 100.0, "climb per gait cycle (cm)"),
        (axes[1], "nominal_slip_per_m", 1.0, "slip per metre climbed"),
    ):
        for p in pts:
            marker = KINDS[p["kind"]][0]
            ax.scatter(
                p["success"],
                scale * p[score],
                marker=marker,
                s=36,
                edgecolors="k",
                color=colours[p["record"]],
                linewidths=0.5,
            )
            if p["label"] in ("ACL, the paper's gait", "rolling helix"):
                ax.annotate(
                    p["label"],
                    (p["success"], scale * p[score]),
                    fontsize=7,
                    xytext=(-6, 6),
                    textcoords="offset points",
                    ha="right",
                )
        ax.axvline(document["best_analytic_success"], color="grey", ls=":", lw=0.8)
        ax.set_xlabel(f"success rate over the {pts[0]['cells']} cells the records share")
        ax.set_ylabel(f"{label}, nominal condition")
    axes[0].axhline(100 * document["specialist_climb_0_97"], color="grey", ls="--", lw=0.8)
    axes[1].axhline(document["specialist_slip_1_15"], color="grey", ls="--", lw=0.8)
    handles = [
        *(plt.Line2D([], [], ls="", marker="o", color=colours[n], label=n) for n in names),
        *(
            plt.Line2D([], [], ls="", marker=m, color="w", markeredgecolor="k", label=text)
            for m, text in KINDS.values()
        ),
    ]
    axes[1].legend(handles=handles, fontsize=7, loc="upper left")
    fig.suptitle(
        "What holding the grid costs at the nominal condition (dashed: 0.97x the "
        "specialist's climb, 1.15x its slip; dotted: the best analytic controller's success)",
        fontsize=9,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__, plot=True)
    parser.add_argument(
        "records", nargs="+", metavar="NAME=RECORD", help="acl-benchmark records, each named"
    )
    parser.add_argument(
        "--specialist",
        default="policy:acl_climb_sea_ppo",
        help="the controller whose nominal climb and slip the dashed lines take 0.97x and 1.15x of",
    )
    args = parser.parse_args(argv)
    pairs = [text.split("=", 1) for text in args.records]
    if any(len(pair) != 2 for pair in pairs):
        parser.error("records: give each as NAME=RECORD")
    records = {name: read_json(Path(path)) for name, path in pairs}
    found = [r for r in records.values() if args.specialist in r["cells"]["nominal"]["controllers"]]
    if not found:
        parser.error(f"--specialist: no record plays {args.specialist}")
    specialist = found[0]["cells"]["nominal"]["controllers"][args.specialist]
    pts = points(records)
    document = {
        "records": dict(pairs),
        "specialist": args.specialist,
        "specialist_climb_0_97": 0.97 * specialist["climb_per_gait_cycle_m"]["mean"],
        "specialist_slip_1_15": 1.15 * specialist["slip_per_m"]["mean"],
        "best_analytic_success": max(p["success"] for p in pts if p["kind"] != "policy"),
        "points": pts,
    }
    write_output(args.json, document)  # the record first: a closed pipe loses nothing
    if args.plot:
        plot(document, args.plot)
    for p in sorted(pts, key=lambda p: -p["success"]):
        print(
            f"{p['success']:.3f}  {100 * p['nominal_climb_per_gait_cycle_m']:6.2f} cm  "
            f"{p['nominal_slip_per_m']:.3f}  {p['record']}: {p['label']}"
        )
    return document


if __name__ == "__main__":
    with guarded_output():
        main()
