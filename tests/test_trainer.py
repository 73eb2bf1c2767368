"""The trainer (acl_env.training.trainer, ``acl-train``): interrupt, resume, bad command lines.

Tiny in-process runs: 2 envs in the trainer process (``--vec-env dummy``), 64-step rollouts
(128 env steps per update), 20-step episodes. Signals are real (``os.kill`` on this process), sent
from inside a rollout or a gradient update, so where they land is exact. SIGINT is handled as in a
terminal's foreground job (:func:`sigint_handled`) however pytest was started.
"""

from __future__ import annotations

import contextlib
import copy
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import torch
import yaml
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.vec_env import VecNormalize

from acl_env import ACL_CLIMB_ID
from acl_env.io import write_json
from acl_env.training import trainer
from acl_env.training.arguments import make_parser
from acl_env.training.model_setup import make_training_env
from acl_env.training.plan import plan_segment, segment_seed

ASYMMETRIC = "acl_env.training.networks.AsymmetricCriticPolicy"
ROLLOUT = 128  # env steps per update: n_steps 64 x 2 envs
EPS = 1e-4  # RunningMeanStd's initial count


def tiny_argv(run_root: Path, n_timesteps: int, *extra: str) -> list[str]:
    """A tiny new run in this process."""
    return [
        *["--env", ACL_CLIMB_ID, "--seed", "3", "--n-timesteps", str(n_timesteps)],
        *["--n-envs", "2", "--vec-env", "dummy", "--run-dir", str(run_root)],
        *["--hyperparams", "n_steps:64", "batch_size:64", "n_epochs:2"],
        *["--env-kwargs", "steps_per_cycle:20", "cycles_per_episode:1"],
        *["--checkpoint-freq", "256", "--no-progress-bar", *extra],
    ]


@contextlib.contextmanager
def sigint_handled() -> Iterator[None]:
    """SIGINT handled as Python does in a terminal's foreground job (``KeyboardInterrupt``), also
    in the processes started meanwhile (exec resets a handled signal to its default). A pytest
    started in the background by a script inherits SIGINT ignored, and so would the trainer: it
    leaves an ignored SIGINT ignored (``nohup acl-train ... &``)."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def run(argv: list[str], *callbacks: BaseCallback) -> Path:
    """Plan and run one segment with extra callbacks (the signal senders below)."""
    args = make_parser().parse_args(argv)
    return trainer.run_segment(plan_segment(args, argv), callbacks, verbose=0)


def policy_params(model: PPO) -> dict[str, torch.Tensor]:
    return {k: v.detach().clone() for k, v in model.policy.state_dict().items()}


def assert_same_params(a: dict[str, torch.Tensor], b: dict[str, torch.Tensor]) -> None:
    assert a.keys() == b.keys()
    for key in a:
        assert torch.equal(a[key], b[key]), key


def load(run_dir: Path) -> tuple[PPO, VecNormalize, dict[str, Any]]:
    model = PPO.load(run_dir / "model.zip", device="cpu")
    with open(run_dir / "vecnormalize.pkl", "rb") as f:
        import pickle

        stats = pickle.load(f)
    return model, stats, json.loads((run_dir / "summary.json").read_text())


class SignalInRollout(BaseCallback):
    """Send ``signum`` to this process at ``step`` of rollout ``rollout`` (1-based); remember the
    weights and step count at that rollout's start (those of the last completed update)."""

    def __init__(self, rollout: int, step: int, signum: int = signal.SIGINT) -> None:
        super().__init__()
        self.rollout, self.step, self.signum = rollout, step, signum
        self.rollouts, self.steps = 0, 0
        self.at_start: tuple[int, dict[str, torch.Tensor]] | None = None
        self.first_original_obs: np.ndarray | None = None

    def _on_training_start(self) -> None:
        vec_normalize = self.model.get_vec_normalize_env()
        self.first_original_obs = vec_normalize.get_original_obs().copy()

    def _on_rollout_start(self) -> None:
        self.rollouts += 1
        self.steps = 0
        if self.rollouts == self.rollout:
            self.at_start = (self.model.num_timesteps, policy_params(self.model))

    def _on_step(self) -> bool:
        self.steps += 1
        if self.rollouts == self.rollout and self.steps == self.step:
            os.kill(os.getpid(), self.signum)
        return True


@pytest.fixture(scope="module")
def interrupted_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, SignalInRollout]:
    """A 512-step run stopped by SIGINT at step 10 of its third rollout (after 2 updates)."""
    sender = SignalInRollout(rollout=3, step=10)
    with sigint_handled():
        run_dir = run(tiny_argv(tmp_path_factory.mktemp("runs"), 512), sender)
    return run_dir, sender


