"""Train a residual PPO policy on an acl_env environment with Stable-Baselines3.

The base gait runs inside the env; PPO learns the residual. Hyperparameters come from a
rl-baselines3-zoo YAML entry keyed by env id (``train/configs/ppo.yml``). Every run writes a folder
``runs/<env>__<exp>__<seed>__<time>/`` with ``model.zip``, ``vecnormalize.pkl``, ``config.yml``
(the exact merged config, itself a zoo config), ``args.json``, ``summary.json`` (wall time, steps,
env steps/s), ``checkpoints/`` and TensorBoard logs (``tb/``).

    python train/train_ppo.py --env acl_env/ACLClimb-v0 --seed 0
    python train/train_ppo.py --resume runs/<run> --n-timesteps 200000
    tensorboard --logdir runs

Ctrl-C (or SIGTERM) stops training and saves the model and the VecNormalize statistics first.
"""

from __future__ import annotations

import argparse
import functools
import json
import signal
import sys
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback, CallbackList, CheckpointCallback
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.utils import set_random_seed
from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecEnv, VecNormalize

from acl_env import ACL_CLIMB_ID
from acl_env.training.config import (
    algo_kwargs,
    import_gym_packages,
    load_hyperparams,
    make_worker_env,
    normalize_kwargs,
    parse_kv_pairs,
    save_hyperparams,
)
from acl_env.training.runs import (
    ARGS_FILE,
    CHECKPOINT_DIR,
    CHECKPOINT_PREFIX,
    CONFIG_FILE,
    MODEL_FILE,
    SUMMARY_FILE,
    VECNORMALIZE_FILE,
    latest_model,
    run_config,
)

DEFAULT_CONFIG = Path(__file__).with_name("configs") / "ppo.yml"


