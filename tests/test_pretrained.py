"""Pretrained policies (:mod:`acl_env.pretrained`): pickle-free files, numpy alone, and the same
deterministic actions as the SB3 policy they were exported from (:mod:`acl_env.evaluation.export`).

The shipped policies' SB3 files are not shipped, and the experiments keep only their runs'
exports; the tests that compare against the SB3 files take them from the git history
(``conftest.sb3_from_history``; skipped where there is none, e.g. in a shallow clone or an sdist).
"""

from __future__ import annotations

import json
import pickle
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import acl_env
from acl_env import pretrained, shipped
from acl_env.evaluation import baselines, export, records, tasks
from acl_env.evaluation import cli as evaluate_cli

ROOT = Path(__file__).resolve().parents[1]
# SB3 runs of the repository's experiments, exported in place: one with the cadence action, one
# non-rolling.
EXPERIMENT_RUNS = [
    "experiments/acl_cadence/acl_cadence_tuned_gait",
    "experiments/noroll_v3/noroll_v3_seed1",
]
STEPS = 300  # observations per policy, from rollouts of its own env


@pytest.fixture(scope="module")
def sb3_shipped(sb3_from_history: Callable[[str], Path]) -> dict[str, Path]:
    """The shipped policies' SB3 folders as they were before the export, from git history."""
    return {
        name: sb3_from_history(f"acl_env/data/policies/{name}") for name in shipped.list_policies()
    }


def _observations(policy: pretrained.PretrainedPolicy, seed: int = 0) -> np.ndarray:
    """``STEPS`` observations of the policy acting in its training env (randomised, so that
    they cover poles and gains), restarting after a fall."""
    env = gym.make(policy.env_id, **policy.env_kwargs)
    obs, _ = env.reset(seed=seed)
    rows = []
    for step in range(STEPS):
        rows.append(obs)
        obs, _, terminated, truncated, _ = env.step(policy(obs))
        if terminated or truncated:
            obs, _ = env.reset(seed=seed + step + 1)
    env.close()
    return np.asarray(rows)


def _sb3_actions(folder: Path, observations: np.ndarray) -> np.ndarray:
    """SB3's deterministic actions on VecNormalize-normalised observations (frozen), one by one
    as evaluation calls it."""
    from stable_baselines3 import PPO

    model = PPO.load(folder / "model.zip", device="cpu")
    stats = pickle.loads((folder / "vecnormalize.pkl").read_bytes())
    stats.training = False
    return np.asarray(
        [model.predict(stats.normalize_obs(o), deterministic=True)[0] for o in observations]
    )


def _assert_exports_exactly(sb3_folder: Path, out: Path, name: str) -> pretrained.PretrainedPolicy:
    export.export_policy(sb3_folder, out, name, trust_pickles=True)
    assert sorted(p.name for p in out.iterdir()) == ["policy.json", "policy.npz"]
    policy = pretrained.load_policy(out)
    observations = _observations(policy)
    expected = _sb3_actions(sb3_folder, observations)
    single = np.asarray([policy(o) for o in observations])
    batch, state = policy.predict(observations)
    assert state is None
    assert single.dtype == batch.dtype == expected.dtype == np.float32
    np.testing.assert_allclose(single, expected, rtol=0, atol=1e-5)
    np.testing.assert_allclose(batch, expected, rtol=0, atol=1e-5)
    return policy


@pytest.mark.parametrize("name", shipped.list_policies())
def test_shipped_policy_is_the_export_of_its_sb3_policy(
    name: str, sb3_shipped: dict[str, Path], tmp_path: Path
) -> None:
    """Exported again from the SB3 files it was made from, the shipped policy gives SB3's
    deterministic actions to 1e-5, and its arrays and metadata are that export's."""
    policy = _assert_exports_exactly(sb3_shipped[name], tmp_path / name, name)
    _assert_same_export(pretrained.load_policy(name), policy)


def _assert_same_export(
    kept: pretrained.PretrainedPolicy, fresh: pretrained.PretrainedPolicy
) -> None:
    """The arrays and metadata of a committed export are those of a fresh one (but for the
    published record's summary and the exporting versions)."""
    with (
        np.load(kept.path / pretrained.WEIGHTS_FILE) as kept_npz,
        np.load(fresh.path / pretrained.WEIGHTS_FILE) as fresh_npz,
    ):
        assert kept_npz.files == fresh_npz.files
        for key in kept_npz.files:
            assert np.array_equal(kept_npz[key], fresh_npz[key]), key
    differ = {k for k in kept.metadata if kept.metadata[k] != fresh.metadata.get(k)}
    assert differ <= {"evaluation", "exported_with"}, differ


