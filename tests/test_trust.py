"""Files from elsewhere run no code unasked: SB3 pickles load only with
``--trust-pickles`` / ``trust_pickles=True``, training writes its statistics pickle-free too, a
config names only allowed classes, and no write follows a symlink out of its folder.

A crafted ``vecnormalize.pkl`` or ``model.zip`` here creates a marker file when unpickled; every
command and function refusing it must leave no marker.
"""

from __future__ import annotations

import base64
import json
import os
import pickle
import shutil
import sys
import zipfile
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest
import yaml

from acl_env import ACL_CLIMB_ID
from acl_env.evaluation import cli as evaluate_cli
from acl_env.evaluation import export
from acl_env.io import atomic_output, atomic_write, check_output
from acl_env.training import config, runs, trainer
from acl_env.training.arguments import make_parser
from acl_env.training.plan import plan_segment
from acl_env.training.policy import load_policy, read_sb3_folder

ROOT = Path(__file__).resolve().parents[1]
SHORT = {"steps_per_cycle": 20, "cycles_per_episode": 1}


class Marker:
    """Unpickled, it creates its file (``open(path, "w")``): the stand-in for any code."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def __reduce__(self) -> tuple[Any, tuple[str, str]]:
        return open, (str(self.path), "w")


def crafted_folder(tmp_path: Path, which: str) -> tuple[Path, Path]:
    """An SB3 policy folder (valid ``config.yml``) whose ``which`` file (``vecnormalize.pkl``
    or ``model.zip``) runs code when loaded; and the marker that code creates."""
    folder, marker = tmp_path / f"crafted_{which.replace('.', '_')}", tmp_path / "marker"
    folder.mkdir()
    hyperparams = {"policy": "MlpPolicy", "normalize": True, "n_timesteps": 1000}
    hyperparams["env_kwargs"] = dict(SHORT)
    config.save_hyperparams(folder / runs.CONFIG_FILE, ACL_CLIMB_ID, hyperparams)
    payload = base64.b64encode(pickle.dumps(Marker(marker))).decode()
    data = {"num_timesteps": 1000, "policy_class": {":type:": "x", ":serialized:": payload}}
    with zipfile.ZipFile(folder / runs.MODEL_FILE, "w") as archive:
        archive.writestr("data", json.dumps(data))
        archive.writestr("policy.pth", b"")
        archive.writestr("pytorch_variables.pth", b"")
    stats = pickle.dumps(Marker(marker)) if which == "vecnormalize.pkl" else b"not a pickle"
    (folder / runs.VECNORMALIZE_FILE).write_bytes(stats)
    return folder, marker


def test_the_crafted_files_do_run_code_when_unpickled(tmp_path: Path) -> None:
    """The fixtures are real: unpickled as SB3 would, each creates its marker."""
    from stable_baselines3.common.save_util import load_from_zip_file

    folder, marker = crafted_folder(tmp_path, "vecnormalize.pkl")
    pickle.loads((folder / runs.VECNORMALIZE_FILE).read_bytes())
    assert marker.exists()
    marker.unlink()
    (tmp_path / "zip").mkdir()
    folder, marker = crafted_folder(tmp_path / "zip", "model.zip")
    with pytest.raises(Exception):  # noqa: B017  (what follows the payload fails; it ran)
        load_from_zip_file(folder / runs.MODEL_FILE, device="cpu")
    assert marker.exists()


def tiny_new_run(run_root: Path, *extra: str) -> list[str]:
    return [
        *["--env", ACL_CLIMB_ID, "--seed", "3", "--n-timesteps", "128", "--n-envs", "2"],
        *["--vec-env", "dummy", "--run-dir", str(run_root), "--no-progress-bar"],
        *["--hyperparams", "n_steps:64", "batch_size:64", "n_epochs:1"],
        *["--env-kwargs", "steps_per_cycle:20", "cycles_per_episode:1", *extra],
    ]


COMMANDS = {
    "acl-evaluate --policy": lambda f, t: evaluate_cli.main(
        ["--policy", str(f), "--episodes", "1", "--workers", "1", "--no-progress-bar"]
    ),
    "acl-train --resume": lambda f, t: trainer.main(["--resume", str(f), "--no-progress-bar"]),
    "acl-train --init-from": lambda f, t: trainer.main(
        [*tiny_new_run(t / "runs"), "--init-from", str(f)]
    ),
    "export": lambda f, t: export.main([str(f), str(t / "out"), "--name", "x"]),
}


@pytest.mark.parametrize("which", ["vecnormalize.pkl", "model.zip"])
@pytest.mark.parametrize("command", list(COMMANDS))
def test_a_crafted_pickle_runs_nothing_without_the_flag(
    command: str, which: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Exit 2, one line naming --trust-pickles, no marker, nothing written."""
    folder, marker = crafted_folder(tmp_path, which)
    before = sorted(tmp_path.rglob("*"))
    with pytest.raises(SystemExit) as exit_info:
        COMMANDS[command](folder, tmp_path)
    err = capsys.readouterr().err.strip()
    assert exit_info.value.code == 2
    assert len(err.splitlines()) == 1 and "--trust-pickles" in err and "Traceback" not in err, err
    assert not marker.exists()
    assert sorted(tmp_path.rglob("*")) == before


