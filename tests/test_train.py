"""Training and evaluation commands, through the command line a user types (``acl-train``,
``acl-evaluate``, run as ``python -m <module>``), and the recipes they train from: the shipped one
(``acl_env/data/ppo.yml``) and the experiments' deltas over it (``experiments/*/*/recipe.yml``)."""

from __future__ import annotations

import inspect
import json
import math
import pickle
import subprocess
import sys
from pathlib import Path

import gymnasium
import pytest
import yaml

import acl_env
from acl_env import (
    ACL_CLIMB_COMPLIANT_ID,
    ACL_CLIMB_ID,
    ACL_CLIMB_NOROLL_COMPLIANT_ID,
    ACL_CLIMB_NOROLL_ID,
    ACL_CLIMB_NOROLL_SEA_ID,
    ACL_CLIMB_NOROLL_V2_ID,
    ACL_CLIMB_SEA_ID,
    NOROLL_KWARGS,
    ROLLING_HELIX_CLIMB_ID,
    evaluation,
    shipped,
    tuned_gaits,
)
from acl_env.envs import ACLClimbEnv
from acl_env.io import parse_kv_pairs
from acl_env.training import config

ROOT = Path(__file__).resolve().parents[1]
RECIPE = shipped.recipe_path()  # the shipped recipe, acl_env/data/ppo.yml
EXPERIMENTS = ROOT / "experiments"
TRAIN_MODULE = "acl_env.training.trainer"  # acl-train
EVALUATE_MODULE = "acl_env.evaluation.cli"  # acl-evaluate

ACL_ID = ACL_CLIMB_ID
HELIX_ID = ROLLING_HELIX_CLIMB_ID
NOROLL_IDS = (ACL_CLIMB_NOROLL_ID, ACL_CLIMB_NOROLL_V2_ID)  # v2: the ablations trained on it

SHORT = {"steps_per_cycle": 20, "cycles_per_episode": 1}  # 20-step episodes
SHORT_ARGS = [f"{k}:{v}" for k, v in SHORT.items()]
TRAIN_STEPS = 512


