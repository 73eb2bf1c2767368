"""experiments/robust_residual/against_every_analytic.py and
experiments/robust_ablation/ablation_table.py, on the published robust benchmark records."""

from __future__ import annotations

import copy
import json
import runpy
from pathlib import Path
from typing import Any

import pytest

from acl_env.io import read_json

ROOT = Path(__file__).resolve().parent.parent
V1, V2 = (ROOT / "docs" / f"benchmark_robust{s}.json" for s in ("", "_v2"))


def _script(*parts: str) -> dict[str, Any]:
    """A script's functions (the experiments are not modules of the package)."""
    return runpy.run_path(str(ROOT.joinpath("experiments", *parts)), run_name="script")


@pytest.fixture(scope="module")
def records() -> dict[str, dict[str, Any]]:
    return {"v1": read_json(V1), "v2": read_json(V2)}


def test_merge_keeps_one_copy_of_the_controllers_both_play_alike(records: dict) -> None:
    merge = _script("robust_residual", "against_every_analytic.py")["merge"]
    merged = merge(records)
    names = list(merged["cells"]["nominal"]["controllers"])
    # The paper's gait and the helix play the same episodes on both tasks: one copy each.
    assert names.count("open_loop_acl") == 1 and names.count("open_loop_rolling_helix") == 1
    # Each task's own gait and grip are kept apart, under the task's name.
    for task in ("v1", "v2"):
        assert f"{task}:open_loop_tuned" in names and f"{task}:compliant_acl" in names
    policies = [n for n in names if n.startswith("policy:")]
    assert len(policies) == 2
    cell = merged["cells"]["friction=0.4,pole_radius=0.12"]["controllers"]
    assert (
        cell["v1:open_loop_tuned"]
        == records["v1"]["cells"]["friction=0.4,pole_radius=0.12"]["controllers"]["open_loop_tuned"]
    )


def test_merge_refuses_records_of_other_seeds(records: dict) -> None:
    merge = _script("robust_residual", "against_every_analytic.py")["merge"]
    other = copy.deepcopy(records["v2"])
    other["settings"]["seeds"] = other["settings"]["seeds"][:-1]
    with pytest.raises(ValueError, match="other seeds"):
        merge({"v1": records["v1"], "v2": other})


def test_ablation_rows_are_the_records_scores(records: dict) -> None:
    arm_row = _script("robust_ablation", "ablation_table.py")["arm_row"]
    for record in records.values():
        row = arm_row(record)
        summary = record["summary"]["all"]["scores"]["success_rate"]["policies"]["per_seed"]
        (policy, rate), = summary.items()  # fmt: skip
        assert row["success"] == pytest.approx(rate)
        nominal = record["cells"]["nominal"]["controllers"][policy]
        assert row["nominal_slip_per_m"] == nominal["slip_per_m"]["mean"]
        limits = record["summary"]["limits"][policy]
        assert (
            row["cells_falling_more_than_best_analytic"]
            == limits["cells_falling_more_than_best_analytic"]
        )


def test_ablation_arm_over_seeds_is_the_mean_of_its_seeds(tmp_path: Path, records: dict) -> None:
    """An arm given two records (ARM= twice) is summarised over them: means, each seed's
    success and falling cells; the figure has a row per seed."""
    main = _script("robust_ablation", "ablation_table.py")["main"]
    plot = tmp_path / "arms.png"
    document = main([f"arm={V1}", f"arm={V2}", f"one={V1}", "--plot", str(plot)])
    arm, one = document["arms"]["arm"], document["arms"]["one"]
    assert arm["seeds"] == 2 and one["seeds"] == 1 and plot.is_file()
    rows = arm["per_seed"]
    assert arm["success"] == pytest.approx((rows[0]["success"] + rows[1]["success"]) / 2)
    assert arm["success_per_seed"] == [rows[0]["success"], rows[1]["success"]]
    assert arm["cells_falling_per_seed"][0] == one["cells_falling_per_seed"][0]
    slips = [row["nominal_slip_per_m"] for row in rows]
    assert arm["nominal_slip_per_m"] == pytest.approx(sum(slips) / 2)


