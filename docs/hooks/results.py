"""MkDocs hook: render the published results tables from the generated records.

A page writes a marker on a line of its own, ``<!-- results: FILE VIEW -->``, where ``FILE`` is a
record under ``docs/`` and ``VIEW`` one of:

- ``headline``: one row per controller of an ``acl-evaluate --json`` record, mean ± 95 % interval
  half-width of the headline metrics, the largest touched arc, falls and cadence;
- ``metrics``: every metric of that record, one column per controller (collapsible);
- ``paired``: the record's paired differences, policy minus each controller;
- ``ratios``: the policy's mean over each controller's, for climb, slip and energy;
- ``notes``: the task, the reward weights, the record's notes and the command that made it;
- ``open_loop``: the open-loop table of ``benchmarks/open_loop.py`` (mean ± standard deviation).

The numbers therefore come from the files the regeneration commands write, never retyped. A
missing file, an unknown view or a record without what the view needs fails the build.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from mkdocs.exceptions import PluginError

MARKER = re.compile(r"^<!--[ \t]*results:[ \t]*(\S+)[ \t]+(\w+)[ \t]*-->[ \t]*$", re.MULTILINE)

# Controller names of acl-evaluate (docs/evaluation.md, glossary) and how the tables label them.
LABELS = {
    "policy": "residual PPO (shipped)",
    "open_loop_acl": "ACL open loop (the task's registered gait)",
    "open_loop_acl_same_cadence": "the policy's gait, open loop at its cadence",
    "open_loop_tuned_same_cadence": "tuned gait at the policy's cadence",
    "open_loop_policy_gait": "the policy's gait, open loop",
    "open_loop_rolling_helix": "rolling helix",
    "open_loop_tuned": "tuned open loop",
    "compliant_acl": "compliant ACL (tuned grip on the tuned gait)",
    "compliant_acl_same_cadence": "compliant ACL at the policy's cadence",
}

# Every metric of an evaluation record: key, label, scale, format (as acl-evaluate's table).
METRICS = (
    ("climb_per_cycle_m", "climb per nominal cycle (cm)", 100.0, ".2f"),
    ("climb_per_gait_cycle_m", "climb per gait cycle (cm)", 100.0, ".2f"),
    ("climb_speed_cm_s", "climb speed (cm/s)", 1.0, ".3f"),
    ("slip_per_cycle_m", "slip per nominal cycle (cm)", 100.0, ".2f"),
    ("slip_per_m", "slip per metre climbed", 1.0, ".3f"),
    ("energy_per_m", "energy (J/m)", 1.0, ".0f"),
    ("mean_abs_torque_nm", "mean abs torque (N m)", 1.0, ".3f"),
    ("torque_limit_fraction", "share at torque limit", 1.0, ".4f"),
    ("touched_arc_deg", "touched arc, mean (°)", 1.0, ".0f"),
    ("reward_per_gait_cycle", "reward per gait cycle", 1.0, ".4f"),
    ("action_change", "action change per step", 1.0, ".3f"),
)
SCALE_FORMAT = {key: (scale, fmt) for key, _, scale, fmt in METRICS}
HEADLINE = ("climb_per_gait_cycle_m", "slip_per_m", "energy_per_m")
RATIOS = (
    ("climb_per_gait_cycle_m", "climb per gait cycle"),
    ("slip_per_m", "slip per metre climbed"),
    ("energy_per_m", "energy per metre"),
)
OPEN_LOOP = (
    ("climb_per_cycle_m", "climb per cycle (cm)", 100.0, ".2f"),
    ("slip_per_cycle_m", "slip per cycle (cm)", 100.0, ".2f"),
    ("touched_arc_deg", "touched arc (°)", 1.0, ".0f"),
)


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:
    """Replace each results marker of a page by its table."""
    docs_dir = Path(config["docs_dir"])

    def render(match: re.Match[str]) -> str:
        name, view = match.group(1), match.group(2)
        where = f"{page.file.src_uri}: <!-- results: {name} {view} -->"
        if view not in VIEWS:
            raise PluginError(f"{where}: unknown view {view!r} (one of {', '.join(VIEWS)})")
        path = docs_dir / name
        if not path.is_file():
            raise PluginError(f"{where}: no file {path}")
        try:
            record = json.loads(path.read_text())
            return VIEWS[view](record, name, docs_dir)
        except (KeyError, TypeError, ValueError) as err:
            raise PluginError(f"{where}: the record lacks what this view needs ({err!r})") from err

    return MARKER.sub(render, markdown)


def _table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def _interval(summary: dict[str, Any], scale: float, fmt: str, sign: str = "") -> str:
    mean, half = summary["mean"] * scale, summary["half_width"] * scale
    return f"{mean:{sign}{fmt}} ± {half:{fmt}}"


def _label(name: str) -> str:
    return f"{LABELS.get(name, name)} (`{name}`)"


def _task(record: dict[str, Any], docs_dir: Path) -> str:
    """The registered id the policy was trained on (its policy.json's ``env_id``); the record
    names the id it ran, a benchmark task spelled as its base id and keyword arguments."""
    metadata = docs_dir.parent / (record.get("policy") or "-") / "policy.json"
    if metadata.is_file():
        return json.loads(metadata.read_text())["env_id"]
    return record["env_ids"]["policy"]


def _headline(record: dict[str, Any], name: str, docs_dir: Path) -> str:
    controllers = record["controllers"]
    header = [
        f"`{_task(record, docs_dir)}`",
        "climb per gait cycle (cm)",
        "slip per metre climbed",
        "energy (J/m)",
        "largest touched arc (°)",
        "falls",
        "keyframes per step",
    ]
    rows = []
    for controller, summary in controllers.items():
        cells = [_interval(summary[metric], *SCALE_FORMAT[metric]) for metric in HEADLINE]
        if controller == "policy":
            cells = [f"**{c}**" for c in cells]
        rows.append(
            [
                _label(controller),
                *cells,
                f"{max(summary['touched_arc_deg']['values']):.0f}",
                f"{summary['falls']['count']}/{summary['episodes']}",
                f"{summary['mean_phase_rate']:.2f}",
            ]
        )
    episodes = next(iter(controllers.values()))["episodes"]
    caption = f"Mean ± 95 % interval half-width over {episodes} starts ({record['ci']})."
    return _table(header, rows) + "\n\n" + caption


def _metrics(record: dict[str, Any], name: str, docs_dir: Path) -> str:
    controllers = record["controllers"]
    summaries = controllers.values()
    header = ["metric", *(f"`{c}`" for c in controllers)]
    rows = [
        [label, *(_interval(s[key], scale, fmt) if key in s else "n/a" for s in summaries)]
        for key, label, scale, fmt in METRICS
    ]
    rows.append(["falls", *(f"{s['falls']['count']}/{s['episodes']}" for s in summaries)])
    rows.append(["unstable", *(str(s["unstable"]) for s in summaries)])
    rows.append(["rolled", *(str(s["rolled"]) for s in summaries)])
    body = _table(header, rows).replace("\n", "\n    ")
    return f'??? info "Every metric of `{name}`"\n\n    {body}\n'


def _paired(record: dict[str, Any], name: str, docs_dir: Path) -> str:
    paired = record.get("paired_vs_policy")
    if not paired:
        return (
            f"*`{name}` holds no paired differences; `acl-evaluate` prints them, and "
            "`acl-compare` pairs two records seed by seed.*"
        )
    keys = (*HEADLINE, "reward_per_gait_cycle")
    metrics = [(k, label, scale, fmt) for k, label, scale, fmt in METRICS if k in keys]
    header = ["policy minus", *(label for _, label, _, _ in metrics)]
    rows = [
        [_label(controller), *(_interval(d[k], s, f, "+") for k, _, s, f in metrics)]
        for controller, d in paired.items()
    ]
    return _table(header, rows) + "\n\nPaired over the same seeds, mean ± 95 % interval half-width."


def _ratios(record: dict[str, Any], name: str, docs_dir: Path) -> str:
    controllers = record["controllers"]
    policy = controllers["policy"]
    header = ["policy ÷", *(label for _, label in RATIOS)]
    rows = [
        [_label(c), *(f"{policy[k]['mean'] / s[k]['mean']:.2f}\u00d7" for k, _ in RATIOS)]
        for c, s in controllers.items()
        if c != "policy"
    ]
    return _table(header, rows) + "\n\nThe policy's mean over each controller's mean."


def _notes(record: dict[str, Any], name: str, docs_dir: Path) -> str:
    task, ran = _task(record, docs_dir), record["env_ids"]["policy"]
    spelled = "" if task == ran else f" (run as `{ran}` with the task's keyword arguments)"
    lines = [f"- **Task:** `{task}`{spelled}, policy `{record['policy']}`."]
    weights = record.get("env_kwargs", {}).get("policy", {}).get("reward_weights")
    if weights:
        terms = ", ".join(f"{k} {v:g}" for k, v in weights.items())
        lines.append(f"- **Reward weights** (every controller): {terms}.")
    lines += [f"- {note}" for note in record.get("notes", [])]
    lines.append(_made_by(name, docs_dir))
    return "\n".join(lines)


def _made_by(name: str, docs_dir: Path) -> str:
    """The command that wrote ``name``, from ``docs/records.json`` when it names it."""
    records = docs_dir / "records.json"
    entry = json.loads(records.read_text()).get(f"docs/{name}") if records.is_file() else None
    if entry:
        return f"- **Made by:** `{entry['command']}` ({entry.get('made', 'date unrecorded')})."
    return f"- **File:** [`docs/{name}`]({name})."


def _open_loop(record: dict[str, Any], name: str, docs_dir: Path) -> str:
    header = ["gait", *(label for _, label, _, _ in OPEN_LOOP), "falls", "episodes"]
    rows = []
    for gait, m in record.items():
        cells = [f"{m[k] * s:{f}} ± {m[k + '_std'] * s:{f}}" for k, _, s, f in OPEN_LOOP]
        rows.append([gait, *cells, f"{m['falls']}/{m['n']}", str(m["n"])])
    caption = "Mean ± standard deviation over the episodes."
    return _table(header, rows) + "\n\n" + caption + "\n\n" + _made_by(name, docs_dir)


VIEWS = {
    "headline": _headline,
    "metrics": _metrics,
    "paired": _paired,
    "ratios": _ratios,
    "notes": _notes,
    "open_loop": _open_loop,
}