def run_script(*args: str, timeout: float = 400) -> subprocess.CompletedProcess:
    """Run ``python args`` (``-m <module> ...``) from the repository root; fail with its output."""
    proc = subprocess.run(
        [sys.executable, *args], cwd=ROOT, capture_output=True, text=True, timeout=timeout
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return proc


def train_command(run_root: Path, n_timesteps: int, *extra: str) -> list[str]:
    """A tiny training run: 2 subprocess envs, 128-step rollouts, 20-step episodes."""
    return [
        *["-m", TRAIN_MODULE],
        "--env",
        ACL_ID,
        "--seed",
        "0",
        "--n-timesteps",
        str(n_timesteps),
        "--n-envs",
        "2",
        "--run-dir",
        str(run_root),
        "--hyperparams",
        "n_steps:128",
        "batch_size:64",
        "n_epochs:2",
        "--env-kwargs",
        *SHORT_ARGS,
        "--checkpoint-freq",
        "256",
        "--no-progress-bar",
        *extra,
    ]


@pytest.fixture(scope="module")
def trained_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One tiny training run shared by the slow tests."""
    run_root = tmp_path_factory.mktemp("runs")
    run_script(*train_command(run_root, TRAIN_STEPS))
    (run_dir,) = run_root.iterdir()
    return run_dir


# ---- fast tests ------------------------------------------------------------------------------


def test_config_entries_build_ppo_arguments() -> None:
    """Both env entries parse; the residual starts small; gamma is long-horizon."""
    for env_id in (ACL_ID, HELIX_ID):
        hyperparams = config.load_hyperparams(RECIPE, env_id)
        kwargs = config.algo_kwargs(hyperparams)
        # Initial joint noise = action std x residual_scale: at most 0.03 rad, which the open-loop
        # gait shrugs off (ppo.yml's comment has the measurements).
        std = math.exp(kwargs["policy_kwargs"]["log_std_init"])
        assert std * hyperparams["env_kwargs"]["residual_scale"] <= 0.03
        assert 0.99 <= kwargs["gamma"] < 1.0
        assert config.normalize_kwargs(hyperparams) == {
            "norm_obs": True,
            "norm_reward": True,
            "gamma": kwargs["gamma"],
        }
        assert hyperparams["env_kwargs"]["domain_randomization"]
        assert not set(kwargs) & set(config.NON_ALGO_KEYS)


def recipe(experiment: str) -> Path:
    """The recipe of an experiment's run: ``experiments/<topic>/<run>/recipe.yml``."""
    (path,) = EXPERIMENTS.glob(f"*/{experiment}/recipe.yml")
    return path


def gaits_file(name: str) -> Path:
    """A tuned-gaits file of the experiments: ``experiments/<topic>/<name>.json``."""
    (path,) = EXPERIMENTS.glob(f"*/{name}.json")
    return path


def test_shipped_recipe_names_the_shipped_tuned_gait() -> None:
    """ppo.yml's ACLClimb-v1 entry names its gait by key (``tuned_gait: acl``, one home for the
    numbers): it resolves to the shipped "acl" entry, whose reward weights are the recipe's (the
    tuner's objective, so evaluation's tuned open loop is the best gait for the same reward), and
    the env it builds plays that gait."""
    from acl_env.training.checks import check_env_kwargs

    env_kwargs = config.load_hyperparams(RECIPE, ACL_ID)["env_kwargs"]
    assert env_kwargs["tuned_gait"] == "acl"
    entry = tuned_gaits.entry("acl")
    resolved = tuned_gaits.resolve(env_kwargs)
    assert "tuned_gait" not in resolved
    assert resolved["squeeze"] == entry["env_kwargs"]["squeeze"]
    assert resolved["gait_kwargs"] == entry["env_kwargs"]["gait_kwargs"]
    assert env_kwargs["reward_weights"] == entry["reward_weights"]
    env = check_env_kwargs(ACL_ID, {**env_kwargs, **SHORT})
    try:
        assert env.unwrapped.config.gait.squeeze == entry["env_kwargs"]["squeeze"]
    finally:
        env.close()


# (experiment, tuned-gaits file or None for the shipped ones, same reward weights): recipes that
# start from a tuner's "acl" gait
GAIT_RECIPES = [
    ("acl_cadence_tuned_gait", None, True),
    ("acl_cadence_tuned_gait_critic", None, True),
    ("acl_slip_weight_3", None, False),
    ("acl_cadence_range_1_5", None, True),
    ("acl_gae_lambda_098", None, True),
    ("acl_cadence2_gait", "tuned_gaits_cadence2", True),
    ("acl_energy_gait", "tuned_gaits_acl_energy", True),
    ("acl_constant_lr", "tuned_gaits_acl_energy", True),
    ("acl_no_energy_term", "tuned_gaits_acl_energy", False),
    ("acl_climb_slip_tuned_gait", "tuned_gaits_climb_slip", True),
]


@pytest.mark.parametrize(("experiment", "gaits", "same_weights"), GAIT_RECIPES)
def test_recipe_plays_the_tuned_gait(
    experiment: str, gaits: str | None, same_weights: bool
) -> None:
    """The ablations beside the shipped recipe start from a tuner's "acl" gait (the shipped one,
    by key or by its numbers, or a study's of their own)."""
    hyperparams = config.load_hyperparams(recipe(experiment), ACL_ID)
    tuned = tuned_gaits.read(None if gaits is None else gaits_file(gaits))["acl"]
    env_kwargs = tuned_gaits.resolve(hyperparams["env_kwargs"])
    assert env_kwargs["squeeze"] == tuned["env_kwargs"]["squeeze"]
    assert env_kwargs["gait_kwargs"] == tuned["env_kwargs"]["gait_kwargs"]
    assert (env_kwargs["reward_weights"] == tuned["reward_weights"]) is same_weights


def test_shipped_gait_is_the_best_open_loop_found_at_the_policys_cadence() -> None:
    """The shipped "acl" gait, the shipped recipe's base, was tuned for the shipped reward (at
    1.45 keyframes per step). A second study of the same reward, tuned at the shipped policy's
    mean cadence (within 5 %, docs/eval.json), found no better gait there: in
    experiments/acl_cadence/cadence_sweep.json the shipped gait earns at least as much per gait
    cycle at that cadence, within the 95 % interval, and more than the cadence-1 study's gait at
    every cadence swept."""
    from acl_env.evaluation.tasks import tuned_gait

    entry = tuned_gaits.entry("acl")
    at_cadence = tuned_gaits.read(gaits_file("tuned_gaits_cadence2"))["acl"]
    weights = config.load_hyperparams(RECIPE, ACL_ID)["env_kwargs"]["reward_weights"]
    assert entry["reward_weights"] == at_cadence["reward_weights"] == weights
    cadence = json.loads((ROOT / "docs" / "eval.json").read_text())["same_cadence_phase_rate"]
    default_cycle = inspect.signature(ACLClimbEnv).parameters["steps_per_cycle"].default
    assert "steps_per_cycle" not in (gymnasium.spec(ACL_ID).kwargs or {})
    assert default_cycle / at_cadence["steps_per_cycle"] == pytest.approx(cadence, rel=0.05)
    gait, note = tuned_gait(tuned_gaits.shipped_path(), weights, non_rolling=False)
    assert gait is not None and "NOT" not in note
    assert gait[1]["gait_kwargs"]["rolls_per_cycle"] == 1

    sweep = json.loads((EXPERIMENTS / "acl_cadence" / "cadence_sweep.json").read_text())
    assert sweep["tuned_gaits"] == [  # the record names the files as they were then
        "train/configs/tuned_gaits.yml",
        "train/configs/tuned_gaits_cadence2.yml",
        "train/configs/tuned_gaits_acl_energy.yml",
    ]
    assert sweep["reward_weights"] == weights
    reward = {(row["gait"], row["rate"]): row["reward_per_gait_cycle"] for row in sweep["rows"]}
    rates = sorted({rate for _, rate in reward})
    assert rates[0] <= 1.0 and rates[-1] >= cadence
    for rate in rates:
        shipped, other = reward[("tuned_gaits", rate)], reward[("tuned_gaits_acl_energy", rate)]
        assert shipped["mean"] > other["mean"], rate
    nearest = min(rates, key=lambda rate: abs(rate - cadence))
    shipped, tuned_there = (
        reward[("tuned_gaits", nearest)],
        reward[("tuned_gaits_cadence2", nearest)],
    )
    assert shipped["mean"] >= tuned_there["mean"] - tuned_there["half_width"]


@pytest.mark.parametrize(
    ("env_id", "policy"),
    [
        (ACL_ID, "acl_climb_ppo"),
        (ACL_CLIMB_NOROLL_ID, "acl_climb_noroll_ppo"),
        (ACL_CLIMB_SEA_ID, "acl_climb_sea_ppo"),
        (ACL_CLIMB_NOROLL_SEA_ID, "acl_climb_noroll_sea_ppo"),
        (ACL_CLIMB_COMPLIANT_ID, "acl_climb_compliant_ppo"),
        (ACL_CLIMB_NOROLL_COMPLIANT_ID, "acl_climb_noroll_compliant_ppo"),
    ],
)
def test_shipped_policy_was_trained_with_the_committed_recipe(env_id: str, policy: str) -> None:
    """Each shipped policy comes from its ppo.yml entry: the recipe its metadata records must be
    that entry (``n_timesteps`` aside: a run in segments passes ``--n-timesteps`` per segment),
    and the run must have trained all of its steps."""
    training = acl_env.load_policy(policy).metadata["training"]
    recipe = config.load_hyperparams(RECIPE, env_id)
    trained = training["hyperparams"]
    assert {k: v for k, v in trained.items() if k != "n_timesteps"} == {
        k: v for k, v in recipe.items() if k != "n_timesteps"
    }
    assert not training["interrupted"]
    assert training["steps"] >= recipe["n_timesteps"]


# Ablations that train with another slip weight than the shipped recipe's 2 (reward shaping); the
# README evaluates them under the shipped weights, against the open loop tuned for those.
SHAPED_SLIP_WEIGHT = {"acl_slip_weight_3": 3.0}
# Non-rolling runs whose objective is the climb (slip 0), on a gait a climb study found, as
# ppo.yml's shipped non-rolling recipe; the roll term stays. Experiment -> that study's gaits file
# (None: the shipped tuned gaits) and entry.
NOROLL_CLIMB_GAITS = {
    "noroll_v2_gait": (None, "acl_noroll"),
    "noroll_climb_gait_action_rate": ("tuned_gaits_noroll_climb", "acl_noroll_climb"),
    "noroll_climb_gait": ("tuned_gaits_noroll_climb", "acl_noroll_climb"),
    "noroll_no_action_rate": ("tuned_gaits_noroll_climb", "acl_noroll_climb"),
    "noroll_climb_rerun_gait": ("tuned_gaits_noroll_climb_rerun", "acl_noroll_climb"),
    "noroll_wide_range_warm": ("tuned_gaits_noroll_climb", "acl_noroll_climb"),
    "noroll_thin_pole_warm": ("tuned_gaits_noroll_climb", "acl_noroll_climb"),
    "noroll_roll_margin_warm": ("tuned_gaits_noroll_climb", "acl_noroll_climb"),
    "noroll_thin_gait_action_rate": ("tuned_gaits_noroll_climb_thin", "acl_noroll_climb_thin"),
    "noroll_thin_gait": ("tuned_gaits_noroll_climb_thin", "acl_noroll_climb_thin"),
}
# Climb recipes on a gait another study found: experiment -> that study's objective (by default
# the climb's). The registered reward's study, rerun on v2, found the gait that climbs furthest.
NOROLL_GAIT_OBJECTIVE = {"noroll_v2_gait": "reward_per_gait_cycle"}
NOROLL_CLIMB_OBJECTIVE = tuple(NOROLL_CLIMB_GAITS)
# Climb recipes on v3's registered gait (no gait kwargs), as ppo.yml's: experiment -> the terms it
# adds to the climb objective's weights. residual_016 doubles the residual's bound and keeps the
# action-rate penalty per squared radian: 0.001 / 0.08**2 = 0.004 / 0.16**2.
NOROLL_V3_CLIMB_EXTRA_WEIGHTS = {"noroll_v3_residual_016": {"action_rate": 0.004}}
# Terms a climb recipe adds to the climb objective's weights (a shaping ablation).
NOROLL_CLIMB_EXTRA_WEIGHTS = {
    "noroll_v2_gait": {"action_rate": 0.001},
    "noroll_thin_gait_action_rate": {"action_rate": 0.001},
    "noroll_climb_gait_action_rate": {"action_rate": 0.001},
}


@pytest.mark.parametrize(
    "path", sorted(EXPERIMENTS.glob("*/*/recipe.yml")), ids=lambda path: path.parent.name
)
def test_ablation_configs_are_valid_recipes(path: Path) -> None:
    """Each experiment's recipe is a zoo file the trainer accepts (a delta over the shipped
    recipe, resolved), whose env kwargs build the env."""
    from acl_env.training.checks import check_env_kwargs, check_hyperparams

    (env_id,) = yaml.safe_load(path.read_text())  # one entry per file
    hyperparams = config.load_hyperparams(path, env_id)
    check_hyperparams(hyperparams, str(path))
    env_kwargs = {**hyperparams["env_kwargs"], **SHORT}
    env_id = acl_env.current_id(env_id)  # an experiment run on a task's old id: the same task
    # quiet: an older version of a task, as the experiment's record made it
    check_env_kwargs(env_id, env_kwargs, quiet=True).close()
    weights = hyperparams["env_kwargs"]["reward_weights"]
    experiment = path.parent.name
    if experiment in NOROLL_CLIMB_OBJECTIVE:  # checked by the test below
        assert weights["slip"] == 0.0
    elif experiment in NOROLL_V3_CLIMB_EXTRA_WEIGHTS:  # the registered gait
        assert env_id == ACL_CLIMB_NOROLL_ID
        assert not {"squeeze", "gait_kwargs", "tuned_gait"} & set(hyperparams["env_kwargs"])
        assert weights == {
            **NOROLL_KWARGS["reward_weights"],
            "slip": 0.0,
            **NOROLL_V3_CLIMB_EXTRA_WEIGHTS[experiment],
        }
    elif env_id in NOROLL_IDS:  # the task's registered weights, the tuner's objective
        assert weights == NOROLL_KWARGS["reward_weights"]
    else:  # the shipped recipe's weights, or a shaping ablation's (evaluated under the shipped)
        assert weights["slip"] == SHAPED_SLIP_WEIGHT.get(experiment, 2.0)


@pytest.mark.parametrize("experiment", NOROLL_CLIMB_OBJECTIVE)
def test_noroll_climb_recipe_plays_the_climb_studys_gait(experiment: str) -> None:
    """The shipped non-rolling recipe's ablations start from the gait a climb study found (or,
    where NOROLL_GAIT_OBJECTIVE says, another study), and train for the climb (slip weight 0; the
    registered roll term kept), so its open loop is the best gait found for the climb."""
    path = recipe(experiment)
    (env_id,) = yaml.safe_load(path.read_text())  # one entry per file
    hyperparams = config.load_hyperparams(path, env_id)
    gaits, key = NOROLL_CLIMB_GAITS[experiment]
    entry = tuned_gaits.read(None if gaits is None else gaits_file(gaits))[key]
    assert entry["objective"] == NOROLL_GAIT_OBJECTIVE.get(experiment, "climb_per_gait_cycle_m")
    assert entry["env_kwargs"]["gait_kwargs"]["rolls_per_cycle"] == 0
    env_kwargs = tuned_gaits.resolve(hyperparams["env_kwargs"])
    for key in ("squeeze", "gait_kwargs"):
        assert env_kwargs[key] == entry["env_kwargs"][key]
    assert env_kwargs["reward_weights"] == {
        **NOROLL_KWARGS["reward_weights"],
        "slip": 0.0,
        **NOROLL_CLIMB_EXTRA_WEIGHTS.get(experiment, {}),
    }


# --- recipes as deltas over the shipped recipe --------------------------------------------------


def write_recipe(tmp_path: Path, entry: dict[str, object]) -> Path:
    """A one-entry recipe for the non-rolling v2 env."""
    path = tmp_path / "recipe.yml"
    path.write_text(yaml.safe_dump({ACL_CLIMB_NOROLL_V2_ID: entry}, sort_keys=False))
    return path


def test_recipe_delta_replaces_top_level_keys_and_merges_env_kwargs(tmp_path: Path) -> None:
    """A delta's top-level keys replace its base's; its env kwargs are merged key by key, a value
    replacing the base's whole; the result is a plain full recipe (no ``base``)."""
    base = config.load_hyperparams(RECIPE, ACL_CLIMB_NOROLL_ID)
    path = write_recipe(
        tmp_path,
        {
            "base": ACL_CLIMB_NOROLL_ID,
            "n_timesteps": 1000,
            "gamma": 0.99,
            "env_kwargs": {"squeeze": 0.0157, "reward_weights": {"climb": 1.0}},
        },
    )
    resolved = config.load_hyperparams(path, ACL_CLIMB_NOROLL_V2_ID)
    assert "base" not in resolved
    assert resolved == {
        **base,
        "n_timesteps": 1000,
        "gamma": 0.99,
        "env_kwargs": {**base["env_kwargs"], "squeeze": 0.0157, "reward_weights": {"climb": 1.0}},
    }
    assert base["n_timesteps"] != 1000 and base["env_kwargs"]["domain_randomization"]
    config.save_hyperparams(tmp_path / "config.yml", ACL_CLIMB_NOROLL_V2_ID, resolved)
    assert config.load_hyperparams(tmp_path / "config.yml", ACL_CLIMB_NOROLL_V2_ID) == resolved


def test_recipe_delta_null_removes_an_env_kwarg(tmp_path: Path) -> None:
    """``null`` in a delta's env kwargs removes the base's key (the env's default applies)."""
    path = write_recipe(
        tmp_path, {"base": ACL_CLIMB_NOROLL_ID, "env_kwargs": {"domain_randomization": None}}
    )
    resolved = config.load_hyperparams(path, ACL_CLIMB_NOROLL_V2_ID)
    base = config.load_hyperparams(RECIPE, ACL_CLIMB_NOROLL_ID)
    assert "domain_randomization" not in resolved["env_kwargs"]
    assert resolved["env_kwargs"] == {
        k: v for k, v in base["env_kwargs"].items() if k != "domain_randomization"
    }


def test_recipe_delta_changing_a_tuned_gait_writes_out_its_numbers(tmp_path: Path) -> None:
    """Over a base that names its gait by key, a delta's squeeze changes that gait's squeeze."""
    path = tmp_path / "recipe.yml"
    path.write_text(yaml.safe_dump({ACL_ID: {"base": ACL_ID, "env_kwargs": {"squeeze": 0.001}}}))
    env_kwargs = config.load_hyperparams(path, ACL_ID)["env_kwargs"]
    assert "tuned_gait" not in env_kwargs and env_kwargs["squeeze"] == 0.001
    assert env_kwargs["gait_kwargs"] == tuned_gaits.gait_shape("acl")["gait_kwargs"]


@pytest.mark.parametrize("base", ["acl_env/NoSuchEnv-v0", ".residual-ppo", 3])
def test_recipe_delta_on_an_unknown_base_is_refused(tmp_path: Path, base: object) -> None:
    """A base that is not an entry of the shipped recipe is refused, naming it and the entries."""
    path = write_recipe(tmp_path, {"base": base, "n_timesteps": 1000})
    with pytest.raises(config.RecipeError, match=f"base {base!r}.*{ACL_CLIMB_NOROLL_ID}"):
        config.load_hyperparams(path, ACL_CLIMB_NOROLL_V2_ID)


def test_linear_schedule_decays_to_zero() -> None:
    """The zoo's ``lin_X`` becomes X at the start of training, X / 2 halfway and 0 at the end,
    with no SB3 deprecation warning (``get_linear_fn`` is deprecated since SB3 2.5)."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        kwargs = config.algo_kwargs({"learning_rate": "lin_2e-4", "clip_range": 0.2})
    schedule = kwargs["learning_rate"]
    # SB3 calls schedules with progress_remaining: 1 at the start of training, 0 at the end.
    assert [schedule(p) for p in (1.0, 0.5, 0.0)] == pytest.approx([2e-4, 1e-4, 0.0])
    assert kwargs["clip_range"] == 0.2
    with pytest.raises(ValueError, match="learning_rate"):
        config.algo_kwargs({"learning_rate": "linear_2e-4"})


def test_config_strings_are_parsed_without_eval() -> None:
    """Zoo strings become objects; code is rejected instead of run."""
    import torch

    parsed = config.parse_python_literal("dict(activation_fn=nn.ReLU, net_arch=[64], x=-1e-3)")
    assert parsed == {"activation_fn": torch.nn.ReLU, "net_arch": [64], "x": -1e-3}
    with pytest.raises(ValueError):
        config.parse_python_literal("__import__('os').system('true')")
    assert parse_kv_pairs(["a:0.5", "b:acl", "c:{'k': [1, 2]}"]) == {
        "a": 0.5,
        "b": "acl",
        "c": {"k": [1, 2]},
    }


# ---- slow tests: real training runs ----------------------------------------------------------


@pytest.mark.slow
def test_training_writes_a_run_folder(trained_run: Path) -> None:
    """model, VecNormalize statistics, merged config, arguments, summary and checkpoints."""
    for name in ("model.zip", "vecnormalize.pkl", "vecnormalize.npz", "config.yml", "args.json"):
        assert (trained_run / name).is_file(), name
    assert trained_run.name.startswith(f"{ACL_ID.replace('/', '_')}__ppo__0__")
    config = yaml.safe_load((trained_run / "config.yml").read_text())
    entry = config[ACL_ID]
    assert entry["n_steps"] == 128 and entry["n_envs"] == 2
    assert entry["env_kwargs"]["steps_per_cycle"] == 20
    assert "domain_randomization" in entry["env_kwargs"]  # the yml's, merged with the overrides
    summary = json.loads((trained_run / "summary.json").read_text())
    assert summary["steps"] == summary["total_steps"] == TRAIN_STEPS
    assert summary["env_steps_per_s"] > 0 and not summary["interrupted"]
    (segment,) = summary["segments"]
    assert set(segment["time_s"]) >= {"env_step", "policy_inference", "gradient_update"}
    assert all(seconds >= 0 for seconds in segment["time_s"].values())
    # The saved files load: the model at the trained step count, statistics counted alike.
    from stable_baselines3 import PPO

    model = PPO.load(trained_run / "model.zip", device="cpu")
    assert model.num_timesteps == TRAIN_STEPS
    stats = pickle.loads((trained_run / "vecnormalize.pkl").read_bytes())
    assert stats.ret_rms.count == pytest.approx(1e-4 + TRAIN_STEPS)
    assert sorted((trained_run / "checkpoints").glob("model_vecnormalize_*_steps.pkl"))
    assert list((trained_run / "tb").rglob("events.out.tfevents.*"))


@pytest.mark.slow
def test_evaluate_loads_the_run(trained_run: Path, tmp_path: Path) -> None:
    """A trained run evaluates through the command line: every controller has every metric."""
    out, plot = tmp_path / "eval.json", tmp_path / "eval.png"
    run_script(
        *["-m", EVALUATE_MODULE],
        *["--policy", str(trained_run), "--trust-pickles", "--episodes", "2", "--json", str(out)],
        *["--plot", str(plot), "--no-progress-bar", "--env-kwargs", *SHORT_ARGS],
    )
    document = json.loads(out.read_text())
    assert {"policy", "open_loop_acl", "open_loop_rolling_helix"} <= set(document["controllers"])
    for summary in document["controllers"].values():
        for metric in evaluation.METRICS:
            assert {"mean", "ci95"} <= set(summary[metric])
            assert len(summary[metric]["values"]) == 2
        assert summary["episodes"] == 2
    assert math.isfinite(document["controllers"]["policy"]["climb_per_gait_cycle_m"]["mean"])
    assert "domain_randomization" not in document["env_kwargs"]["policy"]
    assert plot.stat().st_size > 0


# Interrupt, resume and bad command lines: tests/test_trainer.py.


@pytest.mark.slow
def test_the_zoo_trains_from_the_config(tmp_path: Path) -> None:
    """rl-baselines3-zoo reads the shipped recipe as it is (policy_kwargs, normalize strings)."""
    run_script(
        *["-m", "rl_zoo3.train", "--algo", "ppo", "--env", ACL_ID, "--gym-packages", "acl_env"],
        *["--conf-file", str(RECIPE), "-n", "128", "--eval-freq", "-1"],
        *["--log-folder", str(tmp_path), "--hyperparams", "n_steps:64", "batch_size:64"],
        *["--env-kwargs", *SHORT_ARGS],
    )
    assert list(tmp_path.rglob("vecnormalize.pkl"))
    assert list(tmp_path.rglob(f"*{ACL_ID.split('/')[1]}.zip"))


def test_console_scripts_exit_with_a_status_not_a_document() -> None:
    """A console script runs ``sys.exit(target())``: a target returning a document (as the
    ``main`` functions do, for callers in Python) would be printed and exit with status 1. Every
    script in pyproject.toml must return None or an exit status."""
    import importlib
    import tomllib
    import typing

    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]
    assert {"acl-train", "acl-evaluate", "acl-tune-gait", "acl-compare"} <= set(scripts)
    for name, target in scripts.items():
        module, function = target.split(":")
        returns = typing.get_type_hints(getattr(importlib.import_module(module), function))
        assert returns["return"] in (type(None), int), name
