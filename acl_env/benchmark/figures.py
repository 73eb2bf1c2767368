"""Heat maps of a benchmark record: for one score, a row of panels per controller (the policies
as their mean over seeds), one panel per pair of axes, the other axes nominal, and one for the
grid's events (such as the friction step) where it has any. A cell where the controller falls in
most episodes is marked with a cross."""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from acl_env.benchmark.grid import Cell
from acl_env.benchmark.summary import controllers_of
from acl_env.evaluation.statistics import performance_profile

TITLES = {
    "success_rate": ("success rate (no fall, climbs)", 100.0, "{:.0f}", "%"),
    "climb_per_gait_cycle_m": ("climb per gait cycle", 100.0, "{:.1f}", "cm"),
    "slip_per_m": ("slip per metre climbed", 1.0, "{:.2f}", ""),
    "energy_per_m": ("energy per metre", 1.0, "{:.0f}", "J/m"),
}


def _value(result: dict[str, Any], score: str) -> float:
    value = result[score] if score == "success_rate" else result[score]["mean"]
    return np.nan if value is None else float(value)


def _light(value: float, vmin: float, vmax: float, cmap: str) -> bool:
    """Whether ``value`` falls on viridis's light (yellow) end, where text must be dark."""
    position = (value - vmin) / (vmax - vmin) if vmax > vmin else 1.0
    return (1.0 - position if cmap.endswith("_r") else position) > 0.6


def plot_heat_maps(
    record: dict[str, Any], score: str, path: str | Path, labels: dict[str, str] | None = None
) -> None:
    """The heat maps of ``score`` (a key of :data:`TITLES`) to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    title, scale, _, unit = TITLES[score]
    axes_info = record["settings"]["axes"]
    pairs = list(itertools.combinations(axes_info, 2))
    events = [Cell(e, held_out=True).key for e in record["settings"].get("events", [])]
    policies, analytic = controllers_of(record)
    rows = (["policies"] if policies else []) + analytic
    labels = labels or {}
    columns = len(pairs) + bool(events)
    fig, grid = plt.subplots(
        len(rows),
        columns,
        figsize=(2.6 * columns, 2.3 * len(rows) + 0.8),
        squeeze=False,
        layout="constrained",
    )
    cmap = "viridis" if score in ("success_rate", "climb_per_gait_cycle_m") else "viridis_r"
    colours = _Colours(cmap, *_value_range(record, rows, policies, score, scale))
    image = None
    for r, row in enumerate(rows):
        names = policies if row == "policies" else [row]
        for c, pair in enumerate(pairs):
            image = _heat_map(grid[r, c], record, names, pair, score, colours)
        if events:
            _events_panel(grid[r, len(pairs)], record, names, events, score, colours)
        label = f"policies (mean of {len(policies)})" if row == "policies" else labels.get(row, row)
        grid[r, 0].annotate(
            label,
            (0, 0.5),
            xytext=(-55, 0),
            xycoords="axes fraction",
            textcoords="offset points",
            rotation=90,
            ha="right",
            va="center",
            fontsize=10,
        )
    if image is not None:
        fig.colorbar(
            image,
            ax=grid,
            shrink=0.6,
            label=f"{title} ({unit})" if unit else title,
            extend="neither" if score == "success_rate" else "both",
        )
    fig.suptitle(f"{record['settings']['task']}: {title}; x: falls in most episodes", fontsize=12)
    fig.savefig(path, dpi=90)
    plt.close(fig)


class _Colours(NamedTuple):
    """The heat maps' colour map and the values at its ends, shared by every panel."""

    cmap: str
    vmin: float
    vmax: float

    def text(self, value: float) -> str:
        """The colour of text on ``value``'s colour: dark on the colour map's light end (high
        values, or low reversed)."""
        return "black" if _light(value, self.vmin, self.vmax, self.cmap) else "white"


def _value_range(
    record: dict[str, Any], rows: list[str], policies: list[str], score: str, scale: float
) -> tuple[float, float]:
    """The colour map's ends: 0 and 1 for the success rate; for the other scores the 2nd and
    98th percentiles of the rows' finite values (scaled) over all cells, so that one outlier (a
    controller sliding metres on the trunk) does not wash out every other cell; the cells still
    write their values, and the colour bar shows the ends as extended (0 and 1 when there is no
    value)."""
    if score == "success_rate":
        return 0.0, 1.0
    values_all = []
    for row in rows:
        names = policies if row == "policies" else [row]
        for cell in record["cells"].values():
            values_all += [_value(cell["controllers"][n], score) * scale for n in names]
    finite = [v for v in values_all if np.isfinite(v)]
    if not finite:
        return 0.0, 1.0
    low, high = np.percentile(finite, [2.0, 98.0])
    return float(low), float(high)