def test_interrupt_in_a_rollout_saves_the_last_update(
    interrupted_run: tuple[Path, SignalInRollout],
) -> None:
    """Steps, weights and statistics of update 2; the untrained rollout steps discarded."""
    run_dir, sender = interrupted_run
    model, stats, summary = load(run_dir)
    assert sender.at_start is not None
    steps_at_start, params_at_start = sender.at_start
    assert steps_at_start == 2 * ROLLOUT
    assert model.num_timesteps == 2 * ROLLOUT
    assert_same_params(policy_params(model), params_at_start)
    # VecNormalize counts: one per env and step, plus the first reset's observations.
    assert stats.ret_rms.count == pytest.approx(EPS + 2 * ROLLOUT)
    assert stats.obs_rms.count == pytest.approx(EPS + 2 * ROLLOUT + 2)
    (segment,) = summary["segments"]
    assert segment["interrupted"] and segment["signal"] == "SIGINT"
    assert segment["steps"] == segment["end_steps"] == summary["total_steps"] == 2 * ROLLOUT
    assert segment["discarded_rollout_steps"] == 2 * 11  # step 11 saw the stop
    assert summary["interruptions"] == 1
    # Checkpoints, too, hold completed updates only: the one at 256 steps equals the final save.
    checkpoint = PPO.load(run_dir / "checkpoints" / "model_256_steps.zip", device="cpu")
    assert checkpoint.num_timesteps == 256
    assert_same_params(policy_params(checkpoint), params_at_start)
    assert not list(run_dir.rglob("*.tmp"))


def test_interrupt_in_an_update_finishes_it_and_a_second_signal_is_harmless(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """SIGINT then SIGTERM during update 2: the update completes, its weights are saved."""
    original_train = PPO.train
    calls: list[dict[str, torch.Tensor]] = []

    def train(self: PPO) -> None:
        if len(calls) == 1:
            os.kill(os.getpid(), signal.SIGINT)
            original_train(self)  # the first half of the update would have been cut here
            os.kill(os.getpid(), signal.SIGTERM)
        else:
            original_train(self)
        calls.append(policy_params(self))

    monkeypatch.setattr(PPO, "train", train)
    with sigint_handled():
        run_dir = run(tiny_argv(tmp_path, 10**6))
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored
    model, stats, summary = load(run_dir)
    assert len(calls) == 2
    assert model.num_timesteps == 2 * ROLLOUT
    assert_same_params(policy_params(model), calls[1])
    assert stats.ret_rms.count == pytest.approx(EPS + 2 * ROLLOUT)
    (segment,) = summary["segments"]
    assert segment["interrupted"] and segment["signal"] == "SIGINT"  # the first one received
    assert segment["discarded_rollout_steps"] == 2  # the one vector step that noticed the stop


def test_resume_continues_the_run_with_its_own_settings(
    interrupted_run: tuple[Path, SignalInRollout], tmp_path: Path
) -> None:
    """Config untouched, seed and checkpoint frequency kept, the rest of the steps trained, the
    statistics continue, the summary keeps both segments, the random stream is a new one."""
    run_dir = Path(shutil.copytree(interrupted_run[0], tmp_path / "run"))
    config_before = (run_dir / "config.yml").read_bytes()
    resumed = SignalInRollout(rollout=0, step=0)  # records the first observations only
    run(["--resume", str(run_dir), "--trust-pickles", "--no-progress-bar"], resumed)
    assert (run_dir / "config.yml").read_bytes() == config_before
    model, stats, summary = load(run_dir)
    assert model.num_timesteps == 512  # the config's n_timesteps, not 512 more
    assert stats.ret_rms.count == pytest.approx(EPS + 512)
    assert stats.obs_rms.count == pytest.approx(EPS + 512 + 2 + 2)  # a reset per segment
    first, second = summary["segments"]
    assert (first["start_steps"], first["end_steps"]) == (0, 256)
    assert (second["start_steps"], second["end_steps"], second["steps"]) == (256, 512, 256)
    assert not second["interrupted"] and summary["interruptions"] == 1
    assert summary["steps"] == 512 and summary["total_steps"] == 512
    assert summary["wall_time_s"] == pytest.approx(first["wall_time_s"] + second["wall_time_s"])
    assert first["seed"] == 3 and second["seed"] == segment_seed(3, 1) != 3
    record = json.loads((run_dir / "args.json").read_text())
    assert record["resumes"][0]["settings"]["seed"] == 3
    assert record["resumes"][0]["settings"]["checkpoint_freq"] == 256
    assert record["resumes"][0]["settings"]["vec_env"] == "dummy"
    # A fresh stream: the resumed segment does not replay the first segment's resets.
    first_obs = interrupted_run[1].first_original_obs
    assert first_obs is not None and resumed.first_original_obs is not None
    assert not np.allclose(first_obs, resumed.first_original_obs)


def test_resume_is_reproducible(
    interrupted_run: tuple[Path, SignalInRollout], tmp_path: Path
) -> None:
    """Two copies of a run resumed alike train to identical weights and statistics."""
    results = []
    for name in ("a", "b"):
        run_dir = Path(shutil.copytree(interrupted_run[0], tmp_path / name))
        run(
            [
                "--resume",
                str(run_dir),
                "--trust-pickles",
                "--n-timesteps",
                "128",
                "--no-progress-bar",
            ]
        )
        results.append(load(run_dir))
    (model_a, stats_a, _), (model_b, stats_b, _) = results
    assert model_a.num_timesteps == model_b.num_timesteps == 256 + 128
    assert_same_params(policy_params(model_a), policy_params(model_b))
    np.testing.assert_array_equal(stats_a.obs_rms.mean, stats_b.obs_rms.mean)


def test_segment_seeds_are_distinct_and_reproducible() -> None:
    seeds = [segment_seed(7, k) for k in range(50)]
    assert seeds[0] == 7 and len(set(seeds)) == 50
    assert seeds == [segment_seed(7, k) for k in range(50)]
    assert all(0 <= s < 2**31 for s in seeds)


def test_named_callback_from_the_config(tmp_path: Path) -> None:
    """``callback:`` in the config names classes by dotted path, as in the zoo."""
    argv = tiny_argv(tmp_path, 128)
    args = make_parser().parse_args(argv)
    plan = plan_segment(args, argv)
    assert "callback" in plan.hyperparams  # ppo.yml names InfoTermsCallback
    from acl_env.training.callbacks import InfoTermsCallback, callbacks_from_config

    (callback,) = callbacks_from_config(plan.hyperparams["callback"])
    assert isinstance(callback, InfoTermsCallback)


def test_policy_class_by_dotted_path(tmp_path: Path) -> None:
    """``policy:`` may name an ActorCriticPolicy subclass by dotted path: the run trains with it,
    its config records the path, and the saved model loads as that class."""
    from acl_env.training.networks import LayerNormCriticPolicy

    path = "acl_env.training.networks.LayerNormCriticPolicy"
    run_dir = run(tiny_argv(tmp_path, ROLLOUT, "--hyperparams", f"policy:{path}"))
    (entry,) = yaml.safe_load((run_dir / "config.yml").read_text()).values()
    assert entry["policy"] == path
    model, _, summary = load(run_dir)
    assert isinstance(model.policy, LayerNormCriticPolicy)
    assert summary["total_steps"] == ROLLOUT


def test_layer_norm_critic_normalises_only_the_critic() -> None:
    """Each hidden Linear of the critic is followed by a LayerNorm; the actor is MlpPolicy's."""
    from stable_baselines3.common.policies import ActorCriticPolicy

    from acl_env.training.networks import LayerNormCriticPolicy

    kwargs = {"n_steps": 64, "batch_size": 64, "seed": 0, "device": "cpu"}
    plain = PPO(ActorCriticPolicy, "Pendulum-v1", **kwargs).policy.mlp_extractor
    normed = PPO(LayerNormCriticPolicy, "Pendulum-v1", **kwargs).policy.mlp_extractor
    kinds = [type(m).__name__ for m in normed.value_net]
    assert kinds == ["Linear", "LayerNorm", "Tanh", "Linear", "LayerNorm", "Tanh"]
    assert [type(m) for m in normed.policy_net] == [type(m) for m in plain.policy_net]


def test_where_the_envs_step_changes_nothing_of_the_training(tmp_path: Path) -> None:
    """The same run with its envs in the trainer, on threads, or in worker processes learns the
    same weights, bit for bit: the vector env layout is a speed choice only."""
    weights = {}
    for layout in ("dummy", "threads", "subproc"):
        run_dir = run(tiny_argv(tmp_path / layout, 2 * ROLLOUT, "--vec-env", layout))
        weights[layout] = policy_params(load(run_dir)[0])
    assert_same_params(weights["dummy"], weights["threads"])
    assert_same_params(weights["dummy"], weights["subproc"])


def test_each_segment_records_the_code_that_trained_it(tmp_path: Path) -> None:
    """summary.json's segment names acl_env's version, a hash of its source and the libraries'
    versions; the export carries it; an edited source file changes the hash."""
    import acl_env as acl_env_module
    from acl_env import pretrained
    from acl_env.evaluation import export
    from acl_env.training import runs

    run_dir = run(tiny_argv(tmp_path, ROLLOUT))
    (segment,) = json.loads((run_dir / "summary.json").read_text())["segments"]
    assert segment["code"] == runs.code_version()
    assert set(segment["code"]) >= {"acl_env", "acl_env_sha256", "mujoco", "torch"}
    export.export_policy(run_dir, tmp_path / "exported", "coded", trust_pickles=True)
    training = pretrained.load_policy(tmp_path / "exported").metadata["training"]
    assert training["code"] == [segment["code"]]
    package = tmp_path / "package"
    (package / "envs").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "envs" / "step.py").write_text("SPRING = 20.0\n")
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(acl_env_module, "__file__", str(package / "__init__.py"))
        before = runs.code_version()["acl_env_sha256"]
        (package / "envs" / "step.py").write_text("SPRING = 20.5\n")
        assert runs.code_version()["acl_env_sha256"] != before