def test_ablation_rows_name_their_policys_training_seed(
    records: dict, monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """The seed comes from the exported policy's policy.json (paths in a record are the clone's),
    and labels the arm's row in the figure; unknown, the row's place among the arm's records."""
    script = _script("robust_ablation", "ablation_table.py")
    monkeypatch.chdir(ROOT)
    for record in records.values():
        (folder,) = record["settings"]["policies"]
        seed = read_json(ROOT / folder / "policy.json")["training"]["seed"]
        row = script["arm_row"](record)
        assert row["training_seed"] == seed and script["seed_label"](row, 3) == f"seed {seed}"
    monkeypatch.chdir(tmp_path)  # the exported folders are not here
    row = script["arm_row"](records["v1"])
    assert row["training_seed"] is None and script["seed_label"](row, 3) == "#4"


def test_ablation_table_refuses_arms_of_other_cells(tmp_path: Path, records: dict) -> None:
    main = _script("robust_ablation", "ablation_table.py")["main"]
    fewer = copy.deepcopy(records["v1"])
    del fewer["cells"]["nominal"]
    path = tmp_path / "fewer.json"
    path.write_text(json.dumps(fewer))
    with pytest.raises(SystemExit):
        main([f"base={V1}", f"fewer={path}"])


def test_tradeoff_points_are_the_records_scores(records: dict) -> None:
    """tradeoff.py: one point per controller, those both records play alike once; each point's
    success is its mean over the shared cells and its nominal scores are its nominal cell's."""
    points = _script("robust_residual", "tradeoff.py")["points"](records)
    assert [p["label"] for p in points].count("ACL, the paper's gait") == 1
    assert [p["label"] for p in points].count("rolling helix") == 1
    assert len(points) == 2 * 7 - 2  # a policy and six analytic controllers each, two shared
    for p in points:
        record = records[p["record"]]
        (name,) = (n for n, text in record["labels"].items() if text == p["label"])
        cells = record["cells"].values()
        rates = [cell["controllers"][name]["success_rate"] for cell in cells]
        assert p["success"] == pytest.approx(sum(rates) / len(rates)) and p["cells"] == 58
        nominal = record["cells"]["nominal"]["controllers"][name]
        assert p["nominal_slip_per_m"] == nominal["slip_per_m"]["mean"]
        kinds = {"policy": "policy:", "grip": "compliant_acl", "open": "open_loop_"}
        assert name.startswith(kinds[p["kind"]]), name


def test_squeeze_margin_offsets_the_records_tuned_gait_and_replays_it_at_zero() -> None:
    """squeeze_margin.py: each offset is the record's tuned gait in the cell with its squeeze
    raised; the published record's +0 mm episodes are the benchmark record's, seed by seed."""
    script = _script("robust_tuning", "squeeze_margin.py")
    record = read_json(ROOT / "docs" / "benchmark_sea.json")
    cell = "friction=0.4,pole_radius=0.12"
    base, raised = script["controllers"](record, cell, [0.0, 8.0])
    spec = record["settings"]["controllers"]["open_loop_tuned"]
    assert base.env_id == spec["env_id"] and base.env_kwargs["friction"] == 0.4
    assert base.env_kwargs == {**spec["env_kwargs"], "friction": 0.4, "pole_radius": 0.12}
    assert raised.env_kwargs["squeeze"] - base.env_kwargs["squeeze"] == pytest.approx(0.008)
    margin = read_json(ROOT / "experiments" / "robust_tuning" / "squeeze_margin.json")
    assert list(margin["cells"]) == script["cells_to_play"](record)
    for key, row in margin["cells"].items():
        theirs = record["cells"][key]["controllers"]["open_loop_tuned"]["climb_per_gait_cycle_m"]
        n = margin["episodes"]
        assert row["+0 mm"]["climb_per_gait_cycle_m"]["values"] == theirs["values"][:n], key


def test_modulation_grid_claims_are_its_record() -> None:
    """experiments/robust_modulation's grid answer, as docs/benchmark.md gives it: no fall off the
    0.12 m trunk, success 0.94, and the 3 cells where it falls more often than the best analytic
    controller all on the trunk."""
    record = read_json(ROOT / "experiments" / "robust_modulation" / "benchmark.json")
    ((policy, limits),) = record["summary"]["limits"].items()
    cells = record["cells"].items()
    rates = {key: cell["controllers"][policy]["success_rate"] for key, cell in cells}
    off_trunk = [rate for key, rate in rates.items() if "pole_radius=0.12" not in key]
    assert len(off_trunk) == 48 and min(off_trunk) == 1.0
    falling = limits["cells_falling_more_than_best_analytic"]
    assert len(falling) == 3 and all("pole_radius=0.12" in key for key in falling)
    assert f"{sum(rates.values()) / len(rates):.2f}" == "0.94"
    page = (ROOT / "docs" / "benchmark.md").read_text()
    assert "success 0.94" in page and "helix in 3 cells" in page.replace("\n", " ")


def test_seeds_against_pairs_the_seeds_mean_cell_by_cell(records: dict) -> None:
    """experiments/robust_residual/seeds_against.py: per score, the median over the cells where
    nothing falls of the seeds' mean over the controller's; another record's policies join as
    ``other:<name>``; records of other reset seeds are refused."""
    from acl_env.benchmark.summary import ratios_where_held

    script = _script("robust_residual", "seeds_against.py")
    seeds = read_json(ROOT / "experiments/robust_ablation/benchmark_asymmetric_critic_grid.json")
    merged = script["merge"](seeds, records["v1"])
    names = list(merged["cells"]["nominal"]["controllers"])
    assert "other:policy:acl_climb_robust_ppo_seed0" in names
    assert "other:open_loop_tuned" not in names  # the other's analytic controllers stay out
    policies = [n for n in names if n.startswith("policy:")]
    other = "other:policy:acl_climb_robust_ppo_seed0"
    found = ratios_where_held(merged, policies, other, script["SCORES"])["climb_per_gait_cycle_m"]
    by_hand = []
    for cell in merged["cells"].values():
        results = cell["controllers"]
        if all(results[n]["falls"] == 0 for n in [*policies, other]):
            mine = sum(results[p]["climb_per_gait_cycle_m"]["mean"] for p in policies)
            by_hand.append(mine / len(policies) / results[other]["climb_per_gait_cycle_m"]["mean"])
    assert found["cells"] == len(by_hand) == 57  # v1's residual falls at friction 0.4 on the trunk
    assert found["median"] == pytest.approx(sorted(by_hand)[len(by_hand) // 2])
    assert found["higher"] == sum(v > 1.0 for v in by_hand)
    fewer = copy.deepcopy(records["v1"])
    fewer["settings"]["seeds"] = fewer["settings"]["seeds"][:-1]
    with pytest.raises(ValueError, match="other reset seeds"):
        script["merge"](seeds, fewer)