def test_the_python_api_refuses_pickles_without_trust(tmp_path: Path) -> None:
    """load_policy, load_vecnormalize, read_vecnormalize, export_policy: a ValueError naming
    trust_pickles's flag, before anything is opened."""
    from stable_baselines3.common.vec_env import DummyVecEnv

    folder, marker = crafted_folder(tmp_path, "vecnormalize.pkl")
    env = gymnasium.make(ACL_CLIMB_ID, **SHORT)
    calls = [
        lambda: load_policy(folder, env),
        lambda: load_policy(read_sb3_folder(folder), env),
        lambda: runs.load_vecnormalize(folder / runs.VECNORMALIZE_FILE, DummyVecEnv([lambda: env])),
        lambda: runs.read_vecnormalize(folder / runs.VECNORMALIZE_FILE),
        lambda: export.export_policy(folder, tmp_path / "out", "x"),
    ]
    for call in calls:
        with pytest.raises(runs.UntrustedPickleError, match="trust"):
            call()
    env.close()
    assert not marker.exists() and not (tmp_path / "out").exists()


def test_evaluation_with_the_flag_loads_an_sb3_folder(tmp_path: Path) -> None:
    """--trust-pickles opts in: the same folder evaluates (one short episode)."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    folder = tmp_path / "policy"
    folder.mkdir()
    venv = VecNormalize(DummyVecEnv([lambda: gymnasium.make(ACL_CLIMB_ID, **SHORT)]))
    PPO("MlpPolicy", venv, n_steps=64, batch_size=64, seed=0, device="cpu").save(
        folder / runs.MODEL_FILE
    )
    venv.save(str(folder / runs.VECNORMALIZE_FILE))
    hyperparams = {"policy": "MlpPolicy", "normalize": True, "env_kwargs": dict(SHORT)}
    config.save_hyperparams(folder / runs.CONFIG_FILE, ACL_CLIMB_ID, hyperparams)
    argv = ["--policy", str(folder), "--episodes", "1", "--workers", "1", "--no-progress-bar"]
    document = evaluate_cli.main([*argv, "--trust-pickles", "--tuned-gaits", str(tmp_path / "n")])
    assert document["controllers"]["policy"]["episodes"] == 1


# --- pickle-free statistics ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def trained_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A tiny run (256 steps, a checkpoint at 128): what the trainer writes."""
    root = tmp_path_factory.mktemp("runs")
    argv = [*tiny_new_run(root), "--checkpoint-freq", "128", "--n-timesteps", "256"]
    args = make_parser().parse_args(argv)
    return trainer.run_segment(plan_segment(args, argv), verbose=0)


def test_training_writes_its_statistics_pickle_free_too(trained_run: Path) -> None:
    """vecnormalize.npz beside vecnormalize.pkl, for the final model and each checkpoint, with
    the same numbers and settings; read with allow_pickle=False."""
    model_npz = trained_run / "vecnormalize.npz"
    checkpoint = runs.checkpoint_paths(trained_run, 128)[1]
    for pkl in (trained_run / runs.VECNORMALIZE_FILE, checkpoint):
        npz = pkl.with_suffix(".npz")
        assert pkl.is_file() and npz.is_file()
        stats = pickle.loads(pkl.read_bytes())
        saved = runs.read_vecnormalize(npz)  # no trust needed
        for name in ("obs_rms", "ret_rms"):
            a, b = getattr(stats, name), getattr(saved, name)
            np.testing.assert_array_equal(a.mean, b.mean)
            np.testing.assert_array_equal(a.var, b.var)
            assert a.count == b.count
        for key in runs.STATISTICS_SETTINGS:
            assert getattr(stats, key) == getattr(saved, key), key
    assert runs.latest_model(trained_run)[1] == model_npz  # readers prefer the npz


