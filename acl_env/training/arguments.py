"""The command line of ``acl-train`` (:func:`make_parser`) and its defaults: the shipped recipe,
the run settings outside the zoo config, and the options that define a run's recipe."""

from __future__ import annotations

from typing import Any

from acl_env import ACL_CLIMB_SEA_ID, cli, shipped

DESCRIPTION = "Train a residual PPO policy on an acl_env environment with Stable-Baselines3."

# The shipped recipe (package data), so an installed wheel trains without --config.
DEFAULT_CONFIG = shipped.recipe_path()

# Run settings outside the zoo config: kept by --resume unless given again.
DEFAULT_SETTINGS: dict[str, Any] = {
    "seed": 0,
    "checkpoint_freq": 100_000,
    "torch_threads": 1,
    "device": "cpu",
    "vec_env": "subproc",
    "workers": None,  # one per CPU core
}
# Options that define the run's recipe; a resume refuses them (start a new run instead).
RECIPE_OPTIONS = ("env", "config", "hyperparams", "env_kwargs", "n_envs", "run_dir", "exp_name")


def make_parser() -> cli.ArgumentParser:
    """The command line; ``--hyperparams`` and ``--env-kwargs`` take zoo-style ``key:value``."""
    parser = cli.ArgumentParser(prog="acl-train", description=DESCRIPTION)
    parser.add_argument(
        "--env",
        help=f"registered env id (default: a --config's only entry, else the benchmark task, "
        f"{ACL_CLIMB_SEA_ID})",
    )
    parser.add_argument(
        "--config",
        help="zoo-format YAML, possibly a delta over the shipped recipe (default: the shipped "
        "recipe, acl_env/data/ppo.yml)",
    )
    cli.add_seed(parser, None, f"run seed (default {DEFAULT_SETTINGS['seed']})")
    parser.add_argument(
        "--n-timesteps",
        type=cli.int_at_least(1, cli.MAX_COUNT),
        help="env steps (overrides the config; on --resume: this many more, default: the rest)",
    )
    parser.add_argument(
        "--n-envs", type=cli.int_at_least(1, cli.MAX_PROCESSES), help="parallel envs (override)"
    )
    parser.add_argument(
        "--run-dir",
        type=cli.output_folder,
        help="parent folder of run folders, made if missing (default runs)",
    )
    parser.add_argument("--exp-name", help="experiment name in the run folder (default ppo)")
    parser.add_argument(
        "--resume", metavar="RUN_DIR", help="continue this run (with --trust-pickles)"
    )
    parser.add_argument(
        "--init-from",
        metavar="POLICY_DIR",
        help="new run whose policy starts as this trained one (policy or run folder): its "
        "weights and normalisation, its actions matched by name, new actions at mean 0 (with "
        "--trust-pickles)",
    )
    cli.add_trust_pickles(parser)
    for option, what in (("--hyperparams", "PPO / zoo"), ("--env-kwargs", "env")):
        cli.add_key_values(parser, option, f"{what} overrides (may repeat; numbers finite)", True)
    parser.add_argument(
        "--checkpoint-freq",
        type=cli.int_at_least(1, cli.MAX_COUNT),
        help=f"env steps between checkpoints (default {DEFAULT_SETTINGS['checkpoint_freq']})",
    )
    cli.add_gym_packages(parser)
    parser.add_argument("--device", help="torch device (default cpu: MLP policies)")
    parser.add_argument(
        "--torch-threads",
        type=cli.int_at_least(1, cli.MAX_PROCESSES),
        help="torch CPU threads (default 1: the env workers own the cores; 2 threads were 10x "
        "slower on a loaded 2-core machine)",
    )
    parser.add_argument(
        "--vec-env",
        choices=("subproc", "dummy", "threads"),
        help="env workers: subprocesses (--workers of them), all in the trainer, or in the "
        "trainer on --workers threads (default subproc)",
    )
    cli.add_workers(
        parser, None, "subprocesses sharing the envs (default: one per CPU core, at most n_envs)"
    )
    parser.add_argument("--no-progress-bar", action="store_true")
    return parser