class InfoTermsCallback(BaseCallback):
    """Log per-step means of the env's ``info`` terms once per rollout, and episode climb.

    ``reward/<term>`` for every ``info["reward_<term>"]``; ``charts/climb``, ``charts/slip`` and
    ``charts/energy`` per step; ``charts/episode_climb`` and ``charts/falls`` per finished episode.
    """

    def __init__(self) -> None:
        super().__init__()
        self._sums: dict[str, float] = defaultdict(float)
        self._count = 0
        self._episode_climb: np.ndarray | None = None
        self._finished_climbs: list[float] = []
        self._falls = 0

    def _on_training_start(self) -> None:
        self._episode_climb = np.zeros(self.training_env.num_envs)

    def _on_step(self) -> bool:
        assert self._episode_climb is not None
        infos, dones = self.locals["infos"], self.locals["dones"]
        for i, (info, done) in enumerate(zip(infos, dones, strict=True)):
            for key, value in info.items():
                if key.startswith("reward_"):
                    self._sums[f"reward/{key.removeprefix('reward_')}"] += float(value)
                elif key in ("climb", "slip", "energy"):
                    self._sums[f"charts/{key}"] += float(value)
            self._episode_climb[i] += float(info.get("climb", 0.0))
            if done:
                self._finished_climbs.append(float(self._episode_climb[i]))
                self._falls += int(bool(info.get("fell", False)))
                self._episode_climb[i] = 0.0
        self._count += len(infos)
        return True

    def _on_rollout_end(self) -> None:
        for key, total in self._sums.items():
            self.logger.record(key, total / max(self._count, 1))
        if self._finished_climbs:
            self.logger.record("charts/episode_climb", float(np.mean(self._finished_climbs)))
            self.logger.record("charts/falls", self._falls)
        self._sums.clear()
        self._count = 0
        self._finished_climbs.clear()
        self._falls = 0


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    """Command line; ``--hyperparams`` and ``--env-kwargs`` take zoo-style ``key:value``."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--env", default=ACL_CLIMB_ID, help="registered env id")
    parser.add_argument("--config", default=str(DEFAULT_CONFIG), help="zoo-format YAML")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--n-timesteps", type=int, help="env steps (override; on resume: more)")
    parser.add_argument("--n-envs", type=int, help="parallel envs (override)")
    parser.add_argument("--run-dir", default="runs", help="parent folder of run folders")
    parser.add_argument("--exp-name", default="ppo", help="experiment name in the run folder")
    parser.add_argument("--resume", metavar="RUN_DIR", help="continue the latest model there")
    parser.add_argument("--hyperparams", nargs="*", default=[], metavar="KEY:VALUE")
    parser.add_argument("--env-kwargs", nargs="*", default=[], metavar="KEY:VALUE")
    parser.add_argument("--checkpoint-freq", type=int, default=100_000, help="env steps")
    parser.add_argument("--gym-packages", nargs="*", default=[], help="modules registering envs")
    parser.add_argument("--device", default="cpu", help="torch device (MLP policies: cpu)")
    parser.add_argument(
        "--torch-threads",
        type=int,
        default=1,
        help="torch CPU threads; 1 because the env workers own the cores (2 threads were 10x "
        "slower on a loaded 2-core machine)",
    )
    parser.add_argument("--no-progress-bar", action="store_true")
    return parser.parse_args(argv)


def merged_config(args: argparse.Namespace) -> tuple[str, dict[str, Any]]:
    """The env id and the hyperparameters after the command-line overrides."""
    if args.resume:
        if args.hyperparams:
            raise SystemExit("--hyperparams cannot change a resumed model; start a new run")
        saved = run_config(args.resume)
        if saved is None:
            raise FileNotFoundError(f"{args.resume} has no {CONFIG_FILE}")
        env_id, hyperparams = saved
    else:
        env_id, hyperparams = args.env, load_hyperparams(args.config, args.env)
    hyperparams.update(parse_kv_pairs(args.hyperparams))
    if args.env_kwargs:
        hyperparams["env_kwargs"] = {
            **(hyperparams.get("env_kwargs") or {}),
            **parse_kv_pairs(args.env_kwargs),
        }
    if args.n_envs is not None:
        hyperparams["n_envs"] = args.n_envs
    if args.n_timesteps is not None:
        hyperparams["n_timesteps"] = args.n_timesteps
    return env_id, hyperparams


def make_training_env(env_id: str, hyperparams: dict[str, Any], seed: int) -> VecEnv:
    """Monitored envs in subprocesses (one process per env; in-process when there is one)."""
    n_envs = int(hyperparams.get("n_envs", 1))
    return make_vec_env(
        functools.partial(make_worker_env, env_id) if n_envs > 1 else env_id,
        n_envs=n_envs,
        seed=seed,
        env_kwargs=hyperparams.get("env_kwargs") or {},
        vec_env_cls=SubprocVecEnv if n_envs > 1 else DummyVecEnv,
    )


def _interrupt(signum: int, frame: object) -> None:
    """SIGTERM handler: stop like Ctrl-C, so that the model is saved."""
    raise KeyboardInterrupt


def new_run_dir(args: argparse.Namespace, env_id: str) -> Path:
    """``<run-dir>/<env>__<exp>__<seed>__<time>``, the env id's namespace slash made ``_``."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    name = f"{env_id.replace('/', '_')}__{args.exp_name}__{args.seed}__{stamp}"
    run_dir = Path(args.run_dir) / name
    run_dir.mkdir(parents=True, exist_ok=False)
    return run_dir


def record_args(run_dir: Path, args: argparse.Namespace) -> None:
    """Write ``args.json``; a resume appends its arguments under ``"resumes"``."""
    entry = {"argv": sys.argv, "args": vars(args), "time": time.strftime("%Y-%m-%d %H:%M:%S")}
    path = run_dir / ARGS_FILE
    if args.resume and path.is_file():
        record = json.loads(path.read_text())
        record.setdefault("resumes", []).append(entry)
    else:
        record = entry
    path.write_text(json.dumps(record, indent=2) + "\n")


