"""The README's results tables say what the published records say (docs/eval.json,
docs/eval_servo.json and docs/eval_noroll.json, made by benchmarks/regenerate.py): a regeneration
that changes a number fails here until the README is updated."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from acl_env.evaluation import records

ROOT = Path(__file__).resolve().parents[1]
ACL_ROWS = {
    "residual PPO (shipped)": "policy",
    "tuned ACL at the policy's cadence": "open_loop_acl_same_cadence",
    "tuned ACL": "open_loop_tuned",
    "ACL, the paper's default gait": "open_loop_acl",
    "rolling helix": "open_loop_rolling_helix",
}
ACL_COLUMNS = [("climb_per_gait_cycle_m", 100, 2), ("slip_per_m", 1, 3), ("energy_per_m", 1, 0)]
NOROLL_ROWS = {
    "residual PPO (shipped)": "policy",
    "tuned non-rolling ACL (its gait)": "open_loop_tuned",
    "rolling helix (rolls: 360° of skin touched)": "open_loop_rolling_helix",
}
ROWS = {
    "eval_servo.json": ACL_ROWS,
    "eval.json": {
        "residual PPO (shipped)": "policy",
        "tuned ACL at the policy's cadence": "open_loop_acl_same_cadence",
        "tuned ACL": "open_loop_tuned",
        "ACL, the paper's default gait": "open_loop_acl",
        "rolling helix": "open_loop_rolling_helix",
    },
    "eval_noroll_servo.json": NOROLL_ROWS,
    "eval_noroll.json": {
        "residual PPO (shipped)": "policy",
        "tuned non-rolling ACL (its gait)": "open_loop_tuned",
        "rolling helix (rolls: 360° of skin touched)": "open_loop_rolling_helix",
    },
}
ROWS["eval_compliant.json"] = {
    "residual PPO on the compliant grip (shipped)": "policy",
    "tuned ACL at the policy's cadence": "open_loop_acl_same_cadence",
    "compliant ACL at the policy's cadence": "compliant_acl_same_cadence",
    "tuned ACL": "open_loop_tuned",
    "compliant ACL": "compliant_acl",
}
# Columns of each table: metric, scale, decimals (None: the largest value, as a whole number).
COLUMNS = {
    "eval_compliant.json": ACL_COLUMNS,
    "eval_servo.json": ACL_COLUMNS,
    "eval.json": [
        ("climb_per_gait_cycle_m", 100, 2),
        ("slip_per_m", 1, 3),
        ("energy_per_m", 1, 0),
    ],
    "eval_noroll_servo.json": [
        ("climb_per_gait_cycle_m", 100, 2),
        ("slip_per_m", 1, 2),
        ("energy_per_m", 1, 0),
        ("touched_arc_deg", 1, None),
    ],
    "eval_noroll.json": [
        ("climb_per_gait_cycle_m", 100, 2),
        ("slip_per_m", 1, 2),
        ("energy_per_m", 1, 0),
        ("touched_arc_deg", 1, None),
    ],
}


def _table_rows(text: str, header: str) -> dict[str, list[str]]:
    """The rows of the README table whose first header cell is ``header``, by first cell."""
    lines = text.splitlines()
    start = next(
        i
        for i, line in enumerate(lines[:-1])
        if line.startswith(f"| `{header}` |") and lines[i + 1].startswith("|---")
    )
    rows = {}
    for line in lines[start + 2 :]:
        if not line.startswith("|"):
            break
        cells = [cell.strip().strip("*") for cell in line.strip("|").split("|")]
        rows[cells[0]] = cells[1:]
    return rows


@pytest.mark.parametrize(
    ("record_name", "header"),
    [
        ("eval.json", "acl_env/ACLClimb-v3"),
        ("eval_compliant.json", "acl_env/ACLClimbCompliant-v1"),
        ("eval_servo.json", "acl_env/ACLClimbServo-v1"),
        ("eval_noroll.json", "acl_env/ACLClimbNoRoll-v5"),
        ("eval_noroll_servo.json", "acl_env/ACLClimbNoRollServo-v1"),
    ],
)
def test_readme_results_table_is_its_record(record_name: str, header: str) -> None:
    record = records.read_record(ROOT / "docs" / record_name)
    rows = _table_rows((ROOT / "README.md").read_text(), header)
    assert set(rows) == set(ROWS[record_name])
    for label, controller in ROWS[record_name].items():
        summary = records.controller_summary(record, controller)
        cells = rows[label]
        for cell, (metric, scale, decimals) in zip(cells, COLUMNS[record_name], strict=False):
            if decimals is None:
                expected = f"{max(summary[metric]['values']):.0f}"
            else:
                mean, half = summary[metric]["mean"] * scale, summary[metric]["half_width"] * scale
                expected = f"{mean:.{decimals}f} ± {half:.{decimals}f}"
            assert cell == expected, (label, metric)
        falls = summary["falls"]
        assert cells[-1] == f"{round(falls['mean'] * falls['n'])}/{falls['n']}", label


def test_readme_paired_sentence_is_the_record() -> None:
    """The non-rolling policy's paired differences over its gait, as the README states them."""
    paired = records.read_record(ROOT / "docs" / "eval_noroll.json")["paired_vs_policy"]
    climb, slip = (paired["open_loop_tuned"][m] for m in ("climb_per_gait_cycle_m", "slip_per_m"))
    text = " ".join((ROOT / "README.md").read_text().split())
    sentence = re.search(r"climbs \+([\d.]+) ± ([\d.]+) cm per gait cycle more than its gait", text)
    assert sentence is not None
    assert sentence.groups() == (f"{climb['mean'] * 100:.2f}", f"{climb['half_width'] * 100:.2f}")
    assert f"slides {-slip['mean']:.2f} ± {slip['half_width']:.2f} m less per metre" in text


