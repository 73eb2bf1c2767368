"""The open-loop tuner (acl_env.tuning, acl-tune-gait): shared studies, resuming,
disqualification, the tuned-gaits file, its default outputs under runs/, and one-line errors for
bad input."""

from __future__ import annotations

import json
import math
import multiprocessing
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import optuna
import pytest

from acl_env import ACL_CLIMB_ID, shipped, tuned_gaits
from acl_env.evaluation import run_episode, zero_policy
from acl_env.io import jsonable
from acl_env.training import config
from acl_env.tuning import objective
from acl_env.tuning.cli import main
from acl_env.tuning.frontier import pareto_front, policy_point
from acl_env.tuning.objective import OBJECTIVES, TuneSettings
from acl_env.tuning.remeasure import tuned_entry, validate
from acl_env.tuning.space import DEFAULT_PARAMS, SEARCH_SPACE, ParamRange, UsageError
from acl_env.tuning.study import FINISHED, open_storage

ROOT = Path(__file__).resolve().parents[1]
# 20-step cycles, one cycle per episode: a trial takes a fraction of a second.
TINY = ["--steps-per-cycle", "20", "--cycles", "1", "--validate-seeds", "3", "--no-progress-bar"]


def tiny_args(tmp_path: Path, *extra: str, seeds: tuple[str, ...] = ("0",)) -> list[str]:
    return [
        *TINY,
        "--seeds",
        *seeds,
        "--storage",
        str(tmp_path / "study.db"),
        "--output",
        str(tmp_path / "tuned.json"),
        "--plot",
        str(tmp_path / "frontier_{key}.png"),
        "--sampler-seed",
        "0",
        *extra,
    ]


def load(tmp_path: Path, name: str = "acl") -> optuna.Study:
    return optuna.load_study(study_name=name, storage=open_storage(str(tmp_path / "study.db")))


def _open_after(barrier: Any, path: str) -> str:
    barrier.wait()
    try:
        open_storage(path)
    except UsageError as exc:
        return str(exc)
    return "ok"


def test_processes_opening_one_new_database_at_once_all_succeed(tmp_path: Path) -> None:
    # Workers started together on a new SQLite file race to create Optuna's tables; the losers
    # wait for the winner instead of failing with a duplicate table or version row.
    ctx = multiprocessing.get_context("spawn")
    barrier = ctx.Manager().Barrier(4)
    with ctx.Pool(4) as pool:
        for attempt in range(5):  # the race is not lost every time: try a few new files
            path = str(tmp_path / f"study{attempt}.db")
            assert pool.starmap(_open_after, [(barrier, path)] * 4) == ["ok"] * 4


def test_two_workers_share_one_study_and_write_the_tuned_gait(tmp_path: Path) -> None:
    entry = main(tiny_args(tmp_path, "--n-trials", "8", "--n-jobs", "2"))
    study = load(tmp_path)
    finished = study.get_trials(states=FINISHED)
    assert len(finished) == 8
    # Trial 0, the untuned gait, runs in this process; both worker processes ran the others.
    assert finished[0].user_attrs["default_gait"]
    assert finished[0].params == DEFAULT_PARAMS
    assert finished[0].user_attrs["worker"].endswith(f":{os.getpid()}")
    workers = {t.user_attrs["worker"] for t in finished[1:]}
    assert len(workers) == 2 and finished[0].user_attrs["worker"] not in workers

    document = tuned_gaits.read(tmp_path / "tuned.json")
    assert json.loads((tmp_path / "tuned.json").read_text()) == document  # plain JSON
    saved = document["acl"]
    assert saved == jsonable(entry)
    assert saved["env_id"] == ACL_CLIMB_ID
    assert saved["trials"] == 8
    # The tuned gait is one of the 5 best trials, the best of them on 3 new seeds.
    ranked = sorted((t for t in finished if t.value is not None), key=lambda t: -t.value)
    assert saved["best_trial"] in [t.number for t in ranked[:5]]
    validation = saved["validation"]
    assert validation["seeds"] == [1, 2, 3] and validation["candidates"] == 5
    assert not validation["fell"]
    assert saved["default_gait_validation"]["seeds"] == validation["seeds"]
    for trial in ranked[:5]:
        other = study.user_attrs[f"validation_{trial.number}"]
        if not other["fell"]:
            assert (
                validation["metrics"]["reward_per_gait_cycle"]
                >= (other["metrics"]["reward_per_gait_cycle"])
            )
    recipe = config.load_hyperparams(shipped.recipe_path(), ACL_CLIMB_ID)
    assert saved["reward_weights"] == recipe["env_kwargs"]["reward_weights"]  # the env's recipe
    assert saved["env_kwargs"]["gait_kwargs"]["rolls_per_cycle"] == 1
    assert set(saved["env_kwargs"]["gait_kwargs"]) == {*SEARCH_SPACE, "rolls_per_cycle"} - {
        "squeeze"
    }
    chosen = study.trials[saved["best_trial"]]
    assert saved["metrics"]["reward_per_gait_cycle"] == pytest.approx(chosen.value)
    assert (tmp_path / "frontier_acl.png").stat().st_size > 10_000

    # The entry's env kwargs replay the best trial: same seed, same metrics.
    env = gymnasium.make(
        ACL_CLIMB_ID,
        steps_per_cycle=20,
        cycles_per_episode=1,
        reward_weights=saved["reward_weights"],
        **saved["env_kwargs"],
    )
    replay = run_episode(env, zero_policy(env), 0).metrics()
    env.close()
    for metric, value in saved["metrics"].items():
        assert replay[metric] == pytest.approx(value, rel=1e-9, nan_ok=True)