def test_evaluation_reads_the_npz_and_acts_as_with_the_pickle(trained_run: Path) -> None:
    """The same actions from the npz statistics as from the pickle; with the pickle gone, the
    folder still loads (the model still needs the flag)."""
    from stable_baselines3.common.vec_env import DummyVecEnv

    folder = read_sb3_folder(trained_run)
    assert folder.vecnormalize == trained_run / "vecnormalize.npz"
    env = config.make_env(folder.env_id, folder.env_kwargs)
    obs, _ = env.reset(seed=0)
    venv = DummyVecEnv([lambda: env])
    from_npz = runs.load_vecnormalize(folder.vecnormalize, venv)
    from_pkl = runs.load_vecnormalize(
        trained_run / runs.VECNORMALIZE_FILE, DummyVecEnv([lambda: env]), trust_pickles=True
    )
    np.testing.assert_array_equal(from_npz.normalize_obs(obs), from_pkl.normalize_obs(obs))
    action = load_policy(folder, env, trust_pickles=True)(obs)
    copy = trained_run.parent / "npz_only"
    shutil.copytree(trained_run, copy)
    (copy / runs.VECNORMALIZE_FILE).unlink()
    np.testing.assert_array_equal(load_policy(copy, env, trust_pickles=True)(obs), action)
    env.close()


# --- the config allow-list -----------------------------------------------------------------------

FORBIDDEN = {
    "callback Popen": {"callback": [{"subprocess.Popen": {"args": "touch {m}", "shell": True}}]},
    "callback os.system": {"callback": "os.system"},
    "callback builtins": {"callback": "builtins.exec"},
    "policy Popen": {"policy": "subprocess.Popen"},
    "policy os.system": {"policy": "os.system"},
    "callback module of its own": {"callback": "evil_config_module.Callback"},
    "policy SB3 non-policy": {"policy": "stable_baselines3.common.vec_env.SubprocVecEnv"},
    "callback SB3 non-callback": {"callback": "stable_baselines3.common.vec_env.SubprocVecEnv"},
}


