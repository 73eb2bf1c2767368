"""The plan of a training segment (``acl-train``): its command line, and every argument and file
checked before any work, for a new run, a resume (``--resume``) or a warm start (``--init-from``).

:func:`plan_segment` turns the parsed command line into a :class:`Plan` or raises
:class:`~acl_env.training.checks.ConfigError` naming the first bad argument; nothing is written.
A resume or a warm start loads the run's ``model.zip`` (and ``vecnormalize.pkl`` when it has no
pickle-free ``vecnormalize.npz``), which SB3 unpickles: only with ``--trust-pickles``.
"""

from __future__ import annotations

import argparse
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from acl_env import ACL_CLIMB_SEA_ID, cli, pretrained, shipped
from acl_env.envs.observations import env_observation_names
from acl_env.io import check_writable_folder
from acl_env.training import warm_start
from acl_env.training.checks import ConfigError, check_env_kwargs, check_hyperparams
from acl_env.training.config import (
    RecipeError,
    algo_kwargs,
    load_hyperparams,
    merge_env_kwargs,
    normalize_kwargs,
)
from acl_env.training.policy import read_sb3_folder
from acl_env.training.runs import (
    ARGS_FILE,
    CONFIG_FILE,
    SUMMARY_FILE,
    VECNORMALIZE_FILE,
    UntrustedPickleError,
    is_pickle,
    latest_model,
    model_steps,
    read_json,
    read_vecnormalize,
    require_trust,
    run_config,
)

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


def segment_seed(seed: int, segment: int) -> int:
    """The seed of a run's ``segment``: the run seed for the first, then a fresh but
    reproducible one per resume (never replaying the first segment's resets and draws)."""
    if segment == 0:
        return seed
    state = np.random.SeedSequence([seed, segment]).generate_state(1, dtype=np.uint32)[0]
    return int(state >> 1)  # < 2**31, so seed + env index stays a valid seed


# --- command line --------------------------------------------------------------------------------


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
    parser.add_argument(
        "--seed",
        type=cli.int_at_least(0, cli.MAX_SEED),
        help=f"run seed (default {DEFAULT_SETTINGS['seed']})",
    )
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
        parser.add_argument(
            option,
            nargs="*",
            action="extend",
            type=cli.key_value,
            metavar="KEY:VALUE",
            help=f"{what} overrides (may repeat; numbers finite)",
        )
    parser.add_argument(
        "--checkpoint-freq",
        type=cli.int_at_least(1, cli.MAX_COUNT),
        help=f"env steps between checkpoints (default {DEFAULT_SETTINGS['checkpoint_freq']})",
    )
    parser.add_argument(
        "--gym-packages",
        nargs="*",
        default=[],
        type=cli.importable_module,
        help="modules registering envs",
    )
    parser.add_argument("--device", help="torch device (default cpu: MLP policies)")
    parser.add_argument(
        "--torch-threads",
        type=cli.int_at_least(1, cli.MAX_PROCESSES),
        help="torch CPU threads (default 1: the env workers own the cores; 2 threads were 10x "
        "slower on a loaded 2-core machine)",
    )
    parser.add_argument(
        "--vec-env",
        choices=("subproc", "dummy"),
        help="env workers: one subprocess per env, or all in the trainer (default subproc)",
    )
    parser.add_argument(
        "--workers",
        type=cli.int_at_least(1, cli.MAX_PROCESSES),
        help="subprocesses sharing the envs (default: one per CPU core, at most n_envs)",
    )
    parser.add_argument("--no-progress-bar", action="store_true")
    return parser


# --- plan: everything checked before any work ----------------------------------------------------


@dataclass
class Plan:
    """A checked training segment: what to build, where to write, nothing done yet."""

    env_id: str
    hyperparams: dict[str, Any]
    settings: dict[str, Any]
    segment: int
    segment_steps: int
    run_dir: Path | None  # None for a new run: named when created
    run_parent: Path
    exp_name: str
    progress_bar: bool
    argv: list[str]
    args: dict[str, Any]
    resume_model: Path | None = None
    resume_vecnormalize: Path | None = None
    init_from: warm_start.TrainedStart | None = None  # --init-from, checked and loaded
    history: dict[str, Any] = field(default_factory=dict)

    @property
    def seed(self) -> int:
        """This segment's seed."""
        return segment_seed(int(self.settings["seed"]), self.segment)


def _bad(option: str, message: str) -> ConfigError:
    return ConfigError(f"argument {option}: {message}")


def _resumed_config(run_dir: Path) -> tuple[str, dict[str, Any]]:
    """``(env_id, hyperparams)`` of the run to resume (:func:`runs.run_config`), or refused."""
    try:
        config = run_config(run_dir)
    except ValueError as error:
        raise _bad("--resume", str(error)) from None
    if config is None:
        raise _bad("--resume", f"{run_dir / CONFIG_FILE} is missing")
    return config