@pytest.mark.parametrize("rel", EXPERIMENT_RUNS, ids=lambda rel: Path(rel).name)
def test_export_gives_the_sb3_policys_deterministic_actions(
    rel: str, sb3_from_history: Callable[[str], Path], tmp_path: Path
) -> None:
    """Exported again from its SB3 run (git history), an experiment's run gives SB3's
    deterministic actions, and the export committed beside the run's files is that export."""
    name = Path(rel).name
    policy = _assert_exports_exactly(sb3_from_history(rel), tmp_path / name, name)
    _assert_same_export(pretrained.load_policy(ROOT / rel), policy)


@pytest.mark.parametrize("name", shipped.list_policies())
def test_evaluation_builds_the_same_controllers_from_either_folder(
    name: str, sb3_shipped: dict[str, Path]
) -> None:
    """Env ids, env kwargs, notes: all the same for the pretrained folder as for its SB3 one."""
    from acl_env.training.policy import read_sb3_folder

    ship, sb3 = baselines.read_policy(shipped.policy_dir(name)), read_sb3_folder(sb3_shipped[name])
    assert isinstance(ship, pretrained.PretrainedPolicy)
    # The pretrained policy names its benchmark id (whose defaults are its task); the SB3 folder
    # the id and kwargs it was trained with: the same task, spelled two ways.
    assert ship.env_id in acl_env.BENCHMARK_BASES and ship.hyperparams == sb3.hyperparams
    # (a run trained on the benchmark id itself names it too: both spelled on the base id)
    assert tasks.spelled_on_base(ship.env_id, ship.env_kwargs) == tasks.spelled_on_base(
        sb3.env_id, sb3.env_kwargs
    )
    built = [
        baselines.build_controllers(f, {}, None, baselines.DEFAULT_TUNED_GAITS) for f in (ship, sb3)
    ]
    (ours, our_notes), (theirs, their_notes) = built
    assert our_notes == their_notes
    assert [c.policy_dir for c in ours] == [str(ship.path), *[None] * (len(ours) - 1)]
    assert [(c.name, c.env_id, c.env_kwargs, c.phase_rate) for c in ours] == [
        (c.name, c.env_id, c.env_kwargs, c.phase_rate) for c in theirs
    ]


@pytest.mark.parametrize("name", shipped.list_policies())
def test_a_shipped_policy_fits_its_registered_env(name: str) -> None:
    policy = acl_env.load_policy(name)
    assert name in acl_env.list_policies() and policy.name == name
    assert policy.env_id in gym.registry
    assert policy.metadata["format"] == pretrained.FORMAT
    assert policy.metadata["training"]["steps"] > 0
    assert set(policy.metadata["evaluation"]["controllers"]["policy"]) == set(
        records.SUMMARY_METRICS
    )
    env = gym.make(policy.env_id, **policy.env_kwargs)
    assert policy.observation_shape == env.observation_space.shape
    assert policy.action_shape == env.action_space.shape
    obs, _ = env.reset(seed=0)
    action = policy(obs)
    assert action.shape == env.action_space.shape and env.action_space.contains(action)
    assert np.array_equal(policy.predict(obs)[0], action)
    assert np.array_equal(policy.predict(obs[None])[0], action[None])
    noisy, _ = policy.predict(obs, deterministic=False)
    assert env.action_space.contains(noisy) and not np.array_equal(noisy, action)
    env.step(action)
    env.close()
    with pytest.raises(ValueError, match="observation of shape"):
        policy.predict(obs[:-1])
    # No pickles shipped.
    assert sorted(p.name for p in policy.path.iterdir()) == ["policy.json", "policy.npz"]


@pytest.mark.parametrize("name", shipped.list_policies())
def test_a_shipped_policys_metadata_summarises_its_own_published_record(name: str) -> None:
    """policy.json's ``evaluation`` is the summary of the record it names, a record of this
    policy (a stale copy names another policy's record or lacks its newer controllers)."""
    summary = acl_env.load_policy(name).metadata["evaluation"]
    record = ROOT / summary["record"]
    assert json.loads(record.read_text())["policy"] == f"acl_env/data/policies/{name}"
    assert summary == records.evaluation_summary(record, shown=summary["record"])


def _copy(tmp_path: Path, name: str = shipped.DEFAULT_POLICY) -> Path:
    copy = tmp_path / "copy"
    shutil.copytree(shipped.policy_dir(name), copy)
    return copy


def _edit_metadata(folder: Path, **changes: object) -> None:
    path = folder / pretrained.METADATA_FILE
    metadata = json.loads(path.read_text())
    for key, value in changes.items():
        if value is None:
            del metadata[key]
        else:
            metadata[key] = value
    path.write_text(json.dumps(metadata))