def test_rerun_resumes_the_study_and_other_settings_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    main(tiny_args(tmp_path, "--n-trials", "3"))
    main(tiny_args(tmp_path, "--n-trials", "5"))  # two more, not five
    assert len(load(tmp_path).get_trials(states=FINISHED)) == 5
    # Nothing left to run: the outputs are rewritten, here with a policy's point on the figure.
    evaluation = {"controllers": {"policy": {"energy_per_m": {"mean": 900.0}}}}
    evaluation["controllers"]["policy"]["climb_per_gait_cycle_m"] = {"mean": 0.21}
    (tmp_path / "eval.json").write_text(json.dumps(evaluation))
    (tmp_path / "frontier_acl.png").unlink()
    point = str(tmp_path / "eval.json")
    main(
        tiny_args(
            tmp_path,
            "--n-trials",
            "5",
            "--policy-point",
            point,
            "--policy-point",
            f"{point}:policy=same policy, labelled",
        )
    )
    assert len(load(tmp_path).trials) == 5
    assert (tmp_path / "frontier_acl.png").is_file()
    capsys.readouterr()
    with pytest.raises(SystemExit) as exc:
        main(tiny_args(tmp_path, "--n-trials", "6", "--reward-weights", "climb:1"))
    err = capsys.readouterr().err
    assert exc.value.code == 2
    assert "--study-name" in err and "reward_weights" in err
    assert len(load(tmp_path).trials) == 5


