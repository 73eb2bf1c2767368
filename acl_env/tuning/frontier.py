"""The open-loop frontier: every trial's climb and slip against its energy per metre, the gaits
no other beats on both, and where learned controllers (of evaluation JSONs) land beside them."""

from __future__ import annotations

import io
import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

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


@dataclass(frozen=True)
class _Trials:
    """The trials a frontier figure draws: the study's finished ones, those of them complete and
    those measured and disqualified, the complete trials of the other studies, and the study's
    default gait (None if it has none)."""

    finished: list[optuna.trial.FrozenTrial]
    complete: list[optuna.trial.FrozenTrial]
    measured_out: list[optuna.trial.FrozenTrial]
    extra: list[optuna.trial.FrozenTrial]
    default: optuna.trial.FrozenTrial | None

    @classmethod
    def of(cls, study: optuna.Study, others: Sequence[optuna.Study]) -> _Trials:
        """The trials of ``study`` and ``others``, sorted as above."""
        trials = study.get_trials(deepcopy=False, states=FINISHED)
        complete = [t for t in trials if t.state == optuna.trial.TrialState.COMPLETE]
        measured_out = [
            t
            for t in trials
            if t.user_attrs.get("disqualified") in ("fell", "rolled", "touched arc")
        ]
        extra = [
            t
            for other in others
            for t in other.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
        ]
        default = next((t for t in complete if t.user_attrs.get("default_gait")), None)
        return cls(trials, complete, measured_out, extra, default)


def _point(t: optuna.trial.FrozenTrial, metric: str) -> tuple[float, float]:
    """A trial's ``(energy per metre, metric)``, NaN where it lacks one."""
    return t.user_attrs.get("energy_per_m", math.nan), t.user_attrs.get(metric, math.nan)


def _finite(ts: list[optuna.trial.FrozenTrial], metric: str) -> np.ndarray:
    """The :func:`_point` of each trial, those finite and of positive energy only."""
    pts = np.array([_point(t, metric) for t in ts], dtype=float).reshape(-1, 2)
    return pts[np.all(np.isfinite(pts), axis=1) & (pts[:, 0] > 0)]


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

    trials = _Trials.of(study, others)
    # The docs show this 1440 px figure about 690 px wide: one legend for both panels sits below
    # them, in a font readable there, where it covers no point (the figure grows to hold it).
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.6), constrained_layout=True)
    for ax, panel in zip(axes, FRONTIER_PANELS, strict=True):
        metric, label, maximize = panel
        ok, extra = _draw_gaits(fig, ax, metric, maximize, trials, settings, others, ax is axes[-1])
        out = _finite(trials.measured_out, metric)
        if len(out):
            label_out = "disqualified: fell or rolled"
            ax.scatter(out[:, 0], out[:, 1], marker="x", s=14, color="0.6", label=label_out)
        marked = _draw_marks(ax, metric, trials.default, chosen, policies)
        beyond = _zoom(ax, maximize, ok, extra, out, marked)
        _label_panel(ax, label, settings, len(trials.finished) - len(ok) - len(out), beyond)
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


def value_label(settings: TuneSettings) -> str:
    """What a trial's value is: the objective, or under ``--cvar`` the CVaR of the conditions'
    scores of it (or of their margins over the default gait's)."""
    if settings.cvar is None:
        return settings.objective
    scored = "margin over the default gait" if settings.against_default else "score"
    return f"{settings.objective}: CVaR {settings.cvar:g} of the conditions' {scored}"


def _draw_gaits(
    fig: Any,
    ax: Any,
    metric: str,
    maximize: bool,
    trials: _Trials,
    settings: TuneSettings,
    others: Sequence[optuna.Study],
    colourbar: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """The study's complete gaits coloured by objective (with the colour bar, where
    ``colourbar``), the other studies' in grey, and the frontier of both; return their points."""
    ok = _finite(trials.complete, metric)
    values = [
        t.value
        for t in trials.complete
        if np.all(np.isfinite(_point(t, metric))) and _point(t, metric)[0] > 0
    ]
    if len(ok):
        # Colours span the better 90 % of the gaits: one bad outlier would wash out the rest.
        low, high = np.percentile(values, [10.0, 100.0])
        if settings.direction == "minimize":
            low, high = np.percentile(values, [0.0, 90.0])
        sc = ax.scatter(
            ok[:, 0], ok[:, 1], c=values, s=14, cmap="viridis", vmin=low, vmax=high, zorder=2
        )
        if colourbar:
            extend = "min" if settings.direction == "maximize" else "max"
            fig.colorbar(sc, ax=ax, label=value_label(settings), extend=extend)
    extra = _finite(trials.extra, metric)
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
    return ok, extra


def _draw_marks(
    ax: Any,
    metric: str,
    default: optuna.trial.FrozenTrial | None,
    chosen: optuna.trial.FrozenTrial | None,
    policies: Sequence[tuple[str, Mapping[str, float]]],
) -> list[tuple[float, float]]:
    """The default gait, the tuned one and the policies (where they have the metric); return
    the points marked."""
    if default is not None:
        ax.scatter(
            *_point(default, metric), marker="s", s=60, color="k", label="default gait", zorder=3
        )
    if chosen is not None:
        ax.scatter(
            *_point(chosen, metric), marker="*", s=200, color="tab:red", label="tuned", zorder=4
        )
    marked = [_point(t, metric) for t in (default, chosen) if t is not None]
    colours = ("tab:orange", "tab:pink", "tab:cyan", "tab:brown")
    for (name, values_), colour in zip(policies, itertools.cycle(colours)):
        xy = (values_["energy_per_m"], values_[metric])
        if all(math.isfinite(v) for v in xy):
            ax.scatter(*xy, marker="^", s=90, color=colour, label=name, zorder=5)
            marked.append(xy)
    return marked


def _zoom(
    ax: Any,
    maximize: bool,
    ok: np.ndarray,
    extra: np.ndarray,
    out: np.ndarray,
    marked: list[tuple[float, float]],
) -> int:
    """Axes around the better gaits (the frontier's side), once there are 10 of them: far-off
    bad gaits only squash them. Return how many points fall beyond the axes."""
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
    return beyond


def _label_panel(ax: Any, label: str, settings: TuneSettings, hidden: int, beyond: int) -> None:
    """The panel's note of the gaits not shown (``hidden``) or ``beyond`` the axes, its energy
    axis (logarithmic where the energies span more than a decade), labels and grid."""
    import matplotlib.ticker

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