def test_asymmetric_critic_hides_the_privileged_block_from_the_actor(tmp_path: Path) -> None:
    """The actor's weights on the privileged entries stay exactly zero through training, saving,
    loading and export (its actions ignore them), while the critic reads them."""
    from acl_env import pretrained
    from acl_env.envs.observations import PRIVILEGED
    from acl_env.evaluation import export
    from acl_env.training.networks import AsymmetricCriticPolicy

    extra = ("--hyperparams", f"policy:{ASYMMETRIC}", "--env-kwargs", "privileged_obs:true")
    run_dir = run(tiny_argv(tmp_path, 2 * ROLLOUT, *extra))
    model, _, _ = load(run_dir)
    policy = model.policy
    assert isinstance(policy, AsymmetricCriticPolicy) and policy.critic_only == len(PRIVILEGED)
    first = policy.mlp_extractor.policy_net[0].weight.detach()
    hidden = len(PRIVILEGED)
    assert torch.count_nonzero(first[:, -hidden:]) == 0
    assert torch.count_nonzero(first[:, :-hidden]) == first[:, :-hidden].numel()
    critic = policy.mlp_extractor.value_net[0].weight.detach()
    assert torch.count_nonzero(critic[:, -hidden:]) == critic[:, -hidden:].numel()
    obs = torch.zeros((2, first.shape[1]))
    obs[1, -hidden:] = 3.0  # only the privileged entries differ
    with torch.no_grad():
        actions = policy.get_distribution(obs).distribution.mean
        values = policy.predict_values(obs)
    assert torch.equal(actions[0], actions[1]) and values[0] != values[1]
    export.export_policy(run_dir, tmp_path / "exported", "asym", trust_pickles=True)
    exported = pretrained.load_policy(tmp_path / "exported")
    raw = np.zeros(first.shape[1])
    changed = raw.copy()
    changed[-hidden:] = [0.1, 0.2, 1.5, 0.6, 0.7, 0.8, 0.4, 0.1, 12.0, 0.2]
    np.testing.assert_array_equal(exported(raw), exported(changed))


