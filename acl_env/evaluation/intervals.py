"""Confidence intervals of a mean over episodes: Student's t, without SciPy (numpy only)."""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable
from typing import Any

import numpy as np

CI_NOTE = "two-sided 95 % confidence interval of the mean, Student's t distribution"


@functools.lru_cache(maxsize=256)
def student_t_quantile(p: float, dof: int) -> float:
    """Quantile of Student's t distribution without SciPy: bisection on the integrated pdf."""
    if not 0.5 <= p < 1.0 or dof < 1:
        raise ValueError("need 0.5 <= p < 1 and dof >= 1")
    log_norm = math.lgamma((dof + 1) / 2) - math.lgamma(dof / 2) - 0.5 * math.log(dof * math.pi)

    def cdf(x: float) -> float:
        t = np.linspace(0.0, x, 4001)
        pdf = np.exp(log_norm - 0.5 * (dof + 1) * np.log1p(t * t / dof))
        return 0.5 + float(np.trapezoid(pdf, t))

    lo, hi = 0.0, 1.0
    while cdf(hi) < p:
        lo, hi = hi, 2.0 * hi
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if cdf(mid) < p else (lo, mid)
    return 0.5 * (lo + hi)


def mean_ci95(values: Iterable[float]) -> dict[str, Any]:
    """Mean and two-sided 95 % confidence interval from the t distribution (NaNs dropped).

    One value has no interval: its half-width is NaN, not 0.
    """
    x = np.asarray([v for v in values if not math.isnan(v)], dtype=float)
    n = len(x)
    if n == 0:
        return {"mean": math.nan, "ci95": [math.nan, math.nan], "half_width": math.nan, "n": 0}
    mean = float(x.mean())
    half = math.nan
    if n > 1:
        half = student_t_quantile(0.975, n - 1) * float(x.std(ddof=1)) / math.sqrt(n)
    return {"mean": mean, "ci95": [mean - half, mean + half], "half_width": half, "n": n}
