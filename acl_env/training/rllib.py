"""PPO with RLlib (Ray) on the native vector env, for training beyond one machine.

``acl-train-rllib`` needs the ``rllib`` extra (``pip install "acl_env[rllib]"``). Ray 2.60 pins
gymnasium 1.2.2, older than the package's default, so give it an environment of its own
(docs/training.md, "RLlib: beyond one machine"). It is an alternative to ``acl-train``, not its
replacement: the shipped policies, their records and ``acl-evaluate`` are Stable-Baselines3's.

Each of Ray's env runners holds one :class:`~acl_env.envs.vector.ACLClimbVectorEnv` of
``--envs-per-runner`` worlds (RLlib's ``gym_env_vectorize_mode="vector_entry_point"``): its worlds'
physics runs on threads and its policy inference is batched over them. Runners spread over the
cores of a machine, or over the machines of a Ray cluster (``--address``).

The PPO settings follow the task's entry in the shipped recipe (``acl_env/data/ppo.yml``):
rollout length (``n_steps``), minibatch, epochs, learning rate, gamma, GAE lambda, clip range,
gradient norm, entropy coefficient, network sizes and activation, and the env's keyword
arguments. Observations are normalised by RLlib's ``MeanStdFilter``. Three parts of the SB3 recipe
have no counterpart here: the reward normalisation, ``target_kl``'s early stop of an update, and
the initial action std (``log_std_init``).
"""

from __future__ import annotations

import argparse
import importlib.util
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import gymnasium

from acl_env import ACL_CLIMB_SEA_ID, cli, shipped
from acl_env.io import console_script
from acl_env.training.config import load_hyperparams, parse_python_literal

MISSING_RAY = (
    "acl-train-rllib needs RLlib: pip install 'acl_env[rllib]', in an environment of its own "
    "(Ray 2.60 pins gymnasium 1.2.2)"
)

RLLIB_ENV = "acl_env_worlds"  # the name make_worlds is registered under with Ray


def make_worlds(config: Mapping[str, Any]) -> gymnasium.Env | gymnasium.vector.VectorEnv:
    """RLlib's env creator: ``config`` holds ``env_id``, the env's keyword arguments and, for a
    vector env, ``num_envs`` (and ``threads``). Imports ``acl_env`` in the runner's process, so
    that the ids are registered there."""
    import acl_env  # noqa: F401  (registers the ids in a Ray worker)

    kwargs = dict(config)
    env_id, num_envs = kwargs.pop("env_id"), kwargs.pop("num_envs", None)
    threads = kwargs.pop("threads", None)
    if num_envs is None:
        return gymnasium.make(env_id, **kwargs)
    if threads is not None:  # else the vector env's own default
        kwargs["threads"] = threads
    return gymnasium.make_vec(
        env_id, num_envs=int(num_envs), vectorization_mode="vector_entry_point", **kwargs
    )


def recipe_settings(env_id: str, recipe: str | Path | None = None) -> dict[str, Any]:
    """The PPO settings of ``env_id``'s recipe entry (default: the shipped recipe) that RLlib
    shares, under RLlib's names; and ``env_kwargs``."""
    entry = load_hyperparams(recipe or shipped.recipe_path(), env_id)
    policy = parse_python_literal(entry.get("policy_kwargs", "{}"))
    net = policy.get("net_arch", {})
    activation = getattr(policy.get("activation_fn"), "__name__", "Tanh").lower()
    return {
        "rollout_fragment_length": int(entry["n_steps"]),
        "minibatch_size": int(entry["batch_size"]),
        "num_epochs": int(entry["n_epochs"]),
        "lr": _rate(entry["learning_rate"], float(entry["n_timesteps"])),
        "gamma": float(entry["gamma"]),
        "lambda_": float(entry["gae_lambda"]),
        "clip_param": float(entry["clip_range"]),
        "grad_clip": float(entry["max_grad_norm"]),
        "entropy_coeff": float(entry["ent_coef"]),
        "hiddens": list(net.get("pi", [64, 64])),
        "activation": activation,
        "env_kwargs": dict(entry.get("env_kwargs") or {}),
    }


def _rate(value: float | str, total_steps: float) -> float | list[list[float]]:
    """A recipe's rate, or the zoo's ``lin_<x>`` (x decaying linearly to 0 over the run) as
    RLlib's schedule of ``[env step, value]`` points."""
    if isinstance(value, str) and value.startswith("lin_"):
        start = float(value.removeprefix("lin_"))
        return [[0.0, start], [total_steps, 0.0]]
    return float(value)


