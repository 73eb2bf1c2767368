"""How much squeeze the nominal tuned gait lacks where it falls off the nominal condition.

``acl_sea`` open loop with its squeeze raised by a few millimetres, in the cells of the SEA grid
where it falls.

``python experiments/robust_tuning/squeeze_margin.py [--offsets-mm 0 4 8 12 16]
[--record docs/benchmark_sea.json] [--episodes 5] [--workers 2] [--json PATH] [--plot PATH]``

The cells are the nominal one and those of ``--record`` (an ``acl-benchmark`` record of
``ACLClimb-v3``) where its ``open_loop_tuned`` controller fell in some episode. Each offset is
that controller with ``squeeze`` raised by it (Eq. 1's helix radius, pressed onto the pole), on
the same reset seeds; offset 0 replays the record's episodes. The record is written after every
cell: run the same command again to go on.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from acl_env.benchmark.run import cell_result
from acl_env.evaluation.baselines import Controller
from acl_env.evaluation.runner import make_pool, run_controllers
from acl_env.io import guarded_output, read_json, write_json
from acl_env.scripts import make_parser, use_agg

TUNED = "open_loop_tuned"


def cells_to_play(record: dict[str, Any]) -> list[str]:
    """The nominal cell, then those where the record's tuned gait fell in some episode."""
    fell = [k for k, c in record["cells"].items() if c["controllers"][TUNED]["falls"]]
    return ["nominal", *fell]


def controllers(record: dict[str, Any], cell: str, offsets_mm: list[float]) -> list[Controller]:
    """The record's tuned gait in ``cell``, once per squeeze offset (named ``+<mm> mm``)."""
    spec = record["settings"]["controllers"][TUNED]
    kwargs = {
        **spec["env_kwargs"],
        **record["settings"]["fixed"],
        **record["cells"][cell]["kwargs"],
    }
    base = Controller(TUNED, spec["env_id"], kwargs)
    return [
        replace(
            base, name=f"+{mm:g} mm", env_kwargs={**kwargs, "squeeze": kwargs["squeeze"] + mm / 1e3}
        )
        for mm in offsets_mm
    ]


def plot(document: dict[str, Any], path: Path) -> None:
    """Climb per gait cycle per cell (rows) and offset (columns); a cell with falls shows them."""
    plt = use_agg()
    cells, offsets = list(document["cells"]), [f"+{mm:g} mm" for mm in document["offsets_mm"]]
    climb = np.array(
        [
            [document["cells"][c][o]["climb_per_gait_cycle_m"]["mean"] for o in offsets]
            for c in cells
        ]
    )
    falls = [[document["cells"][c][o]["falls"] for o in offsets] for c in cells]
    held = np.where(np.array(falls) == 0, 100 * climb, np.nan)
    fig, ax = plt.subplots(figsize=(2.5 + 1.1 * len(offsets), 1.0 + 0.38 * len(cells)))
    image = ax.imshow(held, cmap="viridis", aspect="auto")
    middle = np.nanmean([np.nanmin(held), np.nanmax(held)])
    for (row, col), n in np.ndenumerate(np.array(falls)):
        text = f"{held[row, col]:.1f}" if n == 0 else f"falls {n}/{document['episodes']}"
        dark = n == 0 and held[row, col] < middle  # white text on the dark end of viridis
        ax.text(col, row, text, ha="center", va="center", fontsize=7, color="w" if dark else "k")
    ax.set_xticks(range(len(offsets)), offsets, fontsize=8)
    ax.set_yticks(range(len(cells)), cells, fontsize=7)
    ax.set_xlabel("squeeze added to the tuned gait's")
    fig.colorbar(image, ax=ax, label="climb per gait cycle (cm), where no episode fell")
    ax.set_title("acl_sea open loop, squeeze raised, where it falls", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__, plot=True, episodes=5, workers=2, progress=True)
    parser.add_argument(
        "--offsets-mm",
        type=float,
        nargs="+",
        default=[0.0, 4.0, 8.0, 12.0, 16.0],
        help="squeeze added to the tuned gait's, in mm (default %(default)s)",
    )
    parser.add_argument(
        "--record",
        type=Path,
        default=Path("docs/benchmark_sea.json"),
        help="the ACLClimb-v3 benchmark record whose cells and tuned gait to play "
        "(default %(default)s)",
    )
    args = parser.parse_args(argv)
    record = read_json(args.record)
    if record["settings"]["task"] != "acl_env/ACLClimb-v3":
        parser.error(f"--record: {args.record} is not a record of acl_env/ACLClimb-v3")
    seeds = record["settings"]["seeds"][: args.episodes]
    settings = {"record": str(args.record), "offsets_mm": args.offsets_mm, "episodes": len(seeds)}
    document: dict[str, Any] = {**settings, "cells": {}}
    if args.json and args.json.is_file():
        previous = read_json(args.json)
        if {k: previous.get(k) for k in settings} == settings:
            document = previous
    pool = make_pool(args.workers)
    try:
        for cell in tqdm(cells_to_play(record), unit="cell", disable=args.no_progress_bar):
            if cell in document["cells"]:
                continue
            played = run_controllers(
                controllers(record, cell, args.offsets_mm), seeds, pool, progress=False
            )
            document["cells"][cell] = {name: cell_result(eps) for name, eps in played.items()}
            if args.json:
                write_json(args.json, document)
    finally:
        if pool is not None:
            pool.shutdown()
    if args.plot:
        plot(document, args.plot)
    for cell, row in document["cells"].items():
        shown = (
            f"{r['falls']} falls, {100 * r['climb_per_gait_cycle_m']['mean']:.1f} cm"
            for r in row.values()
        )
        print(f"{cell:40s}", " | ".join(shown))
    return document


if __name__ == "__main__":
    with guarded_output():
        main()