def test_asymmetric_critic_rezeroes_loaded_weights_and_names_a_bad_critic_only() -> None:
    from acl_env.training.networks import AsymmetricCriticPolicy

    kwargs = {"n_steps": 64, "batch_size": 64, "seed": 0, "device": "cpu"}
    model = PPO(AsymmetricCriticPolicy, "Pendulum-v1", policy_kwargs={"critic_only": 1}, **kwargs)
    state = model.policy.state_dict()
    state["mlp_extractor.policy_net.0.weight"][:] = 1.0
    model.policy.load_state_dict(state)
    weight = model.policy.mlp_extractor.policy_net[0].weight
    assert torch.all(weight[:, -1] == 0) and torch.all(weight[:, :-1] == 1)
    with pytest.raises(ValueError, match="critic_only=3 hides every one"):
        PPO(AsymmetricCriticPolicy, "Pendulum-v1", policy_kwargs={"critic_only": 3}, **kwargs)
    with pytest.raises(ValueError, match="critic_only"):
        PPO(AsymmetricCriticPolicy, "Pendulum-v1", policy_kwargs={"critic_only": 0}, **kwargs)


def test_critic_warmup_freezes_the_actor_then_lets_it_learn() -> None:
    """Updates up to ``steps`` change the critic only (actor weights and log_std bit-identical,
    KL 0); the first update after them changes the actor."""
    from acl_env.training.callbacks import CriticWarmupCallback

    model = PPO("MlpPolicy", "Pendulum-v1", n_steps=64, batch_size=32, n_epochs=2, seed=0)
    warmup = CriticWarmupCallback(steps=64)

    def split(params: dict[str, torch.Tensor]) -> tuple[dict, dict]:
        actor = {k: v for k, v in params.items() if "value" not in k}
        return actor, {k: v for k, v in params.items() if "value" in k}

    actor0, critic0 = split(policy_params(model))
    assert any(k.startswith("mlp_extractor.policy_net") for k in actor0) and "log_std" in actor0
    model.learn(64, callback=warmup)  # one update, at 64 steps: warming
    actor1, critic1 = split(policy_params(model))
    assert_same_params(actor0, actor1)
    assert any(not torch.equal(critic0[k], critic1[k]) for k in critic0)
    assert model.logger.name_to_value["train/approx_kl"] == 0.0  # the update's, not yet dumped
    model.learn(64, callback=CriticWarmupCallback(steps=64), reset_num_timesteps=False)
    actor2, _ = split(policy_params(model))
    assert model.logger.name_to_value["train/approx_kl"] > 0.0
    assert any(not torch.equal(actor1[k], actor2[k]) for k in actor1)
    with pytest.raises(ValueError, match="steps"):
        CriticWarmupCallback(steps=0)


# --- command lines refused before any work ------------------------------------------------------


def make_corrupt_run(source: Path, target: Path, how: str) -> Path:
    """A copy of a run folder with one file emptied or replaced by garbage."""
    run_dir = Path(shutil.copytree(source, target))
    file, content = {
        "empty config": ("config.yml", b""),
        "corrupt config": ("config.yml", b"{{{ not: yaml"),
        "list config": ("config.yml", b"- 1\n- 2\n"),
        "corrupt stats": ("vecnormalize.pkl", b"garbage"),
        "corrupt model": ("model.zip", b"PK garbage"),
        "corrupt summary": ("summary.json", b"{"),
    }[how]
    (run_dir / file).write_bytes(content)
    shutil.rmtree(run_dir / "checkpoints", ignore_errors=True)
    return run_dir