def _heat_map(
    ax: Any,
    record: dict[str, Any],
    names: list[str],
    pair: tuple[str, str],
    score: str,
    colours: _Colours,
) -> Any:
    """One panel: the mean ``score`` of the controllers ``names`` over the grid of the ``pair``
    of axes (the others nominal), each cell written in and crossed where they fall in most
    episodes; return its image."""
    axes_info = record["settings"]["axes"]
    x_name, y_name = pair
    xs, ys = axes_info[x_name]["values"], axes_info[y_name]["values"]
    nominal = {k: a["nominal"] for k, a in axes_info.items()}
    data = np.full((len(ys), len(xs)), np.nan)
    for (i, y), (j, x) in itertools.product(enumerate(ys), enumerate(xs)):
        changed = {k: v for k, v in ((x_name, x), (y_name, y)) if v != nominal[k]}
        cell = record["cells"].get(Cell(changed, held_out=False).key)
        if cell is None:
            continue
        data[i, j] = _mark(ax, (i, j), [cell["controllers"][n] for n in names], score, colours)
    image = ax.imshow(
        data, origin="lower", cmap=colours.cmap, vmin=colours.vmin, vmax=colours.vmax, aspect="auto"
    )
    ax.set_xticks(range(len(xs)), [f"{x:g}" for x in xs], fontsize=8)
    ax.set_yticks(range(len(ys)), [f"{y:g}" for y in ys], fontsize=8)
    ax.set_xlabel(x_name, fontsize=9)
    ax.set_ylabel(y_name, fontsize=9)
    return image


def _mark(
    ax: Any, at: tuple[int, int], results: list[dict[str, Any]], score: str, colours: _Colours
) -> float:
    """Write the controllers' mean ``score`` (scaled) into the cell at ``at`` (row, column),
    crossed where they fall in most episodes; return the value."""
    _, scale, fmt, _ = TITLES[score]
    values = np.array([_value(res, score) for res in results], dtype=float)
    defined = values[~np.isnan(values)]  # none where every controller fell: a blank cell
    value = float(defined.mean()) * scale if defined.size else np.nan
    i, j = at
    text = "" if np.isnan(value) else fmt.format(value)
    ax.text(j, i, text, ha="center", va="center", fontsize=8, color=colours.text(value))
    if np.mean([res["falls"] / res["episodes"] for res in results]) > 0.5:
        ax.plot(j, i, marker="x", color="red", markersize=18, mew=2)
    return value


def _events_panel(
    ax: Any,
    record: dict[str, Any],
    names: list[str],
    events: list[str],
    score: str,
    colours: _Colours,
) -> None:
    """One panel: the controllers' mean ``score`` in each event cell (keys ``events``)."""
    data = np.full((len(events), 1), np.nan)
    for i, key in enumerate(events):
        results = [record["cells"][key]["controllers"][n] for n in names]
        data[i, 0] = _mark(ax, (i, 0), results, score, colours)
    ax.imshow(
        data, origin="lower", cmap=colours.cmap, vmin=colours.vmin, vmax=colours.vmax, aspect="auto"
    )
    ax.set_xticks([])
    ax.set_yticks(range(len(events)), events, fontsize=8)
    ax.set_xlabel("events, at the nominal condition", fontsize=9)


def plot_profiles(
    record: dict[str, Any], path: str | Path, labels: dict[str, str] | None = None
) -> None:
    """Performance profiles over the grid: for each controller, the fraction of cells (of seeds
    x cells for the policies) whose climb per gait cycle exceeds each threshold, a fall in most
    episodes counting as no climb (Agarwal et al. 2021, Fig. 5's curves over tasks)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = labels or {}
    policies, analytic = controllers_of(record)
    groups = ({"policies": policies} if policies else {}) | {name: [name] for name in analytic}

    def climb(result: dict[str, Any]) -> float:
        fell = result["falls"] > result["episodes"] / 2
        value = _value(result, "climb_per_gait_cycle_m")
        return 0.0 if fell or not np.isfinite(value) else 100.0 * value

    scores = {
        group: np.array(
            [climb(c["controllers"][n]) for c in record["cells"].values() for n in names]
        )
        for group, names in groups.items()
    }
    top = max(float(s.max(initial=0.0)) for s in scores.values())
    thresholds = np.linspace(0.0, top, 200)
    fig, ax = plt.subplots(figsize=(7.5, 4.5), layout="constrained")
    for group, values in scores.items():
        label = (
            f"policies ({len(policies)} seeds)" if group == "policies" else labels.get(group, group)
        )
        ax.plot(
            thresholds,
            performance_profile(values, thresholds),
            lw=2 if group == "policies" else 1.3,
            label=label,
        )
    ax.set_xlabel("climb per gait cycle, cm (a fall in most episodes: 0)")
    ax.set_ylabel("fraction of cells above")
    ax.set_title(
        f"{record['settings']['task']}: performance profiles over {len(record['cells'])} cells"
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize=9)
    fig.savefig(path, dpi=110)
    plt.close(fig)