def test_readme_noroll_compliant_sentence_is_the_record() -> None:
    """The non-rolling residual on the compliant grip, as the README states it."""
    record = records.read_record(ROOT / "docs" / "eval_noroll_compliant.json")
    policy = records.controller_summary(record, "policy")
    climb, slip = policy["climb_per_gait_cycle_m"], policy["slip_per_m"]
    text = " ".join((ROOT / "README.md").read_text().split())
    expected = (
        f"residual climbs {climb['mean'] * 100:.2f} ± {climb['half_width'] * 100:.2f} cm per "
        f"gait cycle and slides {slip['mean']:.2f} per metre"
    )
    assert expected in text
    assert max(policy["touched_arc_deg"]["values"]) <= 90.0  # "its arcs within 90°"


def test_gitignore_covers_what_the_readme_commands_write() -> None:
    """``git status`` stays clean after the README's commands: every file they write into the
    clone (``--plot``, ``--video``, ``--snapshot`` outside docs/, training and tuning runs/,
    rl_zoo3's logs/, the docs site's build/) is ignored."""
    import shutil
    import subprocess

    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    text = (ROOT / "README.md").read_text()
    written = set(re.findall(r"--(?:plot|video|snapshot)\s+([\w./-]+)", text))
    written = {path for path in written if not path.startswith("docs/")}
    assert {"eval.png", "climb.mp4", "snake.png"} <= written
    written |= {"runs/x/model.zip", "logs/ppo/x", "build/site/index.html", "runs/tuned_gaits.json"}
    proc = subprocess.run(
        ["git", "check-ignore", "--no-index", *sorted(written)],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert set(proc.stdout.split()) == written


def test_readme_benchmark_sentence_is_the_record() -> None:
    """The grid's success rates, as the README states them (docs/benchmark_sea.json)."""
    import numpy as np

    from acl_env.io import read_json

    record = read_json(ROOT / "docs" / "benchmark_sea.json")
    cells = record["cells"].values()

    def rate(name: str) -> str:
        return f"{np.mean([c['controllers'][name]['success_rate'] for c in cells]):.2f}"

    text = " ".join((ROOT / "README.md").read_text().split())
    success = record["summary"]["all"]["scores"]["success_rate"]["policies"]
    assert len(success["per_seed"]) == 5
    low, high = success["ci95"]
    assert (
        f"holds the pole in {success['iqm']:.2f} of the episodes over its five training seeds "
        f"(interquartile mean; 95 % interval {low:.2f}-{high:.2f}; the shipped seed "
        f"{rate('policy:acl_climb_sea_ppo')})"
    ) in text
    assert f"the tuned gait in {rate('open_loop_tuned')}" in text
    assert f"the paper's untuned gait in {rate('open_loop_acl')}" in text
    assert f"the rolling helix in {rate('open_loop_rolling_helix')}" in text
    assert f"{len(record['cells'])}-cell grid" in text


def test_readme_compliant_benchmark_sentence_is_the_record() -> None:
    """The compliant recipe's grid success over its seeds and its grip's, as the README states
    them (docs/benchmark_compliant.json)."""
    import numpy as np

    from acl_env.io import read_json

    record = read_json(ROOT / "docs" / "benchmark_compliant.json")
    success = record["summary"]["all"]["scores"]["success_rate"]
    assert len(success["policies"]["per_seed"]) == 5
    grip = np.mean(
        [c["controllers"]["compliant_acl"]["success_rate"] for c in record["cells"].values()]
    )
    low, high = success["policies"]["ci95"]
    text = " ".join((ROOT / "README.md").read_text().split())
    assert (
        f"The compliant residual holds in {success['policies']['iqm']:.2f} ({low:.2f}-{high:.2f}) "
        f"over its five seeds, its grip alone in {grip:.2f}."
    ) in text


@pytest.mark.parametrize("name", ["eval_sea_seeds", "eval_compliant_seeds"])
def test_readme_seeds_sentence_is_the_record(name: str) -> None:
    """The SEA and compliant recipes over their five training seeds (interquartile mean,
    bootstrap interval over seeds, probability of improvement), as the README states them."""
    from acl_env.io import read_json

    record = read_json(ROOT / "docs" / f"{name}.json")
    over = record["over_seeds"]
    climb, slip, energy = (
        over[m] for m in ("climb_per_gait_cycle_m", "slip_per_m", "energy_per_m")
    )
    assert len(climb["per_seed"]) == 5
    text = " ".join((ROOT / "README.md").read_text().split())
    low, high = (100 * v for v in climb["ci95"])
    assert f"climb {100 * climb['iqm']:.2f} cm per gait cycle ({low:.2f}-{high:.2f})" in text
    assert f"slip {slip['iqm']:.3f} per metre ({slip['ci95'][0]:.3f}-{slip['ci95'][1]:.3f})" in text
    assert f"{energy['iqm']:.0f} J/m ({energy['ci95'][0]:.0f}-{energy['ci95'][1]:.0f})" in text
    for metric, name in ((climb, "climb"), (slip, "slip")):
        poi = metric["probability_of_improvement"]
        assert f"{name} {poi['mean']:.2f}" in text, name


def test_readme_robust_sentence_is_the_record() -> None:
    """The robust residuals' grid results as the README states them: v3's five seeds against the
    nominal SEA recipe's five at the nominal condition (docs/benchmark_robust_v3.json,
    docs/benchmark_sea.json), v1 and v2 with a plain critic, and v2 against v1
    (docs/benchmark_robust*.json, experiments/robust_residual)."""
    import numpy as np

    from acl_env.benchmark.summary import controllers_of
    from acl_env.io import read_json

    text = " ".join((ROOT / "README.md").read_text().split())
    v3 = read_json(ROOT / "docs" / "benchmark_robust_v3.json")
    assert v3["settings"]["task"] == "acl_env/ACLClimbRobust-v3"
    rates = v3["summary"]["all"]["scores"]["success_rate"]
    assert len(rates["policies"]["per_seed"]) == 5  # "over its five seeds"
    assert set(rates["policies"]["per_seed"].values()) == {1.0}  # "every episode of every cell"
    assert rates["analytic"]["open_loop_tuned"] == 1.0  # "as its gait alone does"
    low, high = rates["policies"]["ci95"]
    assert f"(IQM {rates['policies']['iqm']:.2f} [{low:.2f}, {high:.2f}]; not shipped)" in text
    sea = read_json(ROOT / "docs" / "benchmark_sea.json")

    def nominal(record: dict, score: str) -> float:
        results = record["cells"]["nominal"]["controllers"]
        return float(np.mean([results[p][score]["mean"] for p in controllers_of(record)[0]]))

    climb, slip = (
        nominal(v3, score) / nominal(sea, score)
        for score in ("climb_per_gait_cycle_m", "slip_per_m")
    )
    assert f"climbs {climb:.2f}x as far as the nominal recipe at the nominal condition" in text
    assert f"and slides {slip:.2f}x as much" in text
    for name, task in (("", "v1"), ("_v2", "v2")):
        record = read_json(ROOT / "docs" / f"benchmark_robust{name}.json")
        assert record["settings"]["task"] == f"acl_env/ACLClimbRobust-{task}"
        (policy,) = record["summary"]["all"]["scores"]["success_rate"]["policies"][
            "per_seed"
        ].values()
        assert f"the residuals hold in {policy:.2f}, falling on the slipperiest trunk" in text, task
        (falling,) = record["summary"]["limits"].values()
        assert falling["cells_falling_more_than_best_analytic"] == ["friction=0.4,pole_radius=0.12"]
    merged = read_json(ROOT / "experiments/robust_residual/against_every_analytic.json")
    ratios = merged["v2_over_v1"]
    climb, slip = (ratios[m]["median"] for m in ("climb_per_gait_cycle_m", "slip_per_m"))
    assert f"climbs {climb:.2f}x as far as v1's at the median cell" in text
    assert f"but slides {slip:.2f}x as much" in text


def test_readme_past_the_grid_sentence_is_the_record() -> None:
    """The README's sentence on the grid's edge: at friction 0.35 on the trunk every seed of v3
    falls in every episode, its compliant controller in none (experiments/robust_residual)."""
    from acl_env.io import read_json

    text = " ".join((ROOT / "README.md").read_text().split())
    assert "at friction 0.35 on the trunk, every v3 seed always falls where its compliant" in text
    record = read_json(ROOT / "experiments/robust_residual/beyond_grid/v3_friction0.35_trunk.json")
    assert record["env_kwargs"]["compliant_acl"]["friction"] == 0.35
    assert record["env_kwargs"]["compliant_acl"]["pole_radius"] == 0.12
    controllers = record["controllers"]
    policies = [name for name in controllers if name.startswith("policy:")]
    assert len(policies) == 5 and all("robust_v3" in name for name in policies)
    for name in policies:
        assert controllers[name]["falls"]["count"] == controllers[name]["episodes"] == 10
    for name in ("compliant_acl", "compliant_acl_same_cadence"):
        assert controllers[name]["falls"]["count"] == 0
        assert min(controllers[name]["climb_per_gait_cycle_m"]["values"]) > 0