BAD_NEW_RUNS = [
    (["--n-timesteps", "0"], "--n-timesteps"),
    (["--checkpoint-freq", "0"], "--checkpoint-freq"),
    (["--n-envs", "0"], "--n-envs"),
    (["--seed", "-1"], "--seed"),
    (["--torch-threads", "0"], "--torch-threads"),
    (["--vec-env", "processes"], "--vec-env"),
    (["--device", "tpu"], "--device"),
    (["--exp-name", "a/b"], "--exp-name"),
    (["--env", "acl_env/NoSuchEnv-v0"], "--env"),
    (["--config", "no/such/ppo.yml"], "--config"),
    (["--gym-packages", "no_such_module_xyz"], "--gym-packages"),
    (["--hyperparams", "learning_rate:abc"], "learning_rate"),
    (["--hyperparams", "learning_rat:1e-4"], "learning_rat"),
    (["--hyperparams", "n_steps:0"], "n_steps"),
    (["--hyperparams", "batch_size:1"], "batch_size"),
    (["--hyperparams", "gamma:1.5"], "gamma"),
    (["--hyperparams", "target_kl:-1"], "target_kl"),
    (["--hyperparams", "n_epochs:2.5"], "n_epochs"),
    (["--hyperparams", "policy_kwargs:dict(no_such_arg=1)"], "policy_kwargs"),
    (["--hyperparams", "callback:no.such.Callback"], "callback"),
    (["--hyperparams", "policy:no.such.Policy"], "policy"),
    (["--hyperparams", "policy:acl_env.training.callbacks.InfoTermsCallback"], "policy"),
    (["--hyperparams", f"policy:{ASYMMETRIC}"], "privileged_obs"),  # hides the robot's own
    (["--hyperparams", f"policy:{ASYMMETRIC}", "policy_kwargs:dict(critic_only=0)"], "critic_only"),
    (["--hyperparams", "env_kwargs:{}"], "--env-kwargs"),
    (["--hyperparams", "nocolon"], "--hyperparams"),
    (["--hyperparams", "n_steps:64", "n_steps:32"], "twice"),
    (["--env-kwargs", "no_such_kwarg:1"], "no_such_kwarg"),
    (["--env-kwargs", "steps_per_cycle:abc"], "steps_per_cycle"),
    (["--env-kwargs", "steps_per_cycle:20.5"], "steps_per_cycle"),
    (["--env-kwargs", "domain_randomization:maybe"], "domain_randomization"),
    (["--env-kwargs", "pole_radius:-0.1"], "pole_radius"),
    (["--env-kwargs", "residual_scale:None", "n_joints:1"], "n_joints"),
]