def _trusted(option: str, path: Path, trust_pickles: bool) -> None:
    """Refuse ``option``'s SB3 folder unless ``--trust-pickles`` (before any file is read)."""
    try:
        require_trust(path, trust_pickles)
    except UntrustedPickleError as error:
        raise _bad(option, str(error)) from None


def _check_saved_model(
    model_path: Path, stats_path: Path | None, normalize: bool, option: str = "--resume"
) -> Any:
    """The saved model is an SB3 zip; its statistics (the pickle-free ``.npz`` when there is one,
    else the ``.pkl``, trusted by then) read as VecNormalize statistics when expected (returned:
    :func:`~acl_env.training.runs.read_vecnormalize`; None when not). A bad file is reported as
    a bad ``option``."""
    if not zipfile.is_zipfile(model_path) or not {"data", "policy.pth"} <= set(
        zipfile.ZipFile(model_path).namelist()
    ):
        raise _bad(option, f"{model_path} is not a Stable-Baselines3 model (corrupt zip)")
    if not normalize:
        return None
    if stats_path is None:
        raise _bad(option, f"the config normalises but {model_path.parent} has no statistics")
    try:
        return read_vecnormalize(stats_path, trust_pickles=True)
    except ValueError as error:
        raise _bad(option, str(error)) from None


