"""The open-loop frontier: every trial's climb and slip against its energy per metre, the gaits
no other beats on both, and where learned controllers (of evaluation JSONs) land beside them."""

from __future__ import annotations

import io
import itertools
import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import optuna

from acl_env.evaluation.records import controller_summary, read_record
from acl_env.io import atomic_write
from acl_env.tuning.objective import TuneSettings
from acl_env.tuning.study import FINISHED

POINT_METRICS = ("energy_per_m", "climb_per_gait_cycle_m", "slip_per_m")
# The frontier figure's panels: y metric, axis label, whether more is better (x: energy, less).
FRONTIER_PANELS = (
    ("climb_per_gait_cycle_m", "climb per gait cycle (m)", True),
    ("slip_per_m", "slip per metre climbed", False),
)


def policy_point(path: str | Path, controller: str = "policy") -> dict[str, float]:
    """Energy, climb and slip means (:data:`POINT_METRICS`) of one controller of an evaluation
    JSON; a metric the JSON lacks is NaN (not drawn)."""
    summary = controller_summary(read_record(path), controller)
    point = {m: float(summary[m]["mean"]) if m in summary else math.nan for m in POINT_METRICS}
    if not math.isfinite(point["energy_per_m"]):
        raise KeyError(f"{controller} has no energy_per_m")
    return point


def pareto_front(points: np.ndarray, maximize: bool = True) -> np.ndarray:
    """Points ``(energy, y)`` that no other point beats on both (less energy, more ``y``, or less
    with ``maximize=False``), sorted by energy."""
    sign = 1.0 if maximize else -1.0
    order = np.argsort(points[:, 0], kind="stable")
    front, best = [], -np.inf
    for i in order:
        if sign * points[i, 1] > best:
            front.append(i)
            best = sign * points[i, 1]
    return points[front]


def plot_frontier(
    study: optuna.Study,
    settings: TuneSettings,
    path: str | Path,
    title: str,
    chosen: optuna.trial.FrozenTrial | None = None,
    policies: Sequence[tuple[str, Mapping[str, float]]] = (),
    others: Sequence[optuna.Study] = (),
) -> None:
    """:func:`render_frontier` written to ``path`` (its suffix the format), atomically: a
    symbolic link there is replaced, never written through."""
    path = Path(path)
    image = render_frontier(study, settings, title, chosen, policies, others, path.suffix[1:])
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(path, image)


