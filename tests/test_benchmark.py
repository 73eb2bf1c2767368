"""acl-benchmark: the condition grids, the runner against a direct run_episode loop, resuming, and
the statistics over training seeds against SciPy."""

from __future__ import annotations

import copy
import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy import stats as scipy_stats

import acl_env
from acl_env import ACL_CLIMB_ROBUST_ID, shipped
from acl_env.benchmark import grid as grids
from acl_env.benchmark import run as bench
from acl_env.benchmark.summary import limits, summarize_benchmark
from acl_env.evaluation import baselines, run_episode
from acl_env.evaluation import statistics as stats


@pytest.mark.parametrize("task", sorted(grids.GRIDS))
def test_every_grid_has_48_cells_nominal_first_held_out_marked(task: str) -> None:
    grid = grids.grid_for(task)
    cells = grid.cells()
    assert len({c.key for c in cells}) == len(cells)
    sea = grid in (grids.SEA_GRID, grids.ROBUST_SEA_GRID)
    events = len(grid.events)
    assert len(cells) == (57 if sea else 51) + events  # docs/benchmark.md's counts
    assert cells[len(cells) - events :] == list(grid.events)
    cells = cells[: len(cells) - events]
    assert cells[0].key == "nominal" and not cells[0].held_out
    assert all(len(c.kwargs) <= 2 for c in cells)
    for cell in cells:
        outside = [k for k, v in cell.kwargs.items() if not grid.axis(k).trained(v)]
        assert cell.held_out == bool(outside), cell.key
    assert any(c.held_out for c in cells) and any(not c.held_out for c in cells)
    pole = grid.axis("pole_radius")
    assert min(pole.values) <= 0.055 and max(pole.values) >= 0.12
    friction = grid.axis("friction")
    if grid is grids.ROBUST_SEA_GRID:
        # the robust recipe trains over the whole grid but the trunk: the same cells as the
        # SEA tasks', held out only on the 0.12 m pole
        assert [c.key for c in cells] == [c.key for c in grids.SEA_GRID.cells()]
        assert all(c.held_out == (c.kwargs.get("pole_radius") == 0.12) for c in cells)
        assert grid.events == (grids.FRICTION_STEP,)  # and the friction step, held out
    else:
        assert sum(v < friction.training[0] for v in friction.values) >= 2


@pytest.mark.parametrize("task", sorted(grids.GRIDS))
def test_grid_training_ranges_are_the_recipe_randomisation(task: str) -> None:
    """The grid marks as trained what the shipped recipe's domain randomisation draws."""
    from acl_env.training import config

    drawn = config.load_hyperparams(shipped.recipe_path(), task)["env_kwargs"]
    drawn = drawn["domain_randomization"]
    grid = grids.grid_for(task)
    for axis in grid.axes:
        assert tuple(axis.training) == tuple(drawn[axis.name]), axis.name
    if grid is grids.SEA_GRID:
        spring = grid.axis("spring_stiffness").values
        assert min(spring) == pytest.approx(12.0) and max(spring) == pytest.approx(28.0)
        assert max(grid.axis("control_latency").values) == pytest.approx(0.2)


TWO_CELLS = grids.Grid(
    (
        grids.Axis("friction", (0.5, 1.0), 1.0, (0.7, 1.2)),
        grids.Axis("pole_radius", (0.075,), 0.075, (0.065, 0.09)),
    ),
    fixed={"cycles_per_episode": 1},
)
SEEDS = (0, 1)


