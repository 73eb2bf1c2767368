"""The protocol's numbers as text: a table of controllers (plain or Markdown) and the paired
differences, one line per controller."""

from __future__ import annotations

from typing import Any

# Columns of :func:`format_table`: metric, label, format.
TABLE_ROWS = (
    ("climb_per_cycle_m", "climb per nominal cycle (m)", ".4f"),
    ("climb_per_gait_cycle_m", "climb per gait cycle (m)", ".4f"),
    ("climb_speed_cm_s", "climb speed (cm/s)", ".3f"),
    ("slip_per_cycle_m", "slip per nominal cycle (m)", ".4f"),
    ("slip_per_m", "slip per metre climbed", ".3f"),
    ("energy_per_m", "energy (J/m)", ".0f"),
    ("mean_abs_torque_nm", "mean abs torque (N m)", ".3f"),
    ("torque_limit_fraction", "share at torque limit", ".4f"),
    ("touched_arc_deg", "touched arc (deg)", ".0f"),
    ("reward_per_gait_cycle", "reward per gait cycle", ".4f"),
    ("action_change", "action change per step", ".3f"),
)


def format_paired(differences: dict[str, dict[str, dict[str, Any]]], reference: str) -> str:
    """One line per controller: the paired differences of
    :func:`~acl_env.evaluation.summary.paired_differences`."""
    lines = [f"{reference} minus each controller, paired over the same seeds (mean ± 95 % CI):"]
    for name, metrics in differences.items():
        cells = []
        for metric, label, fmt in TABLE_ROWS:
            if metric in metrics:
                d = metrics[metric]
                cells.append(f"{label} {d['mean']:+{fmt}} ± {d['half_width']:{fmt}}")
        lines.append(f"  {name}: " + "; ".join(cells))
    return "\n".join(lines)


def format_table(summaries: dict[str, dict[str, Any]], markdown: bool = False) -> str:
    """One column per controller, mean ± 95 % CI half-width per metric: aligned plain text, or a
    Markdown table (``markdown``) for the README."""
    names = list(summaries)
    rows = [["metric", *names]]
    for metric, label, fmt in TABLE_ROWS:
        row = [label]
        for name in names:
            s = summaries[name].get(metric)  # an older evaluation's JSON may lack a metric
            row.append("n/a" if s is None else f"{s['mean']:{fmt}} ± {s['half_width']:{fmt}}")
        rows.append(row)
    values = summaries.values()
    rows.append(["falls", *(f"{s['falls']['count']}/{s['episodes']}" for s in values)])
    rows.append(["gait keyframes per step", *(f"{s['mean_phase_rate']:.3f}" for s in values)])
    n = next(iter(summaries.values()))["episodes"] if summaries else 0
    caption = f"mean ± 95 % CI half-width (Student's t, {n} episodes)"
    if markdown:
        lines = ["| " + " | ".join(row) + " |" for row in rows]
        lines.insert(1, "|---" * len(rows[0]) + "|")
        return "\n".join([*lines, "", caption])
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    lines = []
    for row in rows:
        cells = [row[0].ljust(widths[0])] + [
            c.rjust(w) for c, w in zip(row[1:], widths[1:], strict=True)
        ]
        lines.append("  ".join(cells))
    lines.insert(1, "-" * len(lines[0]))
    return "\n".join([*lines, caption])