# An older version (or an old id) on purpose: Gymnasium's and acl_env's notes say so.
@pytest.mark.filterwarnings("ignore:.*is out of date:DeprecationWarning")
@pytest.mark.filterwarnings("ignore:.*is the task now registered as:DeprecationWarning")
def test_a_study_resumes_on_the_env_it_was_run_on(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A non-rolling study run on v2 is refused on v3 (the default) and resumes with ``--env``
    naming v2; the tuned entry records the env it was tuned on."""
    v3 = ["--no-roll", "--validate-seeds", "0", "--reward-weights", "climb:1", "roll:0.05"]
    v2 = [*v3, "--env", "acl_env/ACLClimbNoRoll-v2"]
    main(tiny_args(tmp_path, "--n-trials", "1", *v2))
    capsys.readouterr()
    with pytest.raises(SystemExit) as exc:
        main(tiny_args(tmp_path, "--n-trials", "2", *v3))
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "--study-name" in err and "env_id" in err
    main(tiny_args(tmp_path, "--n-trials", "2", *v2))
    assert len(load(tmp_path, "acl_noroll").get_trials(states=FINISHED)) == 2
    entry = tuned_gaits.read(tmp_path / "tuned.json")["acl_noroll"]
    assert entry["env_id"] == "acl_env/ACLClimbNoRoll-v2"


def test_a_benchmark_id_is_tuned_for_its_registered_reward_from_the_given_gaits(
    tmp_path: Path,
) -> None:
    """On ACLClimb-v3 (whose recipe entry holds only domain randomisation) the objective is the
    reward the id registers, and the trial plays its own gait, not the registered tuned one;
    ``--start-from`` makes a shipped tuned gait one of the first trials."""
    args = ["--env", "acl_env/ACLClimb-v3", "--key", "sea", "--validate-seeds", "0"]
    args += ["--steps-per-cycle", "110"]  # the SEA's motors cannot follow 20 keyframes a cycle
    main(tiny_args(tmp_path, "--n-trials", "2", "--start-from", "acl", *args))
    study = load(tmp_path, "sea")
    registered = gymnasium.spec("acl_env/ACLClimb-v3").kwargs["reward_weights"]
    assert study.user_attrs["settings"]["reward_weights"] == registered
    started = [t for t in study.trials if t.user_attrs.get("start_from")]
    assert len(started) == 1
    shape = tuned_gaits.gait_shape("acl")
    assert started[0].params["squeeze"] == pytest.approx(shape["squeeze"])
    assert started[0].params["pitch"] == pytest.approx(shape["gait_kwargs"]["pitch"])
    assert len(study.get_trials(states=FINISHED)) == 2


def test_policy_point_reads_energy_climb_and_slip(tmp_path: Path) -> None:
    summary = {"energy_per_m": {"mean": 700.0}, "climb_per_gait_cycle_m": {"mean": 0.2}}
    path = tmp_path / "eval.json"
    path.write_text(json.dumps({"controllers": {"policy": summary}}))
    point = policy_point(path)
    assert point["energy_per_m"] == 700.0 and point["climb_per_gait_cycle_m"] == 0.2
    assert math.isnan(point["slip_per_m"])  # older JSONs: drawn on the climb panel only
    summary["slip_per_m"] = {"mean": 0.16}
    path.write_text(json.dumps({"controllers": {"tuned": summary}}))
    assert policy_point(path, "tuned")["slip_per_m"] == 0.16


def test_pareto_front_of_a_metric_where_less_is_better() -> None:
    # Slip: the 900 J/m point slips least; the 700 J/m one is beaten by 600 J/m on both.
    slip = np.array([[700.0, 0.20], [600.0, 0.18], [900.0, 0.15], [1000.0, 0.25]])
    assert pareto_front(slip, maximize=False).tolist() == [[600.0, 0.18], [900.0, 0.15]]


def test_a_gait_that_falls_is_disqualified(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A helix 3 cm looser than the pole's contact radius never grips.
    args = tiny_args(tmp_path, "--n-trials", "2", "--no-roll", "--space", "squeeze:-0.03:-0.03")
    with pytest.raises(SystemExit) as exc:
        main(args)
    assert exc.value.code == 1
    assert "no qualified trial" in capsys.readouterr().err
    trials = load(tmp_path, "acl_noroll").trials
    assert len(trials) == 2
    for trial in trials:
        assert trial.state == optuna.trial.TrialState.PRUNED
        assert trial.user_attrs["disqualified"] == "fell"
        assert trial.user_attrs["falls"] == 1.0
        assert trial.params["squeeze"] == -0.03
    assert not (tmp_path / "tuned.json").exists()


def test_a_saturated_gait_is_disqualified_without_a_rollout(tmp_path: Path) -> None:
    space = ["amp_pitch:0.05:0.05", "spatial_freq:3:3", "amp_radial:0.025:0.025"]
    with pytest.raises(SystemExit):
        main(tiny_args(tmp_path, "--n-trials", "1", "--space", *space))
    (trial,) = load(tmp_path).trials
    assert trial.user_attrs["disqualified"] == "saturated"
    assert trial.user_attrs["clipped_fraction"] > 0.1
    assert "seeds_run" not in trial.user_attrs


@pytest.mark.parametrize(
    ("extra", "argument"),
    [
        (["--objective", "speed"], "--objective"),
        (["--n-trials", "0"], "--n-trials"),
        (["--n-jobs", "0"], "--n-jobs"),
        (["--space", "amp_radial:0:0.2"], "--space"),  # above the helix radius
        (["--space", "pitch:0.03:0.1"], "--space"),  # turns closer than a module diameter
        (["--space", "spatial_freq:1.5:3"], "--space"),  # not a whole number of waves per turn
        (["--space", "amp_pitch:-0.01:0.02"], "--space"),
        (["--space", "stiffness:1:2"], "--space"),
        (["--reward-weights", "height:1"], "--reward-weights"),
        (["--config", "no/such/config.yml"], "--config"),
        (["--max-clipped", "2"], "--max-clipped"),
        (["--no-roll", "--max-arc", "0"], "--max-arc"),
        (["--policy-point", "no/such/eval.json"], "--policy-point"),
        (["--condition", "gravity:3"], "--condition"),
        (["--condition", "friction:0"], "--condition"),  # the env's range
        (["--condition", "friction:slick"], "--condition"),
        (["--condition", "friction"], "--condition"),
        # the default search space's amp_radial does not fit around a 1 cm pole
        (["--condition", "pole_radius:0.01"], "--space"),
        (["--env", "CartPole-v1"], "--env"),
        (["--env", "acl_env/ACLClimbNoRoll-v9"], "--env"),
    ],
)
def test_bad_input_is_one_line_naming_the_argument(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], argument: str
) -> None:
    with pytest.raises(SystemExit) as exc:
        main(tiny_args(tmp_path, *extra))
    err = capsys.readouterr().err
    assert exc.value.code == 2
    assert err.count("\n") == 1 and argument in err, err
    assert not (tmp_path / "study.db").exists()  # failed before any trial, before any study


@pytest.mark.parametrize("kind", ["not a database", "folder", "bad url"])
def test_unreadable_storage_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], kind: str
) -> None:
    storage = tmp_path / "study.db"
    if kind == "not a database":
        storage.write_bytes(b"\x00garbage" * 200)
    elif kind == "folder":
        storage.mkdir()
    args = tiny_args(tmp_path)
    args[args.index("--storage") + 1] = "nosuchdriver://x/y" if kind == "bad url" else str(storage)
    with pytest.raises(SystemExit) as exc:
        main(args)
    err = capsys.readouterr().err
    assert exc.value.code == 2
    assert err.count("\n") == 1 and "--storage" in err, err
    assert not (tmp_path / "tuned.json").exists()


def test_command_line_error_from_the_script(tmp_path: Path) -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "acl_env.tuning", *tiny_args(tmp_path, "--objective", "speed")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [
        "acl-tune-gait: error: argument --objective: unknown 'speed'; known: "
        f"{list(OBJECTIVES)} (see --help)"
    ]


def test_pareto_front_keeps_the_undominated_points() -> None:
    points = np.array([[500.0, 0.18], [400.0, 0.15], [700.0, 0.22], [600.0, 0.17], [900, 0.21]])
    front = pareto_front(points)
    assert front.tolist() == [[400.0, 0.15], [500.0, 0.18], [700.0, 0.22]]


def test_env_kwargs_split_squeeze_from_the_gait() -> None:
    settings = TuneSettings(rolls_per_cycle=0)
    kwargs = settings.env_kwargs(DEFAULT_PARAMS)
    assert kwargs["squeeze"] == DEFAULT_PARAMS["squeeze"]
    assert kwargs["gait_kwargs"]["rolls_per_cycle"] == 0
    assert "squeeze" not in kwargs["gait_kwargs"]
    env = gymnasium.make(ACL_CLIMB_ID, **kwargs)  # the env accepts them as they are
    assert math.isclose(env.unwrapped.gait.curve.amp_pitch, DEFAULT_PARAMS["amp_pitch"])
    env.close()


def test_a_gait_that_rolls_is_disqualified_by_max_arc(tmp_path: Path) -> None:
    # The default rolling gait touches the pole all round some module (360 deg).
    space = [f"{name}:{value}:{value}" for name, value in DEFAULT_PARAMS.items()]
    with pytest.raises(SystemExit):
        main(tiny_args(tmp_path, "--n-trials", "1", "--max-arc", "90", "--space", *space))
    (trial,) = load(tmp_path).trials
    assert trial.user_attrs["disqualified"] == "touched arc"
    assert trial.user_attrs["max_touched_arc_deg"] > 90.0


def test_validation_passes_over_a_lucky_gait_that_falls_on_new_seeds(tmp_path: Path) -> None:
    # Two finished trials: a loose helix that never grips, recorded with a better value than it
    # could have (as luck on a few seeds might), and the default gait. Validation must pick the
    # default gait, since the other falls on the new seeds.
    space = {**SEARCH_SPACE, "squeeze": ParamRange(-0.04, 0.016)}
    settings = TuneSettings(
        reward_weights={"climb": 1.0, "slip": 2.0},
        seeds=(0,),
        steps_per_cycle=20,
        cycles_per_episode=1,
        space=space,
    )
    study = optuna.create_study(direction="maximize")
    distributions = {
        name: optuna.distributions.IntDistribution(int(r.low), int(r.high))
        if r.integer
        else optuna.distributions.FloatDistribution(r.low, r.high)
        for name, r in space.items()
    }
    loose = {**DEFAULT_PARAMS, "squeeze": -0.03}
    for params, value in ((loose, 1.0), (DEFAULT_PARAMS, 0.01)):
        study.add_trial(
            optuna.trial.create_trial(
                params=params,
                distributions=distributions,
                value=value,
                user_attrs={"default_gait": params is DEFAULT_PARAMS},
            )
        )
    chosen, results = validate(study, settings, top_k=2, n_seeds=3)
    assert chosen.number == 1
    assert results[0]["fell"] and not results[1]["fell"]
    assert results[1]["seeds"] == [1, 2, 3]
    entry = tuned_entry(study, settings, chosen, results)
    assert entry["env_kwargs"]["squeeze"] == DEFAULT_PARAMS["squeeze"]
    assert entry["validation"]["candidates"] == 2
    # The chosen gait is the default one: both validation records are the same measurement.
    assert entry["default_gait_validation"]["metrics"] == entry["validation"]["metrics"]


@pytest.mark.parametrize("n_jobs", ["1", "2"])
def test_sigterm_stops_the_study_and_a_rerun_resumes_it(tmp_path: Path, n_jobs: str) -> None:
    """SIGTERM (or Ctrl-C) stops at a safe point: exit status 130, no trial left RUNNING (the
    interrupted ones are failed, so a rerun redoes them at once), nothing written."""
    args = tiny_args(tmp_path, "--n-trials", "1000", "--n-jobs", n_jobs)
    proc = subprocess.Popen(
        [sys.executable, "-m", "acl_env.tuning", *args],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            time.sleep(0.5)
            if (tmp_path / "study.db").exists():
                try:
                    if len(load(tmp_path).get_trials(states=FINISHED)) >= 2:
                        break
                except KeyError:  # the study is being created
                    pass
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 130, err
    assert "interrupted" in err.splitlines()[-1] and "resume" in err.splitlines()[-1]
    assert not (tmp_path / "tuned.json").exists()  # nothing written on an interrupt
    assert not load(tmp_path).get_trials(states=(optuna.trial.TrialState.RUNNING,))
    finished = len(load(tmp_path).get_trials(states=FINISHED))
    assert 2 <= finished < 1000
    args[args.index("1000")] = str(finished + 1)
    main(args)  # resumes: one more trial, then the outputs
    assert len(load(tmp_path).get_trials(states=FINISHED)) == finished + 1
    assert (tmp_path / "tuned.json").is_file()


def test_also_plot_names_an_existing_study(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exc:
        main(tiny_args(tmp_path, "--n-trials", "2", "--also-plot", "nosuch"))
    err = capsys.readouterr().err
    assert exc.value.code == 2
    assert err.count("\n") == 1 and "--also-plot" in err and "nosuch" in err
    assert not (tmp_path / "study.db").exists()  # refused before the study was created


def tune_recording(
    tmp_path: Path, attrs: tuple[str, ...], n_trials: str, *extra: str
) -> tuple[dict[str, Any] | None, list[tuple[float, ...]]]:
    """Run a tiny study; return its entry and, per rollout, the env's options ``attrs`` it
    played."""
    seen: list[tuple[float, ...]] = []
    real_rollout = objective.rollout

    def setting(env: gymnasium.Env, name: str) -> float:
        """An option as the env checked it (its physics config or its actuator's values)."""
        config = env.unwrapped.config
        if hasattr(config.physics, name):
            return getattr(config.physics, name)
        return config.actuator.values[name]

    def spy(env: gymnasium.Env, seeds: Any) -> list[dict[str, float]]:
        seen.append(tuple(setting(env, a) for a in attrs))
        return real_rollout(env, seeds)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(objective, "rollout", spy)
        entry = main(tiny_args(tmp_path, "--n-trials", n_trials, *extra))
    return entry, seen


def test_a_condition_plays_every_trial_there_and_is_part_of_the_study(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    condition = ["--condition", "friction:0.5", "pole_radius:0.06"]
    entry, seen = tune_recording(tmp_path, ("friction", "pole_radius"), "3", *condition)
    assert entry is not None
    assert seen and set(seen) == {(0.5, 0.06)}  # the trials and the validation
    assert entry["condition"] == {"friction": 0.5, "pole_radius": 0.06}
    written = tuned_gaits.read(tmp_path / "tuned.json")["acl"]
    assert written["condition"] == entry["condition"]
    assert "friction" not in written["env_kwargs"]  # the gait alone, as for any tuned gait
    # The same study under the default condition is another study.
    capsys.readouterr()
    with pytest.raises(SystemExit) as exc:
        main(tiny_args(tmp_path, "--n-trials", "4"))
    assert exc.value.code == 2 and "condition" in capsys.readouterr().err
    # Without --condition, nothing about it is stored: older studies resume as before.
    main(tiny_args(tmp_path, "--n-trials", "2", "--study-name", "plain"))
    assert "condition" not in load(tmp_path, "plain").user_attrs["settings"]
    assert "condition" not in tuned_gaits.read(tmp_path / "tuned.json")["acl"]


def test_a_grid_of_conditions_scores_each_gait_on_all_of_them(tmp_path: Path) -> None:
    grid = ["--condition", "friction:[0.7,1.2]", "kp:20"]
    entry, seen = tune_recording(tmp_path, ("friction", "kp"), "2", *grid)
    assert entry is not None and entry["condition"] == {"friction": [0.7, 1.2], "kp": 20.0}
    assert set(seen) == {(0.7, 20.0), (1.2, 20.0)}
    study = load(tmp_path)
    for trial in study.get_trials(states=(optuna.trial.TrialState.COMPLETE,)):
        assert trial.user_attrs["seeds_run"] == 2  # one seed in each of two conditions
    # The chosen gait's score is the mean of its episodes over the grid, measured again here.
    kwargs = {**TuneSettings().protocol_kwargs(), **entry["env_kwargs"]}
    kwargs.update(steps_per_cycle=20, cycles_per_episode=1)
    climbs = []
    for friction in (0.7, 1.2):
        env = gymnasium.make(ACL_CLIMB_ID, friction=friction, kp=20.0, **kwargs)
        climbs.append(run_episode(env, zero_policy(env), 0).metrics()["climb_per_gait_cycle_m"])
        env.close()
    assert entry["metrics"]["climb_per_gait_cycle_m"] == pytest.approx(np.mean(climbs))


def test_defaults_write_only_under_runs_and_never_the_shipped_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Run from an empty folder with the default storage, output and figure: everything the
    tuner writes lies under ``runs/``, and the shipped tuned gaits stay byte-identical."""
    shipped_gaits = tuned_gaits.shipped_path()
    before = shipped_gaits.read_bytes()
    monkeypatch.chdir(tmp_path)
    entry = main(
        [
            "--steps-per-cycle",
            "20",
            "--cycles",
            "1",
            "--no-progress-bar",
            "--seeds",
            "0",
            "--n-trials",
            "2",
            "--validate-top",
            "1",
            "--validate-seeds",
            "1",
            "--sampler-seed",
            "0",
        ]
    )
    assert entry is not None
    written = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file())
    assert written and all(p.parts[0] == "runs" for p in written), written
    assert {"runs/tune_gait.db", "runs/tuned_gaits.json", "runs/frontier_acl.png"} <= {
        str(p) for p in written
    }
    assert tuned_gaits.read(tmp_path / "runs" / "tuned_gaits.json")["acl"] == jsonable(entry)
    printed = capsys.readouterr().out
    assert json.loads(printed[: printed.index("\nfrontier figure")]) == {"acl": jsonable(entry)}
    assert shipped_gaits.read_bytes() == before


def test_symbolic_links_at_the_outputs_are_replaced_not_written_through(tmp_path: Path) -> None:
    """A link at ``--output`` or ``--plot`` pointing out of its folder: the tuner replaces the
    link with its file (atomically), and the link's target outside stays as it was."""
    outside = tmp_path / "outside"
    outside.mkdir()
    target_gaits, target_plot = outside / "gaits.json", outside / "figure.png"
    target_gaits.write_text('{"kept": {"env_id": "x"}}\n')
    target_plot.write_bytes(b"not a figure")
    (tmp_path / "tuned.json").symlink_to(target_gaits)
    (tmp_path / "frontier_acl.png").symlink_to(target_plot)
    main(tiny_args(tmp_path, "--n-trials", "2", "--validate-seeds", "1", "--validate-top", "1"))
    assert target_gaits.read_text() == '{"kept": {"env_id": "x"}}\n'
    assert target_plot.read_bytes() == b"not a figure"
    for name in ("tuned.json", "frontier_acl.png"):
        assert not (tmp_path / name).is_symlink() and (tmp_path / name).is_file()
    assert "acl" in tuned_gaits.read(tmp_path / "tuned.json")
    assert (tmp_path / "frontier_acl.png").read_bytes()[:4] == b"\x89PNG"


def test_nothing_is_written_when_validation_finds_no_gait(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The tuned gaits and the figure are written only after the study and its validation: a
    study with no qualified trial (every gait touches the pole over 0.001 deg) writes neither,
    exit 1."""
    with pytest.raises(SystemExit) as exc:
        main(tiny_args(tmp_path, "--n-trials", "2", "--max-arc", "0.001"))
    assert exc.value.code == 1
    assert "no qualified trial" in capsys.readouterr().err
    assert not (tmp_path / "tuned.json").exists() and not (tmp_path / "frontier_acl.png").exists()


def test_a_worker_waits_for_a_trial_running_elsewhere_and_retries_it_when_its_heartbeat_stops(
    tmp_path: Path,
) -> None:
    """A trial left RUNNING by a dead worker (no heartbeat since) is failed after the grace
    period and queued again; the worker that finds it runs the retry and completes the study."""
    main(tiny_args(tmp_path, "--n-trials", "2", "--heartbeat", "1", "--plot", ""))
    study = load(tmp_path)
    with pytest.warns(UserWarning, match="Heartbeat"):  # a trial outside Study.optimize
        stale = study.ask()  # RUNNING, its heartbeat recorded once: as if its worker was killed
    stale.set_user_attr("heartbeat", 1)
    open_storage(str(tmp_path / "study.db"), 1).record_heartbeat(stale._trial_id)
    main(tiny_args(tmp_path, "--n-trials", "3", "--heartbeat", "1", "--plot", ""))
    trials = load(tmp_path).get_trials()
    assert trials[stale.number].state == optuna.trial.TrialState.FAIL
    retried = [t for t in trials if t.system_attrs.get("failed_trial") == stale.number]
    assert len(retried) == 1 and retried[0].state in FINISHED
    assert len(load(tmp_path).get_trials(states=FINISHED)) == 3


def test_cvar_is_the_mean_of_the_worst_share() -> None:
    assert objective.cvar([0.3, -1.0, 0.1, 0.2], 0.25) == -1.0
    assert objective.cvar([0.3, -1.0, 0.1, 0.2], 0.5) == pytest.approx(-0.45)
    assert objective.cvar([0.3, 0.1], 1.0) == pytest.approx(0.2)
    assert objective.cvar([0.3], 0.01) == 0.3  # at least one score


def test_cvar_study_scores_falls_instead_of_pruning_them(tmp_path: Path) -> None:
    """``--cvar``: every condition is played; one where the gait falls scores FALL_SCORE, and
    the trial's value is the mean of its worst share of conditions, not a pruned trial."""
    grid = ["--condition", "friction:[0.05,1.0]", "--cvar", "0.5"]
    main(tiny_args(tmp_path, "--n-trials", "2", *grid))
    trials = load(tmp_path).get_trials(states=(optuna.trial.TrialState.COMPLETE,))
    assert len(trials) == 2
    for trial in trials:
        scores = trial.user_attrs["condition_scores"]
        assert len(scores) == 2 and trial.user_attrs["seeds_run"] == 2
        assert trial.value == pytest.approx(objective.cvar(scores, 0.5)) == min(scores)
    fell = [t for t in trials if t.user_attrs["conditions_fallen"]]
    assert fell, "friction 0.05 should make the gait fall"
    assert all(objective.FALL_SCORE in t.user_attrs["condition_scores"] for t in fell)
    study = load(tmp_path)
    assert study.user_attrs["settings"]["cvar"] == 0.5
    # The re-measurement on new seeds scores the same way (the validated entry's CVaR).
    validated = [v for k, v in study.user_attrs.items() if k.startswith("validation_")]
    assert validated and all(len(v["condition_scores"]) == 2 for v in validated)
    assert all(v["cvar"] == min(v["condition_scores"]) for v in validated)


def test_cvar_needs_a_maximised_objective_and_a_share(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for extra, words in (
        (["--cvar", "0"], "(0, 1]"),
        (["--cvar", "0.5", "--objective", "slip_per_m"], "maximised"),
    ):
        with pytest.raises(SystemExit) as exc:
            main(tiny_args(tmp_path, "--n-trials", "1", *extra))
        err = capsys.readouterr().err
        assert exc.value.code == 2 and "--cvar" in err and words in err, (extra, err)


def test_against_default_scores_each_condition_by_its_margin_over_the_paper_gait(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--against-default``: a condition's score is the trial's minus the default gait's on the
    same seeds, so the default gait (trial 0) scores 0 everywhere and every trial's value is the
    CVaR of its margins; the validation scores the same way. It needs ``--cvar``."""
    grid = ["--condition", "friction:[0.05,1.0]", "--cvar", "0.5", "--against-default"]
    main(tiny_args(tmp_path, "--n-trials", "2", *grid))
    study = load(tmp_path)
    assert study.user_attrs["settings"]["against_default"] is True
    trials = study.get_trials(states=(optuna.trial.TrialState.COMPLETE,))
    default = [t for t in trials if t.user_attrs.get("default_gait")]
    assert len(default) == 1 and objective.FALL_SCORE in default[0].user_attrs["condition_scores"]
    # where the default gait falls (friction 0.05) it climbs nothing: falling there too scores
    # a fall; elsewhere the margin is over its score
    reference = [
        0.0 if s == objective.FALL_SCORE else s for s in default[0].user_attrs["condition_scores"]
    ]
    for trial in trials:
        scores, kept = trial.user_attrs["condition_scores"], trial.user_attrs["condition_margins"]
        assert kept == pytest.approx([s - r for s, r in zip(scores, reference, strict=True)])
        assert trial.value == pytest.approx(objective.cvar(kept, 0.5))
    validated = [v for k, v in study.user_attrs.items() if k.startswith("validation_")]
    assert validated and all(v["cvar"] == min(v["condition_margins"]) for v in validated)
    entry = tuned_gaits.read(tmp_path / "tuned.json")["acl"]
    assert entry["cvar"] == 0.5 and entry["against_default"] is True
    with pytest.raises(SystemExit) as exc:
        main(tiny_args(tmp_path / "other", "--n-trials", "1", "--against-default"))
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "--against-default" in err and "--cvar" in err


def test_the_frontier_names_what_a_trial_value_is() -> None:
    """The colour bar says whether a trial's value is the objective, its CVaR over the
    conditions, or the CVaR of the margins over the default gait."""
    from acl_env.tuning.frontier import value_label

    plain = objective.TuneSettings(objective="climb_per_gait_cycle_m")
    assert value_label(plain) == "climb_per_gait_cycle_m"
    risk = objective.TuneSettings(objective="climb_per_gait_cycle_m", cvar=0.25)
    assert "CVaR 0.25" in value_label(risk) and "margin" not in value_label(risk)
    against = objective.TuneSettings(cvar=0.25, against_default=True)
    assert "margin over the default gait" in value_label(against)