@pytest.fixture(scope="module")
def two_policies(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    """The shipped SEA policy and an exported copy of it under another name."""
    folder = tmp_path_factory.mktemp("policies") / "seed_copy"
    shutil.copytree(shipped.policy_dir("acl_climb_sea_ppo"), folder)
    return [shipped.policy_dir("acl_climb_sea_ppo"), folder]


@pytest.fixture(scope="module")
def record(two_policies: list[Path], tmp_path_factory: pytest.TempPathFactory) -> dict:
    path = tmp_path_factory.mktemp("bench") / "bench.json"
    return bench.run_benchmark(acl_env.ACL_CLIMB_SEA_ID, two_policies, TWO_CELLS, SEEDS, path)


def test_record_is_a_direct_run_episode_loop(record: dict, two_policies: list[Path]) -> None:
    """Each cell's figures are those of playing the same controllers with run_episode."""
    assert list(record["cells"]) == ["nominal", "friction=0.5"]
    cell = record["cells"]["friction=0.5"]
    assert cell["held_out"] and not record["cells"]["nominal"]["held_out"]
    names = set(cell["controllers"])
    assert {"policy:acl_climb_sea_ppo", "policy:seed_copy", "open_loop_tuned"} <= names
    folder = baselines.read_policy(two_policies[1])
    kwargs = {"friction": 0.5, "cycles_per_episode": 1}
    controllers, _ = baselines.build_controllers(
        folder, kwargs, None, baselines.DEFAULT_TUNED_GAITS
    )
    by_name = {c.name: c for c in controllers}
    for name, recorded in (("policy", "policy:seed_copy"), ("open_loop_tuned", "open_loop_tuned")):
        controller = by_name[name]
        env = controller.make_env()
        policy = controller.make_policy(env)
        episodes = [run_episode(env, policy, seed) for seed in SEEDS]
        result = cell["controllers"][recorded]
        climbs = [e.metrics()["climb_per_gait_cycle_m"] for e in episodes]
        assert result["climb_per_gait_cycle_m"]["values"] == pytest.approx(climbs, rel=1e-9)
        assert result["success_rate"] == np.mean([bench.success(e) for e in episodes])
        assert result["falls"] == sum(e.fell for e in episodes)
    # The two copies of one policy measure the same.
    a, b = (cell["controllers"][f"policy:{n}"] for n in ("acl_climb_sea_ppo", "seed_copy"))
    assert a["climb_per_gait_cycle_m"]["values"] == b["climb_per_gait_cycle_m"]["values"]


def test_a_finished_record_resumes_without_running_and_other_settings_are_refused(
    record: dict, two_policies: list[Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "bench.json"
    acl_env.io.write_json(path, record)
    monkeypatch.setattr(bench, "run_cell", lambda *a, **k: pytest.fail("ran a finished cell"))
    again = bench.run_benchmark(acl_env.ACL_CLIMB_SEA_ID, two_policies, TWO_CELLS, SEEDS, path)
    assert again["cells"] == acl_env.io.read_json(path)["cells"]
    with pytest.raises(bench.SettingsMismatch, match="other settings"):
        bench.run_benchmark(acl_env.ACL_CLIMB_SEA_ID, two_policies, TWO_CELLS, (0, 1, 2), path)
    # A record whose analytic controllers were other gaits (made by other code) is refused too,
    # and with remake made again from the start: every cell is run.
    stale = copy.deepcopy(record)
    stale["settings"]["controllers"]["open_loop_tuned"]["env_kwargs"]["squeeze"] = 0.0
    acl_env.io.write_json(path, stale)
    with pytest.raises(bench.SettingsMismatch, match="analytic controllers"):
        bench.run_benchmark(acl_env.ACL_CLIMB_SEA_ID, two_policies, TWO_CELLS, SEEDS, path)
    ran: list[dict] = []
    monkeypatch.setattr(bench, "run_cell", lambda *a, **k: ran.append(a[1]) or ({}, {}))
    made = bench.run_benchmark(
        acl_env.ACL_CLIMB_SEA_ID, two_policies, TWO_CELLS, SEEDS, path, remake=True
    )
    assert len(ran) == len(TWO_CELLS.cells()) and made["settings"] == record["settings"]


def test_a_selection_of_cells_plays_those_cells_as_the_whole_grid_does(
    record: dict, two_policies: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--cells``: only the named cells, with the figures the whole grid's record has for them;
    the selection is in the settings, so a whole-grid run does not resume it."""
    from acl_env.benchmark.cli import main

    selected = TWO_CELLS.select(["friction=0.5"])
    assert [c.key for c in selected.cells()] == ["friction=0.5"]
    path = tmp_path / "some.json"
    some = bench.run_benchmark(acl_env.ACL_CLIMB_SEA_ID, two_policies, selected, SEEDS, path)
    assert list(some["cells"]) == ["friction=0.5"]
    assert some["cells"]["friction=0.5"] == record["cells"]["friction=0.5"]
    assert some["settings"]["cells"] == ["friction=0.5"] and "cells" not in record["settings"]
    with pytest.raises(bench.SettingsMismatch):
        bench.run_benchmark(acl_env.ACL_CLIMB_SEA_ID, two_policies, TWO_CELLS, SEEDS, path)
    with pytest.raises(ValueError, match=r"no cell 'friction=0\.3' in the grid"):
        TWO_CELLS.select(["nominal", "friction=0.3"])
    with pytest.raises(SystemExit) as exit_:
        main(["--cells", "friction=0.3", "--json", str(tmp_path / "x.json")])
    assert exit_.value.code == 2
    assert "argument --cells: no cell 'friction=0.3'" in capsys.readouterr().err
    assert not (tmp_path / "x.json").exists()


def test_reuse_takes_the_analytic_controllers_a_record_played_alike(
    record: dict, two_policies: list[Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--reuse``: another record's analytic controllers that play alike are taken from it, not
    played; the policies and the open loops at their cadence are played; the results are those
    playing them would give (episodes are deterministic in their seed)."""
    played: list[str] = []
    evaluate = bench.evaluate

    def counting(controllers: list, *args: object, **kwargs: object) -> dict:
        played.extend(c.name for c in controllers)
        return evaluate(controllers, *args, **kwargs)

    monkeypatch.setattr(bench, "evaluate", counting)
    one = two_policies[:1]
    path = tmp_path / "one.json"
    made = bench.run_benchmark(acl_env.ACL_CLIMB_SEA_ID, one, TWO_CELLS, SEEDS, path, reuse=record)
    reused = set(bench.reusable(made["settings"], record))
    assert reused and not reused & set(baselines.AT_POLICY_CADENCE)
    assert not reused & set(played) and "policy:acl_climb_sea_ppo" in played
    for key, cell in made["cells"].items():
        assert set(cell["reused"]) == reused
        for name in reused:
            assert cell["controllers"][name] == record["cells"][key]["controllers"][name]
    # Played without reuse, the same record: the reused results are what playing gives.
    plain = bench.run_benchmark(
        acl_env.ACL_CLIMB_SEA_ID, one, TWO_CELLS, SEEDS, tmp_path / "p.json"
    )
    assert all(
        plain["cells"][k]["controllers"] == made["cells"][k]["controllers"] for k in plain["cells"]
    )
    # Another task's record of the same controllers and cells: the same reuse.
    assert set(bench.reusable({**made["settings"], "task": "acl_env/Other-v0"}, record)) == reused
    # Another seed set, or another gait: nothing to reuse.
    assert bench.reusable({**made["settings"], "seeds": [5, 6]}, record) == []
    other = copy.deepcopy(record)
    other["settings"]["controllers"]["open_loop_tuned"]["env_kwargs"]["squeeze"] = 0.0
    assert "open_loop_tuned" not in bench.reusable(made["settings"], other)


def test_reuse_sets_aside_the_kwargs_that_only_add_observations(record: dict) -> None:
    """An analytic controller played with ``privileged_obs`` or ``obs_history`` (a task whose
    observation has the privileged block, ACLClimbRobust-v3's) is reused from a record that played
    it without: the env's steps, rewards and infos are the same with them, on a slippery pole
    with a friction step, late commands and the compliant grip."""
    import gymnasium as gym

    conditions = {"friction": 0.4, "control_latency": 0.2, "friction_step": 0.5}
    plain = gym.make(acl_env.ACL_CLIMB_COMPLIANT_ID, **conditions)
    observed = gym.make(
        acl_env.ACL_CLIMB_COMPLIANT_ID, privileged_obs=True, obs_history=2, **conditions
    )
    rng = np.random.default_rng(1)
    for env in (plain, observed):
        env.reset(seed=5)
    for _ in range(120):
        action = rng.uniform(-1, 1, plain.action_space.shape).astype(np.float32)
        (short, *rest), (long, *theirs) = plain.step(action), observed.step(action)
        assert rest == theirs
        np.testing.assert_array_equal(short, long[: len(short)])
    wanted = copy.deepcopy(record["settings"])
    for spec in wanted["controllers"].values():
        spec["env_kwargs"]["privileged_obs"] = True
    assert bench.reusable(wanted, record) == bench.reusable(record["settings"], record)
    assert bench.reusable(wanted, record)


def test_reuse_of_an_unreadable_record_names_the_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from acl_env.benchmark.cli import main

    with pytest.raises(SystemExit) as exit_:
        main(["--reuse", str(tmp_path / "none.json"), "--json", str(tmp_path / "x.json")])
    assert exit_.value.code == 2
    assert "argument --reuse: cannot read" in capsys.readouterr().err
    assert not (tmp_path / "x.json").exists()


def test_policies_of_one_folder_name_are_refused(two_policies: list[Path]) -> None:
    """Records name each seed by its folder: two of one name would merge into one seed."""
    from acl_env.evaluation.runner import PolicySetError, policies_controllers

    with pytest.raises(PolicySetError, match="share a folder name"):
        policies_controllers([two_policies[0], two_policies[0]], {})
    compliant = shipped.policy_dir("acl_climb_compliant_ppo")
    with pytest.raises(PolicySetError, match="another task"):
        policies_controllers([two_policies[0], compliant], {})


def _cell(held_out: bool, **falls: int) -> dict:
    """A record cell of 10 episodes per controller, ``falls`` of each falling (success: the
    others)."""
    return {
        "held_out": held_out,
        "controllers": {
            name: {"episodes": 10, "falls": n, "success_rate": (10 - n) / 10}
            for name, n in falls.items()
        },
    }


def test_limits_cell_by_cell() -> None:
    """Issue 48's measures, counted on a record made by hand."""
    record = {
        "cells": {
            # the policy falls once where an analytic controller never does
            "a": _cell(False, **{"policy:p": 1, "open_loop_acl": 0, "open_loop_tuned": 3}),
            # held out, an analytic controller reliable (0 falls), the policy too
            "b": _cell(True, **{"policy:p": 0, "open_loop_acl": 0, "open_loop_tuned": 10}),
            # held out, reliable analytic, the policy not (2 falls): also falls more
            "c": _cell(True, **{"policy:p": 2, "open_loop_acl": 10, "open_loop_tuned": 0}),
            # every analytic controller falls in most episodes; the policy holds in half
            "d": _cell(True, **{"policy:p": 5, "open_loop_acl": 6, "open_loop_tuned": 9}),
            # the same, the policy falls in 6
            "e": _cell(False, **{"policy:p": 6, "open_loop_acl": 6, "open_loop_tuned": 10}),
        }
    }
    found = limits(record)["policy:p"]
    assert found["cells_falling_more_than_best_analytic"] == ["a", "c"]
    assert found["held_out_reliable_cells"] == 2 and found["held_out_reliable_cells_held"] == 1
    assert found["cells_every_analytic_loses"] == ["d", "e"]
    assert found["cells_every_analytic_loses_held"] == ["d"]


def test_summary_over_seeds(record: dict) -> None:
    summary = summarize_benchmark(record)
    climb = summary["scores"]["climb_per_gait_cycle_m"]
    per_seed = list(climb["policies"]["per_seed"].values())
    assert len(per_seed) == 2 and per_seed[0] == per_seed[1]
    assert climb["policies"]["ci95"] == [per_seed[0], per_seed[0]]
    poi = climb["probability_of_improvement"]
    assert 0.0 <= poi["mean"] <= 1.0 and poi["cells"] == 2
    assert summarize_benchmark(record, held_out_only=True)["cells"] == 1


def test_iqm_and_bootstrap_interval_are_scipys() -> None:
    values = np.array([3.0, 1.0, 9.0, 4.0, 2.0, 8.0, 5.0, 7.0])
    assert stats.iqm(values) == pytest.approx(np.mean([3, 4, 5, 7]))
    assert stats.iqm(values) == pytest.approx(scipy_stats.trim_mean(values, 0.25))
    low, high = stats.bootstrap_interval(values, np.mean, seed=3)
    direct = scipy_stats.bootstrap(
        (values,),
        np.mean,
        n_resamples=stats.RESAMPLES,
        method="percentile",
        rng=np.random.default_rng(3),
    ).confidence_interval
    # resampling indices or values draws the same samples: the same interval, near enough
    assert (low, high) == pytest.approx((direct.low, direct.high), abs=0.2)
    assert low < np.mean(values) < high


def test_probability_of_improvement_is_mann_whitney() -> None:
    rng = np.random.default_rng(0)
    x, y = rng.normal(size=(5, 3)), rng.normal(0.5, 1.0, size=(4, 3))
    per_cell = stats.probability_of_improvement(x, y)
    for j in range(3):
        u = scipy_stats.mannwhitneyu(x[:, j], y[:, j]).statistic
        assert per_cell[j] == pytest.approx(u / (5 * 4))
    assert stats.probability_of_improvement(x, y, higher_is_better=False) == pytest.approx(
        1 - per_cell
    )
    ties = stats.probability_of_improvement(np.ones((2, 1)), np.ones(1))
    assert ties == pytest.approx([0.5])


def test_two_recipes_compare_over_seeds() -> None:
    better, worse = [0.30, 0.31, 0.29, 0.32, 0.30], [0.25, 0.26, 0.24, 0.27, 0.25]
    result = stats.compare_samples(better, worse)
    assert result["probability_of_improvement"]["mean"] == 1.0
    assert result["iqm_difference"]["mean"] == pytest.approx(stats.iqm(better) - stats.iqm(worse))
    low, high = result["iqm_difference"]["ci95"]
    assert 0.0 < low <= result["iqm_difference"]["mean"] <= high
    lower_is_better = stats.compare_samples(better, worse, higher_is_better=False)
    assert lower_is_better["probability_of_improvement"]["mean"] == 0.0


def test_acl_evaluate_and_acl_compare_over_training_seeds(
    two_policies: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Several policies of one recipe: each plays beside the analytic controllers, the record
    holds the summary over seeds, and acl-compare pairs two such records as recipes."""
    from acl_env.evaluation.cli import main as evaluate_main
    from acl_env.evaluation.compare import main as compare_main

    argv = ["--policy", *map(str, two_policies), "--episodes", "2", "--workers", "1"]
    argv += ["--env-kwargs", "cycles_per_episode:1", "--no-progress-bar"]
    document = evaluate_main([*argv, "--json", str(tmp_path / "a.json")])
    assert {"policy:acl_climb_sea_ppo", "policy:seed_copy"} <= set(document["controllers"])
    assert "policy" not in document["controllers"] and "paired_vs_policy" not in document
    climb = document["over_seeds"]["climb_per_gait_cycle_m"]
    assert len(climb["per_seed"]) == 2 and climb["best_analytic"]["controller"] != "policy"
    assert "over 2 training seeds" in capsys.readouterr().out
    shutil.copy(tmp_path / "a.json", tmp_path / "b.json")
    result = compare_main([str(tmp_path / "a.json"), str(tmp_path / "b.json")])
    entry = result["over_seeds"]["climb_per_gait_cycle_m"]
    assert entry["probability_of_improvement"]["mean"] == 0.5
    assert entry["iqm_difference"]["mean"] == 0.0


def test_an_event_is_a_cell_and_the_published_records_are_todays() -> None:
    """The robust grid's friction step is its last cell, held out, in the record's settings.
    Each published record's settings, its analytic controllers included, are those its command
    makes with the code as it is: the record is what that command would write today."""
    from acl_env.benchmark.run import settings
    from acl_env.io import read_json

    root = Path(__file__).resolve().parents[1]
    robust = grids.grid_for(ACL_CLIMB_ROBUST_ID)
    last = robust.cells()[-1]
    assert last.key == "friction_step=0.5" and last.held_out
    assert robust.env_kwargs(last) == {"friction_step": 0.5}
    made = settings(ACL_CLIMB_ROBUST_ID, [], robust, [0], root / "acl_env/data/tuned_gaits.json")
    assert made["events"] == [{"friction_step": 0.5}]
    for name in ("benchmark_sea", "benchmark_compliant", "benchmark_robust", "benchmark_robust_v2"):
        published = read_json(root / f"docs/{name}.json")["settings"]
        again = settings(
            published["task"],
            [root / p for p in published["policies"]],
            grids.grid_for(published["task"]),
            published["seeds"],
            root / published["tuned_gaits"],
        )
        assert again == published, name


def test_heat_maps_draw_the_events_in_a_column_of_their_own(record: dict, tmp_path: Path) -> None:
    """A record's heat maps, and the same record with an event: one panel wider."""
    import copy

    import matplotlib.image

    from acl_env.benchmark.figures import plot_heat_maps

    plain, with_event = tmp_path / "plain.png", tmp_path / "event.png"
    plot_heat_maps(record, "success_rate", plain)
    evented = copy.deepcopy(record)
    evented["settings"]["events"] = [{"friction_step": 0.5}]
    evented["cells"]["friction_step=0.5"] = copy.deepcopy(record["cells"]["friction=0.5"])
    plot_heat_maps(evented, "success_rate", with_event)
    height, width = matplotlib.image.imread(plain).shape[:2]
    assert matplotlib.image.imread(with_event).shape[:2] == (height, 2 * width)


def test_heat_map_colours_span_the_bulk_of_the_values_not_an_outlier(record: dict) -> None:
    """The colour map's ends: 0 and 1 for the success rate; the 2nd and 98th percentiles for
    the other scores, so one controller sliding metres in one cell leaves the rest readable."""
    import copy

    from acl_env.benchmark.figures import _value_range
    from acl_env.benchmark.summary import controllers_of

    policies, analytic = controllers_of(record)
    rows = ["policies", *analytic]
    assert _value_range(record, rows, policies, "success_rate", 1.0) == (0.0, 1.0)
    slips = [
        cell["controllers"][name]["slip_per_m"]["mean"]
        for cell in record["cells"].values()
        for name in [*policies, *analytic]
    ]
    low, high = _value_range(record, rows, policies, "slip_per_m", 1.0)
    assert min(slips) <= low <= high <= max(slips)
    # a grid's worth of cells (30 copies of the record's), one of them an outlier
    big = copy.deepcopy(record)
    big["cells"] = {
        f"{key}#{i}": copy.deepcopy(cell)
        for i in range(15)
        for key, cell in record["cells"].items()
    }
    assert _value_range(big, rows, policies, "slip_per_m", 1.0)[1] <= max(slips)
    outlier = copy.deepcopy(big)
    outlier["cells"]["nominal#0"]["controllers"][analytic[0]]["slip_per_m"]["mean"] = 100.0
    assert _value_range(outlier, rows, policies, "slip_per_m", 1.0)[1] <= max(slips)


def test_benchmark_page_glance_table_is_the_records() -> None:
    """docs/benchmark.md's table of every task's grid result: each row as its record has it."""
    from acl_env.benchmark.summary import controllers_of
    from acl_env.io import read_json

    root = Path(__file__).resolve().parents[1]
    page = (root / "docs" / "benchmark.md").read_text()

    def span(values: list[int]) -> str:
        return f"{min(values)}" if min(values) == max(values) else f"{min(values)}-{max(values)}"

    records = [
        *(
            f"docs/benchmark_{t}.json"
            for t in ("sea", "compliant", "noroll", "robust", "robust_v2")
        ),
        "experiments/robust_residual/benchmark_compliant_v2.json",  # an experiment's record
        "docs/benchmark_robust_v3.json",
    ]
    for path in records:
        record, name = read_json(root / path), Path(path).stem
        rates = record["summary"]["all"]["scores"]["success_rate"]
        policies, _ = controllers_of(record)
        best = max(rates["analytic"].values())
        limits = record["summary"]["limits"].values()
        falls = span([len(v["cells_falling_more_than_best_analytic"]) for v in limits])
        held = span([v["held_out_reliable_cells_held"] for v in limits])
        (reliable,) = {v["held_out_reliable_cells"] for v in limits}
        if len(policies) > 1:
            low, high = rates["policies"]["ci95"]
            success = f"{rates['policies']['iqm']:.2f} [{low:.2f}, {high:.2f}]"
        else:
            success = f"{rates['policies']['iqm']:.2f}"
        task = record["settings"]["task"].removeprefix("acl_env/")
        row = f"| `{task}` (`{name}.json`) | {len(policies)} | {success} | {best:.2f}, "
        assert row in page, row
        assert f"| {falls} | {held} of {reliable} |" in page.split(row)[1].splitlines()[0], name


def test_benchmark_page_noroll_counts_are_the_records() -> None:
    """docs/benchmark.md's non-rolling grid: the cells its open loops lose (by sliding or by
    falling), those where every seed climbs instead, and none where an open loop does but a seed
    does not."""
    from acl_env.io import read_json

    root = Path(__file__).resolve().parents[1]
    record = read_json(root / "docs" / "benchmark_noroll.json")
    page = (root / "docs" / "benchmark.md").read_text()
    open_loops = ("open_loop_acl", "open_loop_tuned", "compliant_acl")
    seeds = [name for name in record["labels"] if name.startswith("policy:")]
    half = 0.5

    def rate(cell: dict, name: str) -> float:
        return cell["controllers"][name]["success_rate"]

    lost = [c for c in record["cells"].values() if max(rate(c, n) for n in open_loops) < half]
    most = len(record["settings"]["seeds"]) / 2  # falls in most episodes: more than this
    slid = [c for c in lost if max(c["controllers"][n]["falls"] for n in open_loops) <= most]
    climbed = [c for c in slid if min(rate(c, n) for n in seeds) >= half]
    assert (len(lost), len(slid), len(climbed)) == (20, 14, 5)
    assert "In 20 cells none of the three non-rolling open loops" in page
    assert "In 14 of them they hold on and slide down" in page
    assert "The residual climbs in 5 of the 14" in page
    for cell in record["cells"].values():
        if max(rate(cell, n) for n in open_loops) >= half:
            assert min(rate(cell, n) for n in seeds) >= half


def test_benchmark_page_success_improvement_is_ties() -> None:
    """docs/benchmark.md's reading of the success rate's probability of improvement (ties count
    half): on the SEA and compliant grids no seed holds more often than a cell's best analytic
    controller, and the tie shares the page gives are the records'."""
    from acl_env.benchmark.summary import cell_matrix, controllers_of
    from acl_env.io import read_json

    root = Path(__file__).resolve().parents[1]
    page = (root / "docs" / "benchmark.md").read_text()
    for task, words in (
        ("sea", "they tie in {:.0%} of the seed-cell pairs"),
        ("compliant", "tie in {:.0%} of the seed-cell pairs"),
    ):
        record = read_json(root / "docs" / f"benchmark_{task}.json")
        policies, analytic = controllers_of(record)
        cells = list(record["cells"])
        best = np.max([cell_matrix(record, n, "success_rate", cells) for n in analytic], axis=0)
        seeds = np.array([cell_matrix(record, p, "success_rate", cells) for p in policies])
        assert not (seeds > best).any(), task
        share = float((seeds == best).mean())
        stored = record["summary"]["all"]["scores"]["success_rate"]["probability_of_improvement"]
        assert stored["mean"] == pytest.approx(share / 2)  # no wins: half the ties
        assert words.format(share).replace("%", " %") in page.replace("\n  ", " ").replace(
            "\n", " "
        ), task
