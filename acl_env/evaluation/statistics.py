"""Statistics over training seeds, as the field reports them (Agarwal et al., NeurIPS 2021, *Deep
RL at the edge of the statistical precipice*): the interquartile mean, bootstrap 95 % intervals,
the probability of improvement, and performance profiles. SciPy computes them.

``rliable``, the paper's library, would pull in arch, pandas and seaborn; SciPy's bootstrap is
what it builds on. rliable's stratified bootstrap resamples the runs within each task
independently; here a training seed is one policy played in every cell, so the bootstrap is a
plain percentile bootstrap over the seeds, each seed's row of a seeds x cells matrix resampled
whole. The probability of improvement counts ties half (Mann-Whitney), as rliable's does.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from scipy import stats

CONFIDENCE = 0.95
# Fewer training seeds than this: bootstrap intervals too narrow to trust (Agarwal et al. 2021
# ask for at least five runs); the commands say so.
MIN_SEEDS = 5
RESAMPLES = 5000


def iqm(values: Sequence[float] | np.ndarray, axis: int = -1) -> Any:
    """Interquartile mean: the mean of the middle half (25 % trimmed from each end)."""
    return stats.trim_mean(np.asarray(values, dtype=float), 0.25, axis=axis)


def bootstrap_interval(
    values: Sequence[float] | np.ndarray,
    statistic: Callable[[np.ndarray], float] = iqm,
    seed: int = 0,
) -> tuple[float, float]:
    """Percentile bootstrap 95 % interval of ``statistic`` of ``values``, resampling its rows
    (the training seeds; a seeds x cells matrix keeps each seed's row whole). SciPy resamples
    the row indices; fewer than two rows, or all alike: the statistic itself, twice."""
    data = np.asarray(values, dtype=float)
    point = float(statistic(data))
    if len(data) < 2 or np.all(data == data[0]):
        return point, point
    result = stats.bootstrap(
        (np.arange(len(data)),),
        lambda rows: statistic(data[rows.astype(int)]),
        vectorized=False,
        confidence_level=CONFIDENCE,
        n_resamples=RESAMPLES,
        method="percentile",
        rng=np.random.default_rng(seed),
    )
    return float(result.confidence_interval.low), float(result.confidence_interval.high)


def probability_of_improvement(
    scores: np.ndarray, reference: np.ndarray, higher_is_better: bool = True
) -> np.ndarray:
    """P(X > Y) + P(X = Y) / 2 per cell, X a row of ``scores`` (seeds x cells) and Y a row of
    ``reference`` (runs x cells, or one value per cell): the Mann-Whitney U statistic over the
    number of pairs, cell by cell."""
    x = np.asarray(scores, dtype=float)
    y = np.asarray(reference, dtype=float)
    if y.ndim == 1:
        y = y[None, :]
    if not higher_is_better:
        x, y = -x, -y
    greater = (x[:, None, :] > y[None, :, :]).mean(axis=(0, 1))
    equal = (x[:, None, :] == y[None, :, :]).mean(axis=(0, 1))
    return greater + 0.5 * equal


def mean_probability_of_improvement(
    scores: np.ndarray, reference: np.ndarray, higher_is_better: bool = True, seed: int = 0
) -> dict[str, Any]:
    """The probability of improvement averaged over cells, and its bootstrap 95 % interval
    over the training seeds (the rows of ``scores``)."""

    def statistic(rows: np.ndarray) -> float:
        return float(probability_of_improvement(rows, reference, higher_is_better).mean())

    low, high = bootstrap_interval(scores, statistic, seed)
    return {"mean": statistic(np.asarray(scores, dtype=float)), "ci95": [low, high]}


# The metrics summarised over training seeds, and whether more is better.
SEED_METRICS = {
    "climb_per_gait_cycle_m": True,
    "slip_per_m": False,
    "energy_per_m": False,
    "reward_per_gait_cycle": True,
}


def over_seeds(summaries: dict[str, dict[str, Any]], policies: Sequence[str]) -> dict[str, Any]:
    """The policies (training seeds of one recipe) over seeds, per metric: each seed's mean, the
    IQM with its bootstrap 95 % interval, the best analytic controller (the best mean among the
    others) and the probability that a seed's mean beats it, with its interval."""
    analytic = [name for name in summaries if name not in policies]
    out: dict[str, Any] = {}
    for metric, higher in SEED_METRICS.items():
        per_seed = np.array([summaries[p][metric]["mean"] for p in policies], dtype=float)
        means = {n: float(summaries[n][metric]["mean"]) for n in analytic}
        means = {n: m for n, m in means.items() if np.isfinite(m)}
        entry: dict[str, Any] = {
            "per_seed": dict(zip(policies, per_seed.tolist(), strict=True)),
            "iqm": float(iqm(per_seed)),
            "ci95": list(bootstrap_interval(per_seed)),
        }
        if means:
            best = (max if higher else min)(means, key=means.__getitem__)
            entry["best_analytic"] = {"controller": best, "mean": means[best]}
            entry["probability_of_improvement"] = mean_probability_of_improvement(
                per_seed[:, None], np.array([means[best]]), higher
            )
        out[metric] = entry
    return out


def compare_samples(
    first: Sequence[float], second: Sequence[float], higher_is_better: bool = True, seed: int = 0
) -> dict[str, Any]:
    """Two recipes' training seeds (one value each): the IQM difference, first minus second,
    and the probability that a seed of the first beats one of the second, each with a
    bootstrap 95 % interval resampling both sets of seeds independently."""
    x, y = np.asarray(first, dtype=float), np.asarray(second, dtype=float)

    def difference(a: np.ndarray, b: np.ndarray) -> float:
        return float(iqm(a) - iqm(b))

    def improvement(a: np.ndarray, b: np.ndarray) -> float:
        return float(probability_of_improvement(a[:, None], b[:, None], higher_is_better)[0])

    out: dict[str, Any] = {}
    for name, statistic in (
        ("iqm_difference", difference),
        ("probability_of_improvement", improvement),
    ):
        point = statistic(x, y)
        if min(len(x), len(y)) < 2:
            out[name] = {"mean": point, "ci95": [point, point]}
            continue
        result = stats.bootstrap(
            (x, y),
            statistic,
            vectorized=False,
            paired=False,
            confidence_level=CONFIDENCE,
            n_resamples=RESAMPLES,
            method="percentile",
            rng=np.random.default_rng(seed),
        )
        ci = result.confidence_interval
        out[name] = {"mean": point, "ci95": [float(ci.low), float(ci.high)]}
    return out


def performance_profile(scores: np.ndarray, thresholds: np.ndarray) -> np.ndarray:
    """The fraction of runs x cells whose score exceeds each threshold (a run's score
    distribution, the curve of the performance profile)."""
    flat = np.asarray(scores, dtype=float).ravel()
    flat = flat[np.isfinite(flat)]
    return np.array([(flat > t).mean() if len(flat) else np.nan for t in thresholds])
