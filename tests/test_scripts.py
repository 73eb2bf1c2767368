"""acl_env.scripts (the shared parser and writers of benchmarks/ and experiments/) and
benchmarks/regenerate.py (the one command that remakes the published records in docs/)."""

from __future__ import annotations

import argparse
import json
import runpy
from pathlib import Path
from typing import Any

import pytest

from acl_env import scripts

ROOT = Path(__file__).resolve().parent.parent


def _regenerate() -> dict[str, Any]:
    """The functions of benchmarks/regenerate.py (a script, not a module of the package)."""
    return runpy.run_path(str(ROOT / "benchmarks" / "regenerate.py"), run_name="regenerate")


def test_parent_parser_gives_the_common_options_under_their_names(tmp_path: Path) -> None:
    parser = scripts.make_parser(
        "A script.\n\nMore.",
        json="the record",
        plot="the figure",
        plot_names=("--figure", "--plot"),
        seed=3,
        episodes=5,
        workers=2,
        env_kwargs="env arguments",
        progress=True,
    )
    assert parser.description == "A script."
    args = parser.parse_args(
        ["--figure", str(tmp_path / "f.png"), "--env-kwargs", "friction:0.5", "roll_limit:None"]
    )
    assert args.plot == tmp_path / "f.png" and args.json is None
    assert args.env_kwargs == {"friction": 0.5, "roll_limit": None}
    assert scripts.seeds(args) == [3, 4, 5, 6, 7] and args.workers == 2
    assert not args.no_progress_bar
    assert parser.parse_args(["--plot", str(tmp_path / "f.svg")]).plot == tmp_path / "f.svg"
    assert scripts.make_parser(None, json=None).parse_args([]) == argparse.Namespace()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--env-kwargs", "a:1", "a:2"], "argument --env-kwargs: 'a' given twice"),
        (["--env-kwargs", "nokey"], "argument --env-kwargs: expected key:value"),
        (["--json", "{tmp}/no/such/folder/x.json"], "argument --json: the folder"),
        (["--plot", "{tmp}/x.txt"], "argument --plot: expected a file ending in"),
    ],
)
def test_parent_parser_refuses_bad_values_in_one_line(
    argv: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    parser = scripts.make_parser("S.", plot="figure", env_kwargs="env arguments")
    with pytest.raises(SystemExit) as exit_:
        parser.parse_args([a.format(tmp=tmp_path) for a in argv])
    assert exit_.value.code == 2
    assert message in capsys.readouterr().err


def test_write_output_writes_strict_json_and_makes_its_folder(tmp_path: Path) -> None:
    import numpy as np

    path = tmp_path / "runs" / "x.json"
    scripts.write_output(path, {"a": np.float64(1.5), "b": float("nan")})
    assert json.loads(path.read_text()) == {"a": 1.5, "b": None}
    scripts.write_output(None, {"a": 1})  # nothing asked, nothing written


def test_save_figure_uses_the_headless_backend(tmp_path: Path) -> None:
    plt = scripts.use_agg()
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    path = tmp_path / "sub" / "f.png"
    scripts.save_figure(fig, path, 50)
    assert path.read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    assert not plt.get_fignums()


def test_regenerate_lists_every_published_record_and_its_command(
    capsys: pytest.CaptureFixture[str],
) -> None:
    regenerate = _regenerate()
    listed = regenerate["main"](["--list"])
    out = capsys.readouterr().out
    records = regenerate["RECORDS"]
    assert set(listed) == set(records)
    made = {file for record in records.values() for file in record.files}
    for file in ("docs/eval.json", "docs/eval.png", "docs/eval_noroll.json", "docs/open_loop.json"):
        assert file in made and file in out
    assert all(file.startswith("docs/") and (ROOT / file).is_file() for file in made)
    assert "acl-evaluate --json docs/eval.json --plot docs/eval.png" in listed["eval"]
    assert listed["open_loop"] == "python benchmarks/open_loop.py --json docs/open_loop.json"


def test_regenerate_dry_run_runs_nothing_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    record = tmp_path / "records.json"
    made = _regenerate()["main"](["--dry-run", "--only", "open_loop", "--record", str(record)])
    assert made == {
        "docs/open_loop.json": {
            "command": "python benchmarks/open_loop.py --json docs/open_loop.json"
        }
    }
    assert "open_loop: python benchmarks/open_loop.py" in capsys.readouterr().out
    assert not record.exists()


def test_regenerate_runs_a_record_from_the_root_and_notes_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A record's command runs in the repository's root with this interpreter; its files are
    noted with the command and the time, and the shipped policies' summaries of them refreshed
    (here a stand-in command, not a minutes-long one, and a stand-in refresh)."""
    regenerate = _regenerate()
    calls: list[tuple[list[str], Path]] = []
    refreshed: list[tuple[str, ...]] = []

    def run(argv: list[str], cwd: Path, check: bool) -> None:
        calls.append((argv, cwd))

    monkeypatch.setattr(regenerate["subprocess"], "run", run)
    monkeypatch.setitem(
        regenerate["regenerate"].__globals__,
        "refresh_policy_summaries",
        lambda files: refreshed.append(files) or [],
    )
    record = tmp_path / "records.json"
    made = regenerate["regenerate"](["gait"], False, record)
    assert calls == [(regenerate["RECORDS"]["gait"].argv(), ROOT)]
    assert refreshed == [regenerate["RECORDS"]["gait"].files]
    assert calls[0][0][0] == regenerate["sys"].executable
    assert json.loads(record.read_text()) == made
    assert made["docs/gait.png"]["command"] == "python -m acl_env.gait --plot docs/gait.png"


def test_regenerate_refreshes_the_summary_of_the_policy_whose_record_it_made(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A shipped policy's policy.json summarises its published record: remaking that record
    re-summarises it there; remaking another record, or a record now of another policy, leaves
    it as it was."""
    import shutil

    from acl_env import shipped
    from acl_env.evaluation.records import evaluation_summary

    for name in ("acl_climb_compliant_ppo", "acl_climb_sea_ppo"):
        shutil.copytree(shipped.policy_dir(name), tmp_path / name)
    metadata_path = tmp_path / "acl_climb_compliant_ppo" / "policy.json"
    metadata = json.loads(metadata_path.read_text())
    record = metadata["evaluation"]["record"]
    metadata["evaluation"]["controllers"]["policy"]["slip_per_m"]["mean"] = 1.0  # stale
    metadata_path.write_text(json.dumps(metadata))
    other_path = tmp_path / "acl_climb_sea_ppo" / "policy.json"
    other = json.loads(other_path.read_text())
    other["evaluation"]["record"] = record  # names the compliant policy's record
    other_path.write_text(json.dumps(other))
    refresh = _regenerate()["refresh_policy_summaries"]

    assert refresh(("docs/eval.json", "docs/eval.png"), tmp_path) == []
    assert json.loads(metadata_path.read_text()) == metadata
    assert refresh((record,), tmp_path) == ["acl_climb_compliant_ppo"]
    assert "not acl_climb_sea_ppo's: left as it was" in capsys.readouterr().out
    assert json.loads(other_path.read_text()) == other
    refreshed = json.loads(metadata_path.read_text())
    assert refreshed["evaluation"] == evaluation_summary(ROOT / record, shown=record)
    assert refreshed["evaluation"]["controllers"]["policy"]["slip_per_m"]["mean"] < 0.2
    assert {k: v for k, v in refreshed.items() if k != "evaluation"} == {
        k: v for k, v in metadata.items() if k != "evaluation"
    }


def test_grip_slip_counts_the_trials_in_the_controller_alone_target_region(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """benchmarks/grip_slip.py's target region: against the grip study's default-gait trial
    (the open loop), trials that held the pole, climbed >= 0.95x and slid <= 0.7x; fallen ones
    left out. A study that is not there is named, with its argument, before any play."""
    optuna = pytest.importorskip("optuna")
    grip_key = "acl_sea_grip"  # the study of the shipped grip entry
    storage = tmp_path / "studies.db"
    script = runpy.run_path(str(ROOT / "benchmarks" / "grip_slip.py"))

    def study(name: str, rows: list[tuple[float, float, str | None]]) -> None:
        made = optuna.create_study(
            study_name=name, storage=f"sqlite:///{storage}", direction="maximize"
        )
        for i, (climb, slip, disqualified) in enumerate(rows):
            trial = made.ask()
            trial.set_user_attr("climb_per_gait_cycle_m", climb)
            trial.set_user_attr("slip_per_m", slip)
            trial.set_user_attr("energy_per_m", 1000 * slip)
            if name == grip_key and i == 1:
                trial.set_user_attr("default_gait", True)  # not trial 0 here: found by its mark
            if disqualified:
                trial.set_user_attr("disqualified", disqualified)
            made.tell(trial, climb)

    # in the region; the open loop 0.20 m, 0.20 per m; too slow; too slippery
    study(
        grip_key, [(0.195, 0.13, None), (0.20, 0.20, None), (0.18, 0.10, None), (0.21, 0.15, None)]
    )
    study("gait", [(0.20, 0.10, "fell"), (0.20, 0.18, None)])
    studies = {name: script["load_trials"](storage, name, "--key") for name in (grip_key, "gait")}
    region = script["target_region"](studies[grip_key], studies)
    assert region["open_loop"] == {
        "climb_per_gait_cycle_m": 0.20,
        "slip_per_m": 0.20,
        "energy_per_m": 200.0,
    }
    assert region[grip_key]["least_energy_per_m"] == pytest.approx(100.0)
    assert region[grip_key]["trials_held"] == 4 and region[grip_key]["climb_at_least_target"] == 3
    assert region[grip_key]["in_target_region"] == 1
    assert region[grip_key]["least_slip_ratio_among_them"] == pytest.approx(0.65)
    assert region["gait"] == {
        "trials_held": 1,
        "climb_at_least_target": 1,
        "least_slip_ratio_among_them": pytest.approx(0.9),
        "in_target_region": 0,
        "least_energy_per_m": pytest.approx(180.0),  # the fallen trial's 100 left out
    }
    with pytest.raises(ValueError, match="no completed default-gait trial"):
        script["target_region"](studies["gait"], studies)
    for key, option in (("acl_noroll_sea_grip", "--key"), (grip_key, "--also-study")):
        argv = ["--key", key, "--storage", str(storage), "--also-study", "nope"]
        with pytest.raises(SystemExit):
            script["main"]([*argv, "--json", str(tmp_path / "x.json")])
        assert f"argument {option}: no study" in capsys.readouterr().err
    assert not (tmp_path / "x.json").exists()


def test_physics_stages_reads_mujocos_own_timers_of_the_steps_played() -> None:
    """benchmarks/physics_stages.py: the stages' times are those of the env steps played (30
    physics steps each), the reset's left out; the sub-stages fit in their stage."""
    script = runpy.run_path(str(ROOT / "benchmarks" / "physics_stages.py"))
    out = script["stage_times"]("acl_env/ACLClimb-v3", 2)
    assert out["physics_steps"] == 2 * 30
    stages = {name: row["share"] for name, row in out["stages"].items()}
    assert stages["mjTIMER_STEP"] == pytest.approx(1.0)
    parts = ("POSITION", "VELOCITY", "ACTUATION", "CONSTRAINT", "ADVANCE")
    assert 0.5 < sum(stages[f"mjTIMER_{p}"] for p in parts) <= 1.0
    inner = ("KINEMATICS", "INERTIA", "COLLISION", "MAKE")
    assert sum(stages[f"mjTIMER_POS_{p}"] for p in inner) <= stages["mjTIMER_POSITION"]


def test_speed_page_stage_table_is_the_record() -> None:
    """docs/speed.md's shares of MuJoCo's step are docs/physics_stages.json's, rounded."""
    record = json.loads((ROOT / "docs" / "physics_stages.json").read_text())
    share = {name[len("mjTIMER_") :]: row["share"] for name, row in record["stages"].items()}
    page = (ROOT / "docs" / "speed.md").read_text()
    rows = {
        "constraint solver (Newton, elliptic cone)": share["CONSTRAINT"],
        "position: collision": share["POS_COLLISION"],
        "position: kinematics, inertia, constraint rows": share["POS_KINEMATICS"]
        + share["POS_INERTIA"]
        + share["POS_MAKE"],
        "integrator (`implicitfast`)": share["ADVANCE"],
        "velocity and actuation": share["VELOCITY"] + share["ACTUATION"],
    }
    rows["the rest of the step (outside these stages' timers)"] = 1.0 - sum(rows.values())
    for what, value in rows.items():
        assert f"| {what} | {100 * value:.0f} % |" in page, what
    text = " ".join(page.split())
    assert (
        f"about {record['contacts']} contacts ({record['constraint_rows']} constraint rows)" in text
    )
    assert f"({record['solver_iterations_last']} at the last step)" in text