def save(model: PPO, run_dir: Path) -> None:
    """Save the model and, when present, its VecNormalize statistics."""
    model.save(run_dir / MODEL_FILE)
    vec_normalize = model.get_vec_normalize_env()
    if vec_normalize is not None:
        vec_normalize.save(str(run_dir / VECNORMALIZE_FILE))


def train(args: argparse.Namespace) -> Path:
    """Build or resume the run, learn, save; return the run folder."""
    import_gym_packages(args.gym_packages)
    env_id, hyperparams = merged_config(args)
    torch.set_num_threads(args.torch_threads)
    n_timesteps = int(hyperparams["n_timesteps"])
    set_random_seed(args.seed)
    env = make_training_env(env_id, hyperparams, args.seed)
    norm_kwargs = normalize_kwargs(hyperparams)

    if args.resume:
        run_dir = Path(args.resume)
        model_path, vecnorm_path = latest_model(run_dir)
        if vecnorm_path is not None:
            env = VecNormalize.load(str(vecnorm_path), env)  # saved with training=True
        model = PPO.load(model_path, env=env, device=args.device)
        model.set_random_seed(args.seed)
        model.tensorboard_log = str(run_dir / "tb")
        print(f"resuming {model_path} at {model.num_timesteps} steps")
    else:
        run_dir = new_run_dir(args, env_id)
        if norm_kwargs is not None:
            env = VecNormalize(env, **norm_kwargs)
        model = PPO(
            env=env,
            seed=args.seed,
            device=args.device,
            tensorboard_log=str(run_dir / "tb"),
            verbose=1,
            **algo_kwargs(hyperparams),
        )
    save_hyperparams(run_dir / CONFIG_FILE, env_id, hyperparams)
    record_args(run_dir, args)
    print(f"run folder: {run_dir}")

    checkpoint = CheckpointCallback(
        save_freq=max(args.checkpoint_freq // env.num_envs, 1),
        save_path=str(run_dir / CHECKPOINT_DIR),
        name_prefix=CHECKPOINT_PREFIX,
        save_vecnormalize=True,
    )
    signal.signal(signal.SIGTERM, _interrupt)
    start_steps = model.num_timesteps
    start = time.perf_counter()
    interrupted = False
    try:
        model.learn(
            total_timesteps=n_timesteps,
            callback=CallbackList([checkpoint, InfoTermsCallback()]),
            tb_log_name="PPO",
            reset_num_timesteps=not args.resume,
            progress_bar=not args.no_progress_bar,
        )
    except KeyboardInterrupt:
        interrupted = True
        print("\ninterrupted: saving the model and the VecNormalize statistics")
    wall = time.perf_counter() - start
    save(model, run_dir)
    if interrupted and isinstance(env.unwrapped, SubprocVecEnv):
        # Ctrl-C may have cut step_wait between two workers' replies: reading the pending ones
        # again in close() would block forever, so close without waiting for them.
        env.unwrapped.waiting = False
    env.close()

    steps = model.num_timesteps - start_steps
    summary = {
        "env_id": env_id,
        "steps": steps,
        "total_steps": model.num_timesteps,
        "wall_time_s": wall,
        "env_steps_per_s": steps / wall if wall > 0 else 0.0,
        "n_envs": env.num_envs,
        "torch_threads": torch.get_num_threads(),
        "interrupted": interrupted,
    }
    (run_dir / SUMMARY_FILE).write_text(json.dumps(summary, indent=2) + "\n")
    print(f"{steps} env steps in {wall:.1f} s: {summary['env_steps_per_s']:.0f} env steps/s")
    print(f"saved {run_dir / MODEL_FILE}")
    return run_dir


def main(argv: list[str] | None = None) -> None:
    """Entry point."""
    train(parse_args(argv))


if __name__ == "__main__":
    main()