@pytest.mark.parametrize("case", list(FORBIDDEN))
def test_a_config_naming_another_class_is_refused_before_anything_runs(
    case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """acl-train exits 2 with one line naming the key; nothing runs, imports or is written."""
    marker = tmp_path / "marker"
    (tmp_path / "evil_config_module.py").write_text(f"open({str(marker)!r}, 'w')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    entry = {"base": "acl_env/ACLClimb-v1", "n_timesteps": 128}
    for key, value in FORBIDDEN[case].items():
        text = json.dumps(value).replace("{m}", str(marker))
        entry[key] = json.loads(text)
    recipe = tmp_path / "recipe.yml"
    recipe.write_text(yaml.safe_dump({ACL_CLIMB_ID: entry}))
    before = sorted(tmp_path.rglob("*"))
    with pytest.raises(SystemExit) as exit_info:
        trainer.main(["--config", str(recipe), "--run-dir", str(tmp_path / "runs")])
    err = capsys.readouterr().err.strip()
    key = next(iter(FORBIDDEN[case]))
    assert exit_info.value.code == 2 and len(err.splitlines()) == 1 and f"{key} must" in err, err
    assert not marker.exists() and "evil_config_module" not in sys.modules
    assert sorted(tmp_path.rglob("*")) == before


@pytest.mark.parametrize("name", ["subprocess.Popen", "os.system", "builtins.eval"])
def test_import_dotted_refuses_names_outside_the_allow_list(name: str) -> None:
    for key in ("callback", "policy"):
        with pytest.raises(ValueError, match="not allowed"):
            config.import_dotted(name, key)


def test_the_allow_list_takes_the_project_and_sb3_classes() -> None:
    from stable_baselines3.common.callbacks import StopTrainingOnMaxEpisodes
    from stable_baselines3.common.policies import ActorCriticPolicy

    from acl_env.training.callbacks import InfoTermsCallback
    from acl_env.training.checks import check_hyperparams
    from acl_env.training.networks import LayerNormCriticPolicy

    assert config.import_dotted("acl_env.training.callbacks.InfoTermsCallback") is InfoTermsCallback
    name = "stable_baselines3.common.callbacks.StopTrainingOnMaxEpisodes"
    assert config.import_dotted(name) is StopTrainingOnMaxEpisodes
    name = "stable_baselines3.common.policies.ActorCriticPolicy"
    assert config.import_dotted(name, "policy") is ActorCriticPolicy
    name = "acl_env.training.networks.LayerNormCriticPolicy"
    assert config.import_dotted(name, "policy") is LayerNormCriticPolicy
    for policy in ("MlpPolicy", name):
        callback = [{"acl_env.training.callbacks.CriticWarmupCallback": {"steps": 10}}]
        check_hyperparams({"n_timesteps": 1, "policy": policy, "callback": callback})


# --- outputs: checked first, written atomically, never through a symlink -------------------------


def test_atomic_writes_replace_a_symlink_instead_of_writing_through_it(tmp_path: Path) -> None:
    """A symlink at the output path is replaced by the file; its target, elsewhere, keeps its
    content (atomic_write, and atomic_output for figures and videos)."""
    folder, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    folder.mkdir()
    elsewhere.mkdir()
    for name, write in (
        ("x.json", lambda p: atomic_write(p, "new")),
        ("x.png", lambda p: _write_through(atomic_output(p))),
    ):
        target = elsewhere / name
        target.write_text("theirs")
        (folder / name).symlink_to(target)
        assert check_output(folder / name, (Path(name).suffix,)) == folder / name
        write(folder / name)
        assert target.read_text() == "theirs"
        assert not (folder / name).is_symlink() and (folder / name).read_text() == "new"
    assert sorted(p.name for p in folder.iterdir()) == ["x.json", "x.png"]  # no temp files


def _write_through(context: Any) -> None:
    with context as path:
        path.write_text("new")


def test_atomic_output_leaves_nothing_when_the_writer_fails(tmp_path: Path) -> None:
    with pytest.raises(RuntimeError), atomic_output(tmp_path / "x.png") as path:
        path.write_text("half")
        raise RuntimeError("the writer failed")
    assert list(tmp_path.iterdir()) == []


BAD_OUTPUTS = {
    "/proc/x.json": "not writable",
    "{tmp}/missing/x.json": "does not exist",
    "{tmp}": "folder",
    "{tmp}/x.txt": "ending in .json",
    "/dev/null": "ending in .json",
}


@pytest.mark.parametrize("path", list(BAD_OUTPUTS))
def test_check_output_refuses_what_cannot_be_written(path: str, tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=BAD_OUTPUTS[path]):
        check_output(path.format(tmp=tmp_path), (".json",))
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into a read-only folder")
def test_check_output_refuses_a_read_only_folder(tmp_path: Path) -> None:
    tmp_path.chmod(0o555)
    try:
        with pytest.raises(ValueError, match="not writable"):
            check_output(tmp_path / "x.json", (".json",))
    finally:
        tmp_path.chmod(0o755)


def test_check_output_formats_a_template_or_refuses_it(tmp_path: Path) -> None:
    path = check_output(str(tmp_path / "run_{seed}.json"), (".json",), {"seed": 3})
    assert path == tmp_path / "run_3.json"
    for template in ("x{0}.json", "x{missing}.json", "x{.json"):
        with pytest.raises(ValueError, match="does not format"):
            check_output(str(tmp_path / template), (".json",), {"seed": 3})


def test_compare_writes_through_no_symlink(tmp_path: Path) -> None:
    """acl-compare --json onto a symlink: the link is replaced, its target untouched."""
    from acl_env.evaluation import compare

    target = tmp_path / "elsewhere.json"
    target.write_text("theirs")
    (tmp_path / "out").mkdir()
    link = tmp_path / "out" / "diff.json"
    link.symlink_to(target)
    record = ROOT / "docs" / "eval_noroll.json"
    compare.main([str(record), str(record), "--labels", "A", "B", "--json", str(link)])
    assert target.read_text() == "theirs" and json.loads(link.read_text())["labels"] == ["A", "B"]