def ppo_config(
    env_id: str,
    runners: int,
    envs_per_runner: int,
    seed: int,
    threads: int | None = None,
    recipe: str | Path | None = None,
) -> Any:
    """RLlib's ``PPOConfig`` for ``env_id``: ``runners`` env runners (0: sample in the driver)
    of ``envs_per_runner`` worlds each, the recipe's settings (:func:`recipe_settings`)."""
    from ray.rllib.algorithms.ppo import PPOConfig
    from ray.rllib.connectors.env_to_module import MeanStdFilter
    from ray.rllib.core.rl_module.default_model_config import DefaultModelConfig
    from ray.tune.registry import register_env

    register_env(RLLIB_ENV, make_worlds)  # Ray shares its registry with the runners

    settings = recipe_settings(env_id, recipe)
    env_config = {"env_id": env_id, "threads": threads, **settings.pop("env_kwargs")}
    hiddens, activation = settings.pop("hiddens"), settings.pop("activation")
    fragment = settings.pop("rollout_fragment_length")
    batch = fragment * envs_per_runner * max(runners, 1)
    return (
        PPOConfig()
        .environment(env=RLLIB_ENV, env_config=env_config)
        .env_runners(
            num_env_runners=runners,
            num_envs_per_env_runner=envs_per_runner,
            gym_env_vectorize_mode="vector_entry_point",
            rollout_fragment_length=fragment,
            env_to_module_connector=lambda *_args, **_kwargs: MeanStdFilter(),
        )
        .training(train_batch_size_per_learner=batch, use_kl_loss=False, **settings)
        .rl_module(
            model_config=DefaultModelConfig(
                fcnet_hiddens=hiddens, fcnet_activation=activation, vf_share_layers=False
            )
        )
        .debugging(seed=seed)
    )


def make_parser() -> cli.ArgumentParser:
    """The command line of ``acl-train-rllib``."""
    parser = cli.ArgumentParser(
        prog="acl-train-rllib",
        description="Train PPO with RLlib on the native vector env (the rllib extra).",
    )
    parser.add_argument("--env", default=ACL_CLIMB_SEA_ID, help="task id (default %(default)s)")
    parser.add_argument(
        "--iterations", type=cli.int_at_least(1, cli.MAX_COUNT), default=100, help="PPO updates"
    )
    parser.add_argument(
        "--runners",
        type=cli.int_at_least(0, cli.MAX_PROCESSES),
        default=2,
        help="Ray env runners (0: sample in this process; default 2)",
    )
    parser.add_argument(
        "--envs-per-runner",
        type=cli.int_at_least(1, cli.MAX_PROCESSES),
        default=4,
        help="worlds in each runner's vector env (default 4)",
    )
    parser.add_argument(
        "--threads",
        type=cli.int_at_least(1, cli.MAX_PROCESSES),
        help="threads of each vector env (default: one per core, at most one per world)",
    )
    cli.add_seed(parser, 0, "seed of RLlib and of the envs' resets (default 0)")
    parser.add_argument(
        "--address",
        help="a running Ray cluster to join (ray start --head, then 'auto' or HOST:PORT); "
        "default: a local Ray on this machine",
    )
    parser.add_argument(
        "--checkpoint", type=cli.output_folder, help="save the algorithm here at the end"
    )
    return parser


def train(args: argparse.Namespace) -> list[dict[str, float]]:
    """Run ``args.iterations`` PPO updates; each one's env steps and mean episode return."""
    import ray

    ray.init(address=args.address, include_dashboard=False, log_to_driver=False)
    try:
        algo = ppo_config(
            args.env, args.runners, args.envs_per_runner, args.seed, args.threads
        ).build_algo()
        history = []
        for i in range(args.iterations):
            result = algo.train()
            runners = result.get("env_runners", {})
            row = {
                "iteration": i + 1,
                "env_steps": float(result.get("num_env_steps_sampled_lifetime", 0)),
                "episode_return_mean": float(runners.get("episode_return_mean", float("nan"))),
            }
            history.append(row)
            print(
                f"iteration {row['iteration']}: {row['env_steps']:.0f} env steps, mean episode "
                f"return {row['episode_return_mean']:.3f}",
                flush=True,
            )
        if args.checkpoint is not None:
            algo.save_to_path(str(Path(args.checkpoint).resolve()))
        algo.stop()
        return history
    finally:
        ray.shutdown()


def main(argv: Sequence[str] | None = None) -> list[dict[str, float]]:
    """Parse, check that RLlib is installed, train."""
    parser = make_parser()
    args = parser.parse_args(argv)
    if importlib.util.find_spec("ray") is None:
        parser.error(MISSING_RAY)
    return train(args)


run = console_script(main)


if __name__ == "__main__":
    run()
