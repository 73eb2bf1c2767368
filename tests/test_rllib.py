"""PPO with RLlib on the native vector env (acl_env.training.rllib, the rllib extra).

The fast tests need no Ray: the env creator RLlib calls, the recipe's settings under RLlib's names,
and the one-line refusal without Ray. The slow one installs the extra into a virtual environment
of its own (Ray pins gymnasium 1.2.2) and trains two PPO updates with one Ray env runner."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

from acl_env import ACL_CLIMB_SEA_ID, shipped
from acl_env.envs.vector import ACLClimbVectorEnv
from acl_env.training.config import load_hyperparams
from acl_env.training.rllib import MISSING_RAY, main, make_worlds, recipe_settings


def test_the_runners_env_is_the_native_vector_env() -> None:
    vector = make_worlds(
        {"env_id": ACL_CLIMB_SEA_ID, "num_envs": 3, "threads": 1, "residual_scale": 0.05}
    )
    single = make_worlds({"env_id": ACL_CLIMB_SEA_ID, "residual_scale": 0.05})
    try:
        assert isinstance(vector, ACLClimbVectorEnv)
        assert vector.num_envs == 3 and vector.threads == 1
        # the keyword arguments reach every world
        assert vector.envs[0].config.gait.residual_scale == 0.05
        assert single.unwrapped.config.gait.residual_scale == 0.05
    finally:
        vector.close()
        single.close()


def test_the_settings_are_the_recipes() -> None:
    entry = load_hyperparams(shipped.recipe_path(), ACL_CLIMB_SEA_ID)
    settings = recipe_settings(ACL_CLIMB_SEA_ID)
    assert settings["rollout_fragment_length"] == entry["n_steps"]
    assert settings["minibatch_size"] == entry["batch_size"]
    assert settings["num_epochs"] == entry["n_epochs"]
    assert settings["gamma"] == entry["gamma"] and settings["lambda_"] == entry["gae_lambda"]
    assert settings["clip_param"] == entry["clip_range"]
    assert settings["hiddens"] == [128, 128] and settings["activation"] == "tanh"
    assert settings["env_kwargs"] == entry["env_kwargs"]
    # the zoo's lin_2e-4 (ACLClimbPaperGait-v1): 2e-4 decaying to 0 over the run's steps
    paper = recipe_settings("acl_env/ACLClimbPaperGait-v1")
    steps = load_hyperparams(shipped.recipe_path(), "acl_env/ACLClimbPaperGait-v1")["n_timesteps"]
    assert paper["lr"] == [[0.0, 2e-4], [float(steps), 0.0]]


@pytest.mark.skipif(importlib.util.find_spec("ray") is not None, reason="Ray is installed here")
def test_without_ray_one_line_names_the_extra(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as stop:
        main(["--iterations", "1"])
    assert stop.value.code == 2
    assert MISSING_RAY in capsys.readouterr().err


@pytest.fixture(scope="session")
def rllib_python(clean_source: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A Python with the rllib extra: ``ACL_RLLIB_PYTHON`` when set, else a virtual environment
    over this one's packages with ``pip install '<clean checkout>[rllib]'``."""
    given = os.environ.get("ACL_RLLIB_PYTHON")
    if given:
        return Path(given)
    venv = tmp_path_factory.mktemp("rllib_venv")
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", venv], check=True)
    python = venv / "bin" / "python"
    install = subprocess.run(
        [python, "-m", "pip", "install", "-q", f"{clean_source}[rllib]"],
        capture_output=True,
        text=True,
        timeout=1200,
    )
    if install.returncode != 0:
        pytest.skip(f"the rllib extra could not be installed: {install.stderr[-500:]}")
    return python


@pytest.mark.slow
def test_rllib_trains_ppo_on_the_vector_env(rllib_python: Path, tmp_path: Path) -> None:
    run = subprocess.run(
        [
            rllib_python,
            "-m",
            "acl_env.training.rllib",
            "--iterations",
            "2",
            "--runners",
            "1",
            "--envs-per-runner",
            "2",
            "--checkpoint",
            "algo",
        ],
        cwd=tmp_path,
        env={**os.environ, "RAY_DISABLE_USAGE_STATS": "1", "PYTHONPATH": ""},
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert run.returncode == 0, run.stderr[-3000:]
    # one runner x 2 worlds x the recipe's 256-step rollouts per update
    assert "iteration 1: 512 env steps" in run.stdout
    assert "iteration 2: 1024 env steps" in run.stdout
    assert (tmp_path / "algo").is_dir() and any((tmp_path / "algo").iterdir())