def _edit_arrays(folder: Path, **changes: object) -> None:
    path = folder / pretrained.WEIGHTS_FILE
    with np.load(path) as npz:
        arrays = {k: npz[k] for k in npz.files}
    for key, value in changes.items():
        if value is None:
            del arrays[key]
        else:
            arrays[key] = value
    with open(path, "wb") as f:
        np.savez(f, **arrays)


MALFORMED = {
    "no policy.json": (lambda f: (f / "policy.json").unlink(), "policy.json"),
    "no policy.npz": (lambda f: (f / "policy.npz").unlink(), "policy.npz"),
    "policy.json not JSON": (lambda f: (f / "policy.json").write_text("{"), "policy.json"),
    "policy.json a list": (lambda f: (f / "policy.json").write_text("[]"), "policy.json"),
    "unknown format": (lambda f: _edit_metadata(f, format="acl_env.policy/9"), "policy.json"),
    "no env_id": (lambda f: _edit_metadata(f, env_id=None), "policy.json"),
    "bad activation": (lambda f: _edit_metadata(f, activation="gelu"), "policy.json"),
    "bad net_arch": (lambda f: _edit_metadata(f, net_arch=[128, -1]), "policy.json"),
    "short bounds": (lambda f: _edit_metadata(f, action_low=[-1.0]), "policy.json"),
    "policy.npz garbage": (lambda f: (f / "policy.npz").write_bytes(b"PK garbage"), "policy.npz"),
    "missing array": (lambda f: _edit_arrays(f, hidden_1_bias=None), "policy.npz"),
    "wrong shape": (lambda f: _edit_arrays(f, action_bias=np.zeros(3)), "policy.npz"),
    "pickled array": (
        lambda f: _edit_arrays(f, log_std=np.array([{"a": 1}] * 21, dtype=object)),
        "policy.npz",
    ),
    "non-finite": (
        lambda f: _edit_arrays(f, obs_var=np.full(89, np.nan)),
        "policy.npz",
    ),
}


@pytest.mark.parametrize("case", MALFORMED)
def test_a_malformed_folder_is_refused_naming_the_file(case: str, tmp_path: Path) -> None:
    folder = _copy(tmp_path)
    breaks, file = MALFORMED[case]
    breaks(folder)
    with pytest.raises(ValueError, match=file.replace(".", r"\.")) as error:
        pretrained.load_policy(folder)
    assert str(folder) in str(error.value)


def test_a_name_that_is_neither_shipped_nor_a_folder_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="acl_climb_ppo"):
        pretrained.load_policy("no_such_policy")
    with pytest.raises(ValueError, match="not a pretrained policy"):
        pretrained.load_policy(tmp_path)


def test_an_unregistered_env_or_other_spaces_are_refused(tmp_path: Path) -> None:
    folder = _copy(tmp_path)
    _edit_metadata(folder, env_id="acl_env/NoSuchEnv-v0")
    with pytest.raises(ValueError, match="not registered"):
        baselines.read_policy(folder)
    policy = pretrained.load_policy(shipped.DEFAULT_POLICY)
    env = gym.make(policy.env_id, **{**policy.env_kwargs, "phase_rate_range": None})
    with pytest.raises(pretrained.SpaceMismatchError, match="action_space"):
        policy.check_spaces(env)
    env.close()


def test_the_loader_and_evaluation_need_neither_torch_nor_yaml() -> None:
    """A shipped policy loads and acts, and evaluation builds and plays its controllers, with no
    torch, SB3 or PyYAML imported."""
    probe = """
import sys
import acl_env.pretrained as pretrained
policy = pretrained.load_policy("acl_climb_noroll_ppo")
from acl_env.evaluation import baselines, run_episode
folder = baselines.read_policy(policy.path)
controllers, _ = baselines.build_controllers(folder, {}, None, baselines.DEFAULT_TUNED_GAITS)
env = controllers[0].make_env(cycles_per_episode=1, steps_per_cycle=20)
episode = run_episode(env, controllers[0].make_policy(env), 0)
assert episode.steps == 20, episode.steps
print(sorted(m for m in ("torch", "stable_baselines3", "yaml") if m in sys.modules))
"""
    out = subprocess.run(
        [sys.executable, "-c", probe], cwd=ROOT, capture_output=True, text=True, check=True
    )
    assert out.stdout.split()[-1] == "[]", out.stdout