def render_frontier(
    study: optuna.Study,
    settings: TuneSettings,
    title: str,
    chosen: optuna.trial.FrozenTrial | None = None,
    policies: Sequence[tuple[str, Mapping[str, float]]] = (),
    others: Sequence[optuna.Study] = (),
    image_format: str = "png",
) -> bytes:
    """The frontier figure as a file's bytes in ``image_format``: every trial's climb per gait
    cycle (left) and slip per metre (right) against its energy per metre: the open-loop
    frontiers, with labelled policy points (:func:`policy_point`) where a learned controller
    lands.

    ``others``: studies (of other objectives or ranges) whose qualified gaits join the frontier,
    drawn in grey.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    trials = study.get_trials(deepcopy=False, states=FINISHED)
    complete = [t for t in trials if t.state == optuna.trial.TrialState.COMPLETE]
    measured_out = [
        t for t in trials if t.user_attrs.get("disqualified") in ("fell", "rolled", "touched arc")
    ]
    extra_trials = [
        t
        for other in others
        for t in other.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
    ]
    default = next((t for t in complete if t.user_attrs.get("default_gait")), None)
    # The docs show this 1440 px figure about 690 px wide: one legend for both panels sits below
    # them, in a font readable there, where it covers no point (the figure grows to hold it).
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.6), constrained_layout=True)
    colours = ("tab:orange", "tab:pink", "tab:cyan", "tab:brown")
    for ax, (metric, label, maximize) in zip(axes, FRONTIER_PANELS, strict=True):

        def point(t: optuna.trial.FrozenTrial, metric: str = metric) -> tuple[float, float]:
            return t.user_attrs.get("energy_per_m", math.nan), t.user_attrs.get(metric, math.nan)

        def finite(ts: list[optuna.trial.FrozenTrial]) -> np.ndarray:
            pts = np.array([point(t) for t in ts], dtype=float).reshape(-1, 2)
            return pts[np.all(np.isfinite(pts), axis=1) & (pts[:, 0] > 0)]

        ok = finite(complete)
        values = [t.value for t in complete if np.all(np.isfinite(point(t))) and point(t)[0] > 0]
        if len(ok):
            # Colours span the better 90 % of the gaits: one bad outlier would wash out the rest.
            low, high = np.percentile(values, [10.0, 100.0])
            if settings.direction == "minimize":
                low, high = np.percentile(values, [0.0, 90.0])
            sc = ax.scatter(
                ok[:, 0], ok[:, 1], c=values, s=14, cmap="viridis", vmin=low, vmax=high, zorder=2
            )
            if ax is axes[-1]:
                extend = "min" if settings.direction == "maximize" else "max"
                fig.colorbar(sc, ax=ax, label=settings.objective, extend=extend)
        extra = finite(extra_trials)
        if len(extra):
            names = ", ".join(other.study_name for other in others)
            ax.scatter(
                extra[:, 0],
                extra[:, 1],
                s=14,
                facecolors="none",
                edgecolors="0.55",
                lw=0.7,
                label=f"studies {names}",
                zorder=1,
            )
        if len(ok) or len(extra):
            front = pareto_front(np.vstack([ok, extra]), maximize)
            ax.step(front[:, 0], front[:, 1], where="post", color="0.3", lw=1, label="frontier")
        out = finite(measured_out)
        if len(out):
            label_out = "disqualified: fell or rolled"
            ax.scatter(out[:, 0], out[:, 1], marker="x", s=14, color="0.6", label=label_out)
        if default is not None:
            ax.scatter(*point(default), marker="s", s=60, color="k", label="default gait", zorder=3)
        if chosen is not None:
            ax.scatter(*point(chosen), marker="*", s=200, color="tab:red", label="tuned", zorder=4)
        marked = [point(t) for t in (default, chosen) if t is not None]
        for (name, values_), colour in zip(policies, itertools.cycle(colours)):
            xy = (values_["energy_per_m"], values_[metric])
            if all(math.isfinite(v) for v in xy):
                ax.scatter(*xy, marker="^", s=90, color=colour, label=name, zorder=5)
                marked.append(xy)
        # Axes around the better gaits (the frontier's side): far-off bad gaits only squash them.
        shown = np.vstack([ok, extra, out, np.array(marked, dtype=float).reshape(-1, 2)])
        shown = shown[np.all(np.isfinite(shown), axis=1) & (shown[:, 0] > 0)]
        beyond = 0
        if len(ok) >= 10:
            x_hi = max([np.percentile(ok[:, 0], 90) * 1.3, *(1.1 * m[0] for m in marked)])
            if maximize:
                y_lo = min([np.percentile(ok[:, 1], 10), *(m[1] for m in marked)])
                y_hi = shown[:, 1].max()
                beyond = int(np.sum((shown[:, 0] > x_hi) | (shown[:, 1] < y_lo)))
            else:
                y_hi = max([np.percentile(ok[:, 1], 90), *(m[1] for m in marked)])
                y_lo = shown[:, 1].min()
                beyond = int(np.sum((shown[:, 0] > x_hi) | (shown[:, 1] > y_hi)))
            pad = 0.05 * (y_hi - y_lo)
            ax.set_xlim(shown[:, 0].min() / 1.1, x_hi)
            ax.set_ylim(y_lo - pad, y_hi + pad)
        hidden = len(trials) - len(ok) - len(out)
        clip = f"{settings.max_clipped:.0%}"
        note = f"not shown: {hidden} gaits that did not climb or clipped over {clip} of the joints"
        if beyond:
            note += f";\n{beyond} beyond the axes"
        ax.set_title(note, fontsize=10)
        lo, hi = ax.get_xlim()
        if hi / lo > 10.0:  # a log axis only where the energies span more than a decade
            ax.set_xscale("log")
            ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax.set_xlabel("energy per metre climbed (J/m)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3, which="both")
    legend = {}  # label -> handle, over both panels (a policy may lack one panel's metric)
    for ax in axes:
        for handle, name in zip(*ax.get_legend_handles_labels(), strict=True):
            legend.setdefault(name, handle)
    fig.legend(legend.values(), legend.keys(), loc="outside lower center", ncols=4, fontsize=11)
    fig.suptitle(title, fontsize=11)
    buffer = io.BytesIO()
    fig.savefig(buffer, format=image_format or "png", dpi=120)
    plt.close(fig)
    return buffer.getvalue()
