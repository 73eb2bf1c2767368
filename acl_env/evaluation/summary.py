"""Over episodes: each metric's mean and 95 % interval, and two controllers compared episode by
episode on the same seeds."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from acl_env.evaluation.intervals import mean_ci95
from acl_env.evaluation.protocol import METRICS, Episode

# Metrics compared episode by episode in :func:`paired_differences`.
PAIRED_METRICS = ("climb_per_gait_cycle_m", "slip_per_m", "energy_per_m", "reward_per_gait_cycle")


def summarize(episodes: Sequence[Episode]) -> dict[str, Any]:
    """Mean and t-based 95 % CI per metric (``values`` per episode, in seed order)."""
    per_episode = [e.metrics() for e in episodes]
    summary: dict[str, Any] = {}
    for metric in METRICS:
        values = [m[metric] for m in per_episode]
        summary[metric] = {**mean_ci95(values), "values": values}
    summary["falls"]["count"] = sum(e.fell for e in episodes)
    summary["unstable"] = sum(e.unstable for e in episodes)
    summary["rolled"] = sum(e.rolled for e in episodes)
    summary["mean_phase_rate"] = float(
        sum(e.keyframes for e in episodes) / max(1, sum(e.steps for e in episodes))
    )
    summary["episodes"] = len(episodes)
    summary["seeds"] = [e.seed for e in episodes]
    return summary


def paired_differences(
    summaries: dict[str, dict[str, Any]],
    reference: str = "policy",
    metrics: Sequence[str] = PAIRED_METRICS,
) -> dict[str, dict[str, dict[str, Any]]]:
    """``reference`` minus each other controller, episode by episode on the same reset seeds:
    ``{controller: {metric: mean_ci95(differences)}}`` (:func:`summarize`'s ``values``).

    Both sides of a pair share the seed, so the pole, skin and springs drawn for it: the paired
    interval is the one that says whether one controller beats the other, and it is often much
    narrower than the two controllers' own intervals side by side. Episodes where either value is
    undefined (no climb: slip per metre) are left out of that metric's pairs (``n`` says how many
    remain). Controllers run on other seeds raise ``ValueError``.
    """
    ref = summaries[reference]
    out: dict[str, dict[str, dict[str, Any]]] = {}
    for name, summary in summaries.items():
        if name == reference:
            continue
        if summary["seeds"] != ref["seeds"]:
            raise ValueError(
                f"{name} ran on seeds {summary['seeds']}, {reference} on {ref['seeds']}"
            )
        out[name] = {}
        for metric in metrics:
            pairs = zip(ref[metric]["values"], summary[metric]["values"], strict=True)
            out[name][metric] = mean_ci95(
                a - b for a, b in pairs if a is not None and b is not None
            )
    return out