@pytest.mark.parametrize(
    ("extra", "named"), BAD_NEW_RUNS, ids=[" ".join(c[0]) for c in BAD_NEW_RUNS]
)
def test_bad_new_run_is_refused_up_front(
    extra: list[str], named: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Exit status 2, one line naming the argument, and no run folder."""
    run_root = tmp_path / "runs"
    with pytest.raises(SystemExit) as exit_info:
        trainer.main(["--run-dir", str(run_root), "--no-progress-bar", *extra])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and named in err, err
    assert not run_root.exists()


RESUME_CASES = [
    ("empty config", [], "config.yml"),
    ("corrupt config", [], "config.yml"),
    ("list config", [], "config.yml"),
    ("corrupt stats", [], "vecnormalize.pkl"),
    ("corrupt model", [], "model.zip"),
    ("corrupt summary", [], "summary.json"),
    (None, ["--hyperparams", "n_steps:32"], "--hyperparams"),
    (None, ["--env-kwargs", "friction:0.5"], "--env-kwargs"),
    (None, ["--n-envs", "4"], "--n-envs"),
    (None, ["--env", ACL_CLIMB_ID], "--env"),
    (None, [], "--n-timesteps"),  # the run is complete: say how to train more
]


@pytest.mark.parametrize(("how", "extra", "named"), RESUME_CASES)
def test_bad_resume_is_refused_up_front(
    how: str | None,
    extra: list[str],
    named: str,
    complete_run: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Exit status 2, one line naming the argument or file; the run folder is left as it was."""
    if how is None:
        run_dir = Path(shutil.copytree(complete_run, tmp_path / "run"))
    else:
        run_dir = make_corrupt_run(complete_run, tmp_path / "run", how)
    before = {p: p.read_bytes() for p in run_dir.rglob("*") if p.is_file()}
    with pytest.raises(SystemExit) as exit_info:
        trainer.main(["--resume", str(run_dir), "--trust-pickles", "--no-progress-bar", *extra])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and named in err, err
    assert {p: p.read_bytes() for p in run_dir.rglob("*") if p.is_file()} == before


def test_missing_resume_folder_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exit_info:
        trainer.main(["--resume", str(tmp_path / "nope")])
    assert exit_info.value.code == 2 and "--resume" in capsys.readouterr().err


def test_lowercase_booleans_are_booleans(tmp_path: Path) -> None:
    """``domain_randomization:false`` is the bool False, not a string of letters."""
    argv = tiny_argv(tmp_path, 128, "--env-kwargs", "domain_randomization:false")
    plan = plan_segment(make_parser().parse_args(argv), argv)
    assert plan.hyperparams["env_kwargs"]["domain_randomization"] is False
    assert not (tmp_path / "runs").exists()


def test_env_kwargs_override_the_recipes_tuned_gait(tmp_path: Path) -> None:
    """The shipped recipe names its gait by key (``tuned_gait: acl``); ``--env-kwargs squeeze:X``
    still changes that gait's squeeze alone: the gait's numbers are written out, then replaced."""
    from acl_env import tuned_gaits

    shape = tuned_gaits.gait_shape("acl")
    argv = tiny_argv(tmp_path / "runs", 128, "--env-kwargs", "squeeze:0.001")
    plan = plan_segment(make_parser().parse_args(argv), argv)
    env_kwargs = plan.hyperparams["env_kwargs"]
    assert "tuned_gait" not in env_kwargs
    assert env_kwargs["squeeze"] == 0.001 and env_kwargs["gait_kwargs"] == shape["gait_kwargs"]
    argv = tiny_argv(tmp_path / "runs", 128)
    plan = plan_segment(make_parser().parse_args(argv), argv)
    assert plan.hyperparams["env_kwargs"]["tuned_gait"] == "acl"  # kept by key otherwise
    assert not (tmp_path / "runs").exists()


def test_a_recipe_delta_plans_as_its_resolved_entry(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--config`` may be an experiment's delta over the shipped recipe: the run gets the
    resolved entry; a delta on an unknown base is refused, naming ``--config`` and the base."""
    from acl_env import shipped
    from acl_env.training import config

    delta = tmp_path / "recipe.yml"
    delta.write_text(
        yaml.safe_dump({ACL_CLIMB_ID: {"base": ACL_CLIMB_ID, "env_kwargs": {"friction": 0.9}}})
    )
    argv = tiny_argv(tmp_path / "runs", 128, "--config", str(delta))
    plan = plan_segment(make_parser().parse_args(argv), argv)
    base = config.load_hyperparams(shipped.recipe_path(), ACL_CLIMB_ID)
    assert "base" not in plan.hyperparams
    assert plan.hyperparams["env_kwargs"] == {
        **base["env_kwargs"],
        "friction": 0.9,
        "steps_per_cycle": 20,
        "cycles_per_episode": 1,
    }
    assert plan.hyperparams["learning_rate"] == base["learning_rate"]
    delta.write_text(yaml.safe_dump({ACL_CLIMB_ID: {"base": "acl_env/NoSuch-v0"}}))
    with pytest.raises(SystemExit) as exit_info:
        trainer.main(tiny_argv(tmp_path / "runs", 128, "--config", str(delta)))
    err = capsys.readouterr().err.strip()
    assert exit_info.value.code == 2 and len(err.splitlines()) == 1
    assert "--config" in err and "acl_env/NoSuch-v0" in err, err
    assert not (tmp_path / "runs").exists()


@pytest.fixture(scope="module")
def complete_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A finished 128-step run."""
    return run(tiny_argv(tmp_path_factory.mktemp("complete"), 128))


# --- the real thing: a subprocess, signals from outside ----------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize(
    "signals", [(signal.SIGINT, signal.SIGINT), (signal.SIGTERM, signal.SIGINT)], ids=str
)
def test_signals_from_outside(tmp_path: Path, signals: tuple[int, int]) -> None:
    """``acl-train`` (``python -m acl_env.training.trainer``) with subprocess workers, two
    signals 50 ms apart once learning has started: exit 0, a loadable model at a whole number of
    updates with matching statistics."""
    run_root, log = tmp_path / "runs", tmp_path / "train.log"
    argv = tiny_argv(run_root, 10**7)
    argv[argv.index("dummy")] = "subproc"
    with open(log, "w") as out, sigint_handled():
        proc = subprocess.Popen(
            [sys.executable, "-m", "acl_env.training.trainer", *argv],
            cwd=tmp_path,
            stdout=out,
            stderr=out,
        )
    try:
        deadline = time.monotonic() + 300
        while not list(run_root.rglob("model_*_steps.zip")):  # two updates done
            assert proc.poll() is None and time.monotonic() < deadline, log.read_text()[-3000:]
            time.sleep(0.2)
        for signum in signals:
            proc.send_signal(signum)
            time.sleep(0.05)
        assert proc.wait(timeout=180) == 0, log.read_text()[-3000:]
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    (run_dir,) = run_root.iterdir()
    model, stats, summary = load(run_dir)
    assert model.num_timesteps % ROLLOUT == 0 and model.num_timesteps >= 256
    assert stats.ret_rms.count == pytest.approx(EPS + model.num_timesteps)
    assert summary["interrupted"] and summary["total_steps"] == model.num_timesteps
    assert yaml.safe_load((run_dir / "config.yml").read_text())[ACL_CLIMB_ID]["n_steps"] == 64
    assert not list(run_dir.rglob("*.tmp"))


def test_several_envs_per_worker_step_like_one_process() -> None:
    """5 envs in 2 worker processes give the same observations, rewards, dones and terminal
    observations as the same 5 envs stepped in this process, through auto-resets."""
    hyperparams = {"n_envs": 5, "env_kwargs": {"steps_per_cycle": 20, "cycles_per_episode": 1}}
    workers = make_training_env(ACL_CLIMB_ID, hyperparams, 11, "subproc", 2)
    local = make_training_env(ACL_CLIMB_ID, hyperparams, 11, "dummy")
    try:
        assert [len(s) for s in workers.slices] == [2, 3]
        np.testing.assert_array_equal(workers.reset(), local.reset())
        rng = np.random.default_rng(0)
        resets = 0
        for _ in range(25):  # through the 20-step episode ends
            actions = rng.uniform(-1, 1, (5, *workers.action_space.shape))
            (obs_a, rew_a, done_a, info_a), (obs_b, rew_b, done_b, info_b) = (
                workers.step(actions),
                local.step(actions),
            )
            np.testing.assert_array_equal(obs_a, obs_b)
            np.testing.assert_array_equal(rew_a, rew_b)
            np.testing.assert_array_equal(done_a, done_b)
            resets += int(done_a.sum())
            for a, b in zip(info_a, info_b, strict=True):
                assert a.keys() == b.keys()
                if "terminal_observation" in a:
                    np.testing.assert_array_equal(
                        a["terminal_observation"], b["terminal_observation"]
                    )
        assert resets == 5
        assert workers.get_attr("steps_per_cycle", indices=[1, 4]) == [20, 20]
        assert all(s > 0 for s in workers.get_attr("step_seconds"))
    finally:
        workers.close()
        local.close()


def test_write_json_writes_strict_json_atomically(tmp_path: Path) -> None:
    path = tmp_path / "figures.json"
    path.write_text("old")
    document = {"ratio": np.float32(1.5), "ci": np.array([0.1, 0.2]), "missing": float("nan")}
    write_json(path, document)
    # NaN is not JSON: strict parsers reject it, so it is written as null.
    parsed = json.loads(path.read_text(), parse_constant=lambda name: pytest.fail(name))
    assert parsed == {"ratio": 1.5, "ci": [0.1, 0.2], "missing": None}
    assert [p.name for p in tmp_path.iterdir()] == ["figures.json"]  # no temporary file left
    with pytest.raises(TypeError):  # not JSON at all: the old file stays whole
        write_json(path, {"bad": object()})
    assert json.loads(path.read_text())["ratio"] == 1.5


# --- warm start: a new run from a trained policy (acl_env/training/warm_start.py) ---------------


class AtTrainingStart(BaseCallback):
    """Remember the policy and normalisation a run starts learning from."""

    def _on_training_start(self) -> None:
        self.params = policy_params(self.model)
        normalize = self.model.get_vec_normalize_env()
        self.obs_rms = copy.deepcopy(normalize.obs_rms)
        self.first_obs = normalize.get_original_obs().copy()  # the resets' observations

    def _on_step(self) -> bool:
        return True


def test_init_from_starts_as_the_trained_policy_with_new_actions_at_zero(
    complete_run: Path, tmp_path: Path
) -> None:
    modulation = ["--env-kwargs", "gait_modulation:{'squeeze':0.003}", "modulation_sections:2"]
    start = AtTrainingStart()
    run_dir = run(
        tiny_argv(tmp_path, 128, "--trust-pickles", "--init-from", str(complete_run), *modulation),
        start,
    )
    trained, stats, _ = load(complete_run)
    source = policy_params(trained)
    # The default recipe has the cadence action: 20 joints, 2 squeeze sections, cadence.
    new, old = [*range(20), 22], [*range(20), 20]
    weight, bias = start.params["action_net.weight"], start.params["action_net.bias"]
    log_std = start.params["log_std"]
    assert weight.shape[0] == 23 and source["action_net.weight"].shape[0] == 21
    assert torch.equal(weight[new], source["action_net.weight"][old])
    assert torch.equal(bias[new], source["action_net.bias"][old])
    assert torch.equal(log_std[new], source["log_std"][old])
    # The squeeze actions start at mean 0 (the gait unchanged) and explore at log_std_init.
    assert not weight[20:22].any() and not bias[20:22].any()
    assert torch.equal(log_std[20:22], torch.full((2,), -1.0))
    for key in source:
        if key not in ("action_net.weight", "action_net.bias", "log_std"):
            assert torch.equal(start.params[key], source[key]), key
    # The statistics carried over; the first reset (2 envs) adds its observations to them.
    assert start.obs_rms.count == pytest.approx(stats.obs_rms.count + 2)
    assert np.allclose(start.obs_rms.mean, stats.obs_rms.mean, atol=0.5)
    record = json.loads((run_dir / "args.json").read_text())
    assert record["args"]["init_from"] == str(complete_run)


def test_init_from_carries_over_to_an_env_that_observes_more(
    complete_run: Path, tmp_path: Path
) -> None:
    """New observations (here the privileged block) start with zero input weights and unit
    statistics: the warm-started policy first acts as the trained one; the shared observations
    keep their columns and statistics."""
    from acl_env.envs.observations import PRIVILEGED

    start = AtTrainingStart()
    run(tiny_argv(tmp_path, 128, "--trust-pickles", "--init-from", str(complete_run),
                  "--env-kwargs", "privileged_obs:true"), start)  # fmt: skip
    trained, stats, _ = load(complete_run)
    source = policy_params(trained)
    n_old, n_new = stats.obs_rms.mean.size, len(PRIVILEGED)  # the new env appends the block
    for key in ("mlp_extractor.policy_net.0.weight", "mlp_extractor.value_net.0.weight"):
        weight = start.params[key]
        assert weight.shape[1] == n_old + n_new
        assert torch.equal(weight[:, :n_old], source[key]) and not weight[:, n_old:].any()
    assert torch.equal(start.params["action_net.weight"], source["action_net.weight"])
    # the statistics before the first reset's 2 observations: carried over, new at 0 and 1
    count = stats.obs_rms.count
    assert start.obs_rms.mean.size == n_old + n_new
    assert start.obs_rms.count == pytest.approx(count + 2)
    assert np.allclose(start.obs_rms.mean[:n_old], stats.obs_rms.mean, atol=0.5)
    com = slice(n_old, n_old + 6)
    assert np.allclose(start.obs_rms.mean[com], 0.0, atol=0.1)  # 2 of count + 2 samples
    assert np.allclose(start.obs_rms.var[com], 1.0, atol=0.1)
    # the physics entries (friction, radius, stiffness, latency, as each env drew them): the
    # mean moved from 0 by the two resets' values over count + 2
    expected = start.first_obs[:, -4:].sum(axis=0) / (count + 2)
    np.testing.assert_allclose(start.obs_rms.mean[-4:], expected, rtol=1e-9, atol=1e-12)
    assert (start.first_obs[:, -4:-1] > 0).all()


INIT_FROM_CASES = [
    (["--env-kwargs", "n_joints:10"], "does not observe"),  # fewer observations
    (["--hyperparams", "normalize:false"], "normalise"),
    (["--hyperparams", "policy_kwargs:dict(net_arch=[32])"], "policy_kwargs"),
]


@pytest.mark.parametrize(("extra", "named"), INIT_FROM_CASES, ids=[c[1] for c in INIT_FROM_CASES])
def test_bad_init_from_is_refused_naming_it(
    extra: list[str],
    named: str,
    complete_run: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Exit status 2, one line naming --init-from and what is wrong, nothing written."""
    run_root = tmp_path / "runs"
    with pytest.raises(SystemExit) as exit_info:
        trainer.main(
            tiny_argv(run_root, 128, "--trust-pickles", "--init-from", str(complete_run), *extra)
        )
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--init-from" in err and named in err, err
    assert not run_root.exists()


def test_init_from_cannot_resume(complete_run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        trainer.main(["--resume", str(complete_run), "--init-from", str(complete_run)])
    assert exit_info.value.code == 2 and "--init-from" in capsys.readouterr().err


def _fake_model(path: Path, steps: int) -> Path:
    """A zip with an SB3 ``data`` record trained ``steps`` env steps (all latest_model reads)."""
    import zipfile

    path.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("data", json.dumps({"num_timesteps": steps}))
    return path


def test_latest_model_ranks_by_steps_not_file_times(tmp_path: Path) -> None:
    """A copied run folder has new file times in any order: resume and policy loading must
    still take the model that trained furthest (here model.zip at 300 steps, though the
    100-step checkpoint is the newest file), and a checkpoint beyond model.zip when there is
    one (a run killed after its last checkpoint)."""
    from acl_env.training.runs import latest_model, model_steps

    checkpoints = tmp_path / "checkpoints"
    final = _fake_model(tmp_path / "model.zip", 300)
    for steps in (200, 100):  # written last: the newest files
        _fake_model(checkpoints / f"model_{steps}_steps.zip", steps)
        (checkpoints / f"model_vecnormalize_{steps}_steps.pkl").write_bytes(b"")
    os.utime(final, ns=(1, 1))  # the oldest file time of all
    assert model_steps(checkpoints / "model_200_steps.zip") == 200
    assert latest_model(tmp_path) == (final, None)

    _fake_model(checkpoints / "model_400_steps.zip", 400)
    (checkpoints / "model_vecnormalize_400_steps.pkl").write_bytes(b"")
    os.utime(checkpoints / "model_400_steps.zip", ns=(1, 1))
    assert latest_model(tmp_path) == (
        checkpoints / "model_400_steps.zip",
        checkpoints / "model_vecnormalize_400_steps.pkl",
    )


def test_latest_model_prefers_the_final_model_on_a_tie_and_names_a_bad_file(
    tmp_path: Path,
) -> None:
    from acl_env.training.runs import latest_model

    final = _fake_model(tmp_path / "model.zip", 256)
    _fake_model(tmp_path / "checkpoints" / "model_256_steps.zip", 256)
    assert latest_model(tmp_path)[0] == final
    final.write_bytes(b"not a zip")
    with pytest.raises(ValueError, match=r"model\.zip: not an SB3 model"):
        latest_model(tmp_path)


# An older version (or an old id) on purpose: Gymnasium's and acl_env's notes say so.
@pytest.mark.filterwarnings("ignore:.*is out of date:DeprecationWarning")
@pytest.mark.filterwarnings("ignore:.*is the task now registered as:DeprecationWarning")
def test_a_recipe_with_one_entry_trains_that_env_without_env(tmp_path: Path) -> None:
    """``acl-train --config experiments/.../recipe.yml`` without ``--env`` plans the recipe's only
    entry (here a non-rolling v2 delta), not the default env."""
    from acl_env import ACL_CLIMB_NOROLL_V2_ID

    delta = tmp_path / "recipe.yml"
    delta.write_text(
        yaml.safe_dump({ACL_CLIMB_NOROLL_V2_ID: {"base": "acl_env/ACLClimbNoRoll-v3"}})
    )
    argv = tiny_argv(tmp_path / "runs", 128, "--config", str(delta))
    argv = argv[2:]  # drop "--env ACL_CLIMB_ID"
    assert "--env" not in argv
    plan = plan_segment(make_parser().parse_args(argv), argv)
    assert plan.env_id == ACL_CLIMB_NOROLL_V2_ID


def test_init_from_a_pretrained_policy_is_refused_naming_the_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A shipped (numpy) policy has no optimiser state or torch weights to warm-start from: one
    line naming --init-from, exit 2, nothing written."""
    from acl_env import shipped

    folder = shipped.policy_dir()
    with pytest.raises(SystemExit) as exit_info:
        trainer.main(tiny_argv(tmp_path / "runs", 128, "--init-from", str(folder)))
    err = capsys.readouterr().err.strip()
    assert exit_info.value.code == 2 and len(err.splitlines()) == 1
    assert "--init-from" in err and "pretrained" in err, err
    assert not (tmp_path / "runs").exists()