def _run_history(run_dir: Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """``(args.json, summary.json)`` of a run, each ``{}`` when absent."""
    documents = []
    for name in (ARGS_FILE, SUMMARY_FILE):
        path = run_dir / name
        try:
            documents.append(read_json(path) if path.is_file() else {})
        except ValueError as error:
            raise _bad("--resume", str(error)) from None
        if not isinstance(documents[-1], dict):
            raise _bad("--resume", f"{path} is not a JSON object")
    return documents[0], documents[1]


def _only_entry(config_path: Path) -> str | None:
    """The env id of a recipe file with one entry (an experiment's ``recipe.yml``), else None."""
    try:
        entries = [k for k in (yaml.safe_load(config_path.read_text()) or {}) if k[:1] != "."]
    except (yaml.YAMLError, OSError, TypeError, AttributeError):
        return None  # reported as a bad --config below
    return entries[0] if len(entries) == 1 else None


@dataclass
class _Start:
    """Where a segment starts: its recipe (and where it was read, for messages) and, for a
    resume, the run it continues, that run's newest model and statistics and its history."""

    env_id: str
    hyperparams: dict[str, Any]
    source: str
    run_dir: Path | None = None
    model_path: Path | None = None
    vecnorm_path: Path | None = None
    history: dict[str, Any] = field(default_factory=dict)
    segment: int = 0


def _resumed_start(args: argparse.Namespace, settings: dict[str, Any]) -> _Start:
    """The run ``--resume`` continues, checked; ``settings`` updated with the run's own."""
    given = [f"--{name.replace('_', '-')}" for name in RECIPE_OPTIONS if getattr(args, name)]
    if given:
        raise _bad(given[0], "cannot change a resumed run's recipe; start a new run instead")
    run_dir = Path(args.resume)
    if not run_dir.is_dir():
        raise _bad("--resume", f"no run folder {str(run_dir)!r}")
    _trusted("--resume", run_dir, args.trust_pickles)
    env_id, hyperparams = _resumed_config(run_dir)
    record, history = _run_history(run_dir)
    settings.update(
        {
            k: v
            for k, v in (record.get("settings") or record.get("args") or {}).items()
            if k in DEFAULT_SETTINGS and v is not None
        }
    )
    try:
        model_path, vecnorm_path = latest_model(run_dir)
    except (FileNotFoundError, ValueError) as error:
        raise _bad("--resume", str(error)) from None
    return _Start(
        env_id,
        hyperparams,
        f"{run_dir / CONFIG_FILE}",
        run_dir,
        model_path,
        vecnorm_path,
        history,
        segment=max(len(history.get("segments", [])), 1 if history else 0),
    )


def _new_start(args: argparse.Namespace) -> _Start:
    """The recipe of a new run: ``--config``'s entry for ``--env`` (or their defaults)."""
    config_path = Path(args.config) if args.config else DEFAULT_CONFIG
    if not config_path.is_file():
        raise _bad("--config", f"no such file {str(config_path)!r}")
    env_id = args.env or _only_entry(config_path) or ACL_CLIMB_SEA_ID
    try:
        hyperparams = load_hyperparams(config_path, env_id)
    except KeyError as error:
        raise _bad("--env", str(error.args[0])) from None
    except RecipeError as error:
        raise _bad("--config", str(error)) from None
    except (yaml.YAMLError, ValueError, TypeError, AttributeError) as error:
        raise _bad("--config", f"{config_path} is not a zoo config ({error})") from None
    if args.exp_name and not args.exp_name.replace("-", "").replace("_", "").isalnum():
        raise _bad("--exp-name", f"letters, digits, '-' and '_' only, got {args.exp_name!r}")
    return _Start(env_id, hyperparams, f"{config_path} entry {env_id}")


def _run_parent(args: argparse.Namespace, run_dir: Path | None) -> Path:
    """The parent of a new run's folder; where the run writes, the default too, and a resumed
    run's folder: a folder that cannot be written fails now."""
    run_parent = Path(args.run_dir or "runs")
    try:
        if run_dir is not None:
            check_writable_folder(run_dir, "the run folder")
        else:
            run_parent = cli.output_folder(str(run_parent))
    except (ValueError, argparse.ArgumentTypeError) as error:
        raise _bad("--resume" if args.resume else "--run-dir", str(error)) from None
    return run_parent


def _override_recipe(
    start: _Start,
    args: argparse.Namespace,
    hyperparam_overrides: dict[str, Any],
    env_kwarg_overrides: dict[str, Any],
) -> dict[str, Any]:
    """The start's recipe, checked, with the command line's overrides, checked again."""
    hyperparams = start.hyperparams
    check_hyperparams(hyperparams, start.source)
    if hyperparam_overrides:
        if "env_kwargs" in hyperparam_overrides:
            raise _bad("--hyperparams", "set env kwargs with --env-kwargs")
        check_hyperparams({"n_timesteps": 1, **hyperparam_overrides}, "argument --hyperparams")
    hyperparams.update(hyperparam_overrides)
    if env_kwarg_overrides:
        try:
            hyperparams["env_kwargs"] = merge_env_kwargs(
                hyperparams.get("env_kwargs") or {}, env_kwarg_overrides
            )
        except ValueError as error:
            raise _bad("--env-kwargs", str(error)) from None
    if args.n_envs is not None:
        hyperparams["n_envs"] = args.n_envs
    if args.n_timesteps is not None and not args.resume:
        hyperparams["n_timesteps"] = args.n_timesteps
    check_hyperparams(hyperparams, start.source)
    return hyperparams


def _check_env_and_policy(
    env_id: str, hyperparams: dict[str, Any], args: argparse.Namespace
) -> warm_start.TrainedStart | None:
    """Build the env and the policy network once, and check ``--init-from`` against them;
    return the trained start (None without ``--init-from``)."""
    try:
        probe = check_env_kwargs(env_id, hyperparams.get("env_kwargs") or {})
    except ConfigError as error:
        option = "--env" if str(error).startswith("unknown env id") else "--env-kwargs"
        raise _bad(option if not args.resume else "--resume", str(error)) from None
    init_from = None
    try:
        policy = _check_policy_kwargs(probe, hyperparams)
        if args.init_from:
            init_from = _check_init_from(
                args.init_from, probe, hyperparams, policy, args.trust_pickles
            )
    finally:
        probe.close()
    return init_from


def _resumed_steps(
    args: argparse.Namespace, start: _Start, hyperparams: dict[str, Any], total: int
) -> tuple[int, Path | None]:
    """The steps a resume trains (``--n-timesteps``, or the rest of the run's ``total``), its
    saved model checked, and the statistics the trainer reloads (the pickle beside an ``.npz``)."""
    model_path, vecnorm_path = start.model_path, start.vecnorm_path
    assert model_path is not None
    _check_saved_model(model_path, vecnorm_path, normalize_kwargs(hyperparams) is not None)
    if vecnorm_path is not None and not is_pickle(vecnorm_path):
        # The trainer reloads the VecNormalize itself from the pickle beside the npz.
        vecnorm_path = vecnorm_path.with_suffix(Path(VECNORMALIZE_FILE).suffix)
        if not vecnorm_path.is_file():
            raise _bad("--resume", f"{vecnorm_path} is missing: a resume reloads it")
        _check_saved_model(model_path, vecnorm_path, True)
    try:
        trained = model_steps(model_path)
    except ValueError as error:
        raise _bad("--resume", str(error)) from None
    if args.n_timesteps is not None:
        return args.n_timesteps, vecnorm_path
    if total - trained <= 0:
        raise _bad(
            "--n-timesteps",
            f"the run has trained {trained} of its {total} steps; "
            "pass --n-timesteps N to train N more",
        )
    return total - trained, vecnorm_path


def plan_segment(args: argparse.Namespace, argv: Sequence[str]) -> Plan:
    """Check every argument and file; raise :class:`ConfigError` naming the first bad one."""
    settings = dict(DEFAULT_SETTINGS)
    hyperparam_overrides = cli.pairs_to_dict("--hyperparams", args.hyperparams)
    env_kwarg_overrides = cli.pairs_to_dict("--env-kwargs", args.env_kwargs)
    if args.resume and args.init_from:
        raise _bad("--init-from", "a resumed run continues its own policy; start a new run")
    start = _resumed_start(args, settings) if args.resume else _new_start(args)
    run_parent = _run_parent(args, start.run_dir)
    for name in DEFAULT_SETTINGS:
        if getattr(args, name) is not None:
            settings[name] = getattr(args, name)
    hyperparams = _override_recipe(start, args, hyperparam_overrides, env_kwarg_overrides)
    init_from = _check_env_and_policy(start.env_id, hyperparams, args)
    _check_device(str(settings["device"]))
    total = int(hyperparams["n_timesteps"])
    if args.resume:
        segment_steps, vecnorm_path = _resumed_steps(args, start, hyperparams, total)
    else:
        segment_steps, vecnorm_path = total, start.vecnorm_path
    return Plan(
        env_id=start.env_id,
        hyperparams=hyperparams,
        settings=settings,
        segment=start.segment,
        segment_steps=segment_steps,
        run_dir=start.run_dir,
        run_parent=run_parent,
        exp_name=args.exp_name or "ppo",
        progress_bar=not args.no_progress_bar,
        argv=list(argv),
        args={k: str(v) if isinstance(v, Path) else v for k, v in vars(args).items()},
        resume_model=start.model_path,
        resume_vecnormalize=vecnorm_path,
        init_from=init_from,
        history=start.history,
    )


def _check_init_from(
    path: str, probe: Any, hyperparams: dict[str, Any], policy: Any, trust_pickles: bool
) -> warm_start.TrainedStart:
    """The trained policy of ``--init-from``, loaded and checked against the new run: the same
    normalisation and network (``policy``, the new run's) but for the action entries and any
    observations the new env adds, every observation of the trained one, and at least one
    shared action (warm_start.py)."""
    from stable_baselines3 import PPO

    if pretrained.is_pretrained(path):
        raise _bad(
            "--init-from",
            f"{path} is a pretrained (numpy) policy; warm starts need a training run folder "
            "(model.zip and its statistics)",
        )
    if not Path(path).is_dir():
        raise _bad("--init-from", f"no policy folder {path!r}")
    _trusted("--init-from", Path(path), trust_pickles)
    try:
        folder = read_sb3_folder(path)
    except ValueError as error:
        raise _bad("--init-from", str(error)) from None
    normalize = normalize_kwargs(hyperparams) is not None
    if (folder.vecnormalize is not None) != normalize:
        raise _bad(
            "--init-from",
            "the trained policy and the new config must both normalise observations or neither",
        )
    stats = _check_saved_model(folder.model, folder.vecnormalize, normalize, "--init-from")
    try:
        source = check_env_kwargs(folder.env_id, folder.env_kwargs)
    except ConfigError as error:
        raise _bad("--init-from", f"its env does not build here ({error})") from None
    try:
        names = [env_observation_names(e.unwrapped) for e in (source, probe)]
        observed = None if names[0] == names[1] else warm_start.observation_map(*names)
        shared = warm_start.action_map(source.unwrapped.action_names, probe.unwrapped.action_names)
    except ValueError as error:
        raise _bad("--init-from", f"{error}") from None
    finally:
        source.close()
    try:
        state = PPO.load(folder.model, device="cpu").policy.state_dict()
    except Exception as error:  # a zip that is not an SB3 model fails in many ways
        raise _bad("--init-from", f"{folder.model} is not a PPO model ({error})") from None
    try:
        warm_start.check_compatible(state, policy.state_dict(), shared, observed)
    except ValueError as error:
        raise _bad("--init-from", str(error)) from None
    return warm_start.TrainedStart(folder.model, state, stats, shared, observed)


def _check_policy_kwargs(probe: Any, hyperparams: dict[str, Any]) -> Any:
    """Build the policy network once on the env's spaces and return it: unknown or bad
    ``policy_kwargs`` fail here, before any worker starts."""
    from stable_baselines3.common.policies import ActorCriticPolicy

    kwargs = algo_kwargs(hyperparams)
    policy_kwargs = kwargs.get("policy_kwargs") or {}
    try:
        return ActorCriticPolicy(
            probe.observation_space,
            probe.action_space,
            lambda _: 1e-4,
            use_sde=bool(kwargs.get("use_sde", False)),
            **policy_kwargs,
        )
    except (TypeError, ValueError, AssertionError) as error:
        raise _bad("--hyperparams", f"policy_kwargs refused by the policy: {error}") from None


def _check_device(device: str) -> None:
    import torch

    try:
        torch.device(device)
    except RuntimeError:
        raise _bad("--device", f"not a torch device: {device!r} (cpu, cuda, cuda:0, ...)") from None
    if device.startswith("cuda") and not torch.cuda.is_available():
        raise _bad("--device", f"{device!r} but CUDA is not available here")