def test_acl_evaluate_takes_a_shipped_name_or_a_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    parser = evaluate_cli.make_parser()
    assert parser.parse_args([]).policy == [shipped.policy_dir()]
    for name in shipped.list_policies():
        assert parser.parse_args(["--policy", name]).policy == [shipped.policy_dir(name)]
    assert parser.parse_args(["--policy", str(tmp_path)]).policy == [tmp_path]
    with pytest.raises(SystemExit) as exit_info:
        parser.parse_args(["--policy", "no_such_policy"])
    assert exit_info.value.code == 2
    assert "acl_climb_noroll_ppo" in capsys.readouterr().err
    folder = _copy(tmp_path)
    (folder / "policy.npz").write_bytes(b"garbage")
    with pytest.raises(SystemExit) as exit_info:
        evaluate_cli.main(["--policy", str(folder), "--episodes", "1", "--no-progress-bar"])
    err = capsys.readouterr().err.strip()
    assert exit_info.value.code == 2 and len(err.splitlines()) == 1
    assert "--policy" in err and "policy.npz" in err


def test_the_export_names_the_commands_that_resumed_its_run(
    tmp_path: Path, sb3_from_history: Callable[[str], Path]
) -> None:
    """A resumed run's steps come from its first command and its resumes: policy.json names
    both, so that the command alone is not mistaken for the whole training."""
    from acl_env.training.policy import read_sb3_folder

    folder = tmp_path / "run"
    shutil.copytree(sb3_from_history(EXPERIMENT_RUNS[1]), folder)
    args = json.loads((folder / "args.json").read_text())
    assert export.training_summary(read_sb3_folder(folder), 1, None).get("resumed_with") is None
    args["resumes"] = [{"argv": ["--resume", "runs/x", "--trust-pickles", "--n-timesteps", "5"]}]
    (folder / "args.json").write_text(json.dumps(args))
    summary = export.training_summary(read_sb3_folder(folder), 1, None)
    assert summary["command"].startswith("acl-train ") and "--resume" not in summary["command"]
    assert summary["resumed_with"] == ["acl-train --resume runs/x --trust-pickles --n-timesteps 5"]


def test_the_exporter_command_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], sb3_from_history: Callable[[str], Path]
) -> None:
    """It writes both files and prints them; a folder without SB3 files is refused in one line."""
    source, out = sb3_from_history(EXPERIMENT_RUNS[1]), tmp_path / "out"
    record = ROOT / "docs" / "eval_noroll.json"
    export.main(
        [str(source), str(out), "--name", "seed1", "--record", str(record), "--trust-pickles"]
    )
    assert capsys.readouterr().out.split() == [str(out / "policy.npz"), str(out / "policy.json")]
    metadata = json.loads((out / "policy.json").read_text())
    assert metadata["name"] == "seed1" and metadata["evaluation"]["record"].endswith(record.name)
    assert metadata["training"]["command"].startswith("acl-train ")
    (tmp_path / "empty").mkdir()
    with pytest.raises(SystemExit) as exit_info:
        export.main([str(tmp_path / "empty"), str(tmp_path / "again"), "--name", "x"])
    assert exit_info.value.code == 2
    assert not (tmp_path / "again").exists()


def test_an_exported_policy_reexports_under_its_tasks_own_id(tmp_path: Path) -> None:
    """An exported folder given to the exporter is copied under the most specific registered id
    its task has: the asymmetric critic arm, exported on ACLClimbRobust-v1 with
    ``privileged_obs=True``, is ACLClimbRobust-v3's at its defaults, with the same weights and the
    same actions there."""
    source = ROOT / "experiments" / "robust_ablation" / "asymmetric_critic"
    out = export.main([str(source), str(tmp_path / "v3"), "--name", "seed0"])
    before, after = (json.loads((f / "policy.json").read_text()) for f in (source, out))
    assert (before["env_id"], before["env_kwargs"]["privileged_obs"]) == (
        acl_env.ACL_CLIMB_ROBUST_ID,
        True,
    )
    assert after["env_id"] == acl_env.ACL_CLIMB_ROBUST_V3_ID and after["name"] == "seed0"
    assert after["env_kwargs"] == {
        "domain_randomization": before["env_kwargs"]["domain_randomization"]
    }
    assert {k: v for k, v in after.items() if k not in ("name", "env_id", "env_kwargs")} == {
        k: v for k, v in before.items() if k not in ("name", "env_id", "env_kwargs")
    }
    assert (out / "policy.npz").read_bytes() == (source / "policy.npz").read_bytes()
    with pytest.raises(SystemExit):  # an exported folder has no run to summarise or date
        export.main([str(source), str(tmp_path / "x"), "--name", "x", "--commit", "abc"])
    assert not (tmp_path / "x").exists()
    env = gym.make(acl_env.ACL_CLIMB_ROBUST_V3_ID)
    old, new = pretrained.load_policy(source), pretrained.load_policy(out)
    new.check_spaces(env)
    obs, _ = env.reset(seed=0)
    for _ in range(5):
        action = new(obs)
        np.testing.assert_array_equal(action, old(obs))
        obs, *_ = env.step(action)
